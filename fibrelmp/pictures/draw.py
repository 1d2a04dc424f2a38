"""Drawing with matplotlib (Agg, no display): history panels and one frame in 3D (or 2D).

Every function returns the figure and what it drew, read back from the artists (the
tests compare that with the data).  Spheres are scatter markers whose size follows the
sphere radius in data units: the axes are orthographic with one scale on all three axes,
so a radius r is r × (pixels per unit) on screen wherever the sphere is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.pictures.history import History
from fibrelmp.pictures.sources import SceneFrame

MISSING = ("plot and snapshot draw with matplotlib, which is not installed: "
           "pip install 'fibrelmp[plot]' (or pip install matplotlib)")
WALL_COLOUR = "#8a8f98"
BOND_COLOUR = "#3a3a3a"
LIQUID_BOND_COLOUR = "#2f7fd0"


def figure(width: int, height: int, dpi: int = 100):
    """A matplotlib Figure on an Agg canvas (no pyplot, no display), or an InputError
    saying how to install matplotlib."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise InputError(None, None, MISSING) from None
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


# -- history ---------------------------------------------------------------------------------
@dataclass
class DrawnPlot:
    panels: list[str]
    lines: dict[str, tuple[np.ndarray, np.ndarray]]     # series name -> (x, y) as drawn


def draw_history(hist: History, width: int, height: int, dpi: int = 100):
    fig = figure(width, height, dpi)
    titles = list(hist.panels)[:6]              # at most six panels stay readable
    axes = fig.subplots(len(titles), 1, sharex=True, squeeze=False)[:, 0]
    drawn = DrawnPlot(titles, {})
    for ax, title in zip(axes, titles):
        for name in hist.panels[title]:
            y = hist.series[name]
            keep = np.isfinite(hist.x) & np.isfinite(y)
            (line,) = ax.plot(hist.x[keep], y[keep], label=name, lw=1.4,
                              drawstyle="steps-post" if title == "counts" else "default")
            xs, ys = line.get_data()
            drawn.lines[name] = (np.asarray(xs, float), np.asarray(ys, float))
        ax.set_ylabel(title if len(title) < 24 else title[:22] + "…", fontsize=9)
        ax.grid(alpha=0.3)
        if title == "counts":
            from matplotlib.ticker import MaxNLocator

            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
            top = max((float(np.nanmax(hist.series[n], initial=0)) for n in hist.panels[title]), default=0)
            ax.set_ylim(0, max(top, 1.0) * 1.15)          # counts from zero
        ax.tick_params(labelsize=8)
        if len(hist.panels[title]) > 1 or title in ("counts",) or title.startswith("energy"):
            ax.legend(fontsize=8, loc="best", frameon=False)
    unit = f" [{hist.x_unit}]" if hist.x_unit else ""
    axes[-1].set_xlabel(f"{hist.x_name}{unit}", fontsize=9)
    fig.suptitle(f"from {hist.source}", fontsize=8)
    fig.tight_layout()
    return fig, drawn


# -- one frame -------------------------------------------------------------------------------
@dataclass
class DrawnScene:
    positions: np.ndarray              # (n,3) the sphere centres drawn
    sizes: np.ndarray                  # (n,) marker areas [pt²]
    bonds: int                         # line segments drawn for bonds (a periodic crossing: 2)
    triangles: int                     # wall faces drawn (triangles and clipped planes)
    pixels_per_unit: float
    notes: list[str] = field(default_factory=list)
    liquid_bonds: int = 0              # line segments drawn for MUSEN liquid bonds


def _bond_segments(frame: SceneFrame, pairs: np.ndarray | None = None) -> np.ndarray:
    """(m,2,3) segments of ``pairs`` (default: the frame's bonds); a bond longer than half
    the box along an axis crosses a periodic boundary (no bond can be that long otherwise):
    drawn as two halves, one at each end."""
    pairs = frame.bonds if pairs is None else pairs
    if not len(pairs):
        return np.zeros((0, 2, 3))
    a, b = frame.position[pairs[:, 0]], frame.position[pairs[:, 1]]
    d = b - a
    if frame.box is not None:
        length = np.asarray(frame.box[1]) - np.asarray(frame.box[0])
        with np.errstate(divide="ignore", invalid="ignore"):
            shift = np.where(length > 0, np.round(d / length), 0.0)
        d_min = d - shift * length
        crossing = np.any(shift != 0, axis=1)
    else:
        d_min, crossing = d, np.zeros(len(d), bool)
    whole = np.stack([a[~crossing], b[~crossing]], axis=1)
    halves_a = np.stack([a[crossing], a[crossing] + d_min[crossing] / 2], axis=1)
    halves_b = np.stack([b[crossing], b[crossing] - d_min[crossing] / 2], axis=1)
    return np.concatenate([whole, halves_a, halves_b])


def _plane_polygon(normal: np.ndarray, point: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The polygon where a plane cuts the box [lo, hi] (corners in order), or (0,3)."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    edges = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
    side = (corners - point) @ normal
    hits = []
    for i, j in edges:
        if side[i] == 0:
            hits.append(corners[i])
        elif side[i] * side[j] < 0:
            hits.append(corners[i] + (corners[j] - corners[i]) * side[i] / (side[i] - side[j]))
    if len(hits) < 3:
        return np.zeros((0, 3))
    hits = np.unique(np.round(np.array(hits), 12), axis=0)
    centre = hits.mean(axis=0)
    u = hits[0] - centre
    u /= np.linalg.norm(u) or 1.0
    v = np.cross(normal, u)
    angle = np.arctan2((hits - centre) @ v, (hits - centre) @ u)
    return hits[np.argsort(angle)]


def _view_bounds(frame: SceneFrame, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """The region to show: the spheres and walls, and the box when it is not much larger
    (a MUSEN domain can be far larger than the scene: more than 20 times, it is left out)."""
    parts = [frame.position - radius[:, None], frame.position + radius[:, None]]
    if frame.triangles is not None and len(frame.triangles):
        parts.append(frame.triangles.reshape(-1, 3))
    pts = np.concatenate(parts) if len(frame.position) or len(parts) > 2 else np.zeros((0, 3))
    pts = pts[np.isfinite(pts).all(axis=1)]
    show_box = False
    if frame.box is not None:
        lo, hi = np.asarray(frame.box[0], float), np.asarray(frame.box[1], float)
        if len(pts) == 0:
            return lo, hi, True
        span = np.ptp(pts, axis=0).max()
        show_box = bool(np.isfinite(hi - lo).all() and (hi - lo).max() <= 20 * max(span, 1e-300))
        if show_box:
            pts = np.concatenate([pts, [lo, hi]])
    if len(pts) == 0:
        return -np.ones(3), np.ones(3), False
    return pts.min(axis=0), pts.max(axis=0), show_box


def _radii(frame: SceneFrame, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, str | None]:
    if frame.radius is not None and len(frame.radius) and np.isfinite(frame.radius).all():
        return np.asarray(frame.radius, float), None
    n = max(frame.count, 1)
    volume = float(np.prod(np.maximum(hi - lo, 1e-300)))
    r, how = 0.25 * (volume / n) ** (1 / 3), "a quarter of the mean spacing"
    if frame.count > 1:
        try:
            from scipy.spatial import cKDTree          # with MDAnalysis, scipy is installed
        except ImportError:
            cKDTree = None
        if cKDTree is not None:
            gap = cKDTree(frame.position).query(frame.position, k=2)[0][:, 1]
            gap = gap[np.isfinite(gap) & (gap > 0)]
            if len(gap) and 0.4 * float(np.median(gap)) < r:
                r, how = 0.4 * float(np.median(gap)), "0.4 of the median nearest-neighbour distance"
    return np.full(frame.count, r), f"radii unknown: drawn as {r:.3g} ({how})"


def _colours(kinds: np.ndarray):
    from matplotlib import colormaps

    cmap = colormaps["tab10"]
    return cmap(np.asarray(kinds) % 10)


def draw_frame(frame: SceneFrame, width: int, height: int, title: str, dpi: int = 100,
               elev: float = 22.0, azim: float = -60.0):
    if frame.dimension == 2:
        return _draw_frame_2d(frame, width, height, title, dpi)
    from mpl_toolkits.mplot3d import proj3d
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    fig = figure(width, height, dpi)
    ax = fig.add_axes((0.0, 0.0, 1.0, 0.93), projection="3d", proj_type="ortho")
    fig.text(0.5, 0.965, title, ha="center", va="center", fontsize=9)
    first = _radii(frame, *_view_bounds(frame, np.zeros(frame.count))[:2])
    radius, note = first
    lo, hi, show_box = _view_bounds(frame, radius)
    span = np.maximum(hi - lo, 1e-12 * max(float(np.max(hi - lo)), 1e-300))
    ax.set_xlim(lo[0], lo[0] + span[0])
    ax.set_ylim(lo[1], lo[1] + span[1])
    ax.set_zlim(lo[2], lo[2] + span[2])
    ax.set_box_aspect(span / span.max(), zoom=0.95)
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    # walls under bonds under spheres: matplotlib orders whole collections by their mean
    # depth, which would hide a sphere resting on a plate behind the plate's faces
    ax.computed_zorder = False
    notes = [note] if note else []

    triangles = 0
    faces = []
    if frame.triangles is not None and len(frame.triangles):
        faces += list(frame.triangles)
    box_lo, box_hi = (np.asarray(frame.box[0], float), np.asarray(frame.box[1], float)) \
        if frame.box is not None else (lo, hi)
    for normal, point in frame.planes:
        poly = _plane_polygon(np.asarray(normal, float), np.asarray(point, float), box_lo, box_hi)
        if len(poly):
            faces.append(poly)
    if faces:
        walls = Poly3DCollection(faces, facecolors=WALL_COLOUR, edgecolors="#5b6068",
                                 linewidths=0.3, alpha=0.35, zorder=1)
        ax.add_collection3d(walls)
        triangles = len(faces)
    if show_box:
        _draw_box(ax, box_lo, box_hi)

    segments = _bond_segments(frame)
    if len(segments):
        ax.add_collection3d(Line3DCollection(segments, colors=BOND_COLOUR, linewidths=0.8, alpha=0.8,
                                             zorder=2))
    liquid = _bond_segments(frame, frame.liquid_bonds)
    if len(liquid):
        ax.add_collection3d(Line3DCollection(liquid, colors=LIQUID_BOND_COLOUR, linewidths=1.6,
                                             linestyles="--", alpha=0.8, zorder=2))

    # pixels per data unit: ortho projection with equal scales, so any screen-parallel offset
    # works; measure one along the screen's horizontal
    fig.canvas.draw()
    centre = (lo + hi) / 2
    az = math.radians(azim)
    right = np.array([-math.sin(az), math.cos(az), 0.0])
    ends = np.array([centre, centre + right * span.max()])
    x2, y2, _ = proj3d.proj_transform(ends[:, 0], ends[:, 1], ends[:, 2], ax.get_proj())
    px = ax.transData.transform(np.column_stack([x2, y2]))
    per_unit = float(np.linalg.norm(px[1] - px[0])) / span.max()
    diameter_pt = 2 * radius * per_unit * 72.0 / dpi
    sizes = np.maximum(diameter_pt, 0.5) ** 2
    pos = frame.position
    scatter = ax.scatter(pos[:, 0], pos[:, 1], pos[:, 2], s=sizes, c=_colours(frame.kind),
                         edgecolors="#222222", linewidths=0.2, depthshade=len(pos) > 1, alpha=1.0,
                         zorder=3)
    if len(frame.kind_names) > 1:
        from matplotlib.lines import Line2D

        colours = _colours(np.arange(len(frame.kind_names)))
        handles = [Line2D([], [], ls="", marker="o", color=c, markeredgecolor="#222222",
                          markersize=7, label=name) for c, name in zip(colours, frame.kind_names)]
        ax.legend(handles=handles, loc="lower left", fontsize=8, frameon=False)
    x, y, z = scatter._offsets3d
    drawn = DrawnScene(np.column_stack([np.asarray(x, float), np.asarray(y, float), np.asarray(z, float)]),
                       np.asarray(scatter.get_sizes(), float), len(segments), triangles, per_unit, notes,
                       len(liquid))
    return fig, drawn


def _draw_box(ax, lo: np.ndarray, hi: np.ndarray) -> None:
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    c = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    edges = [(c[i], c[j]) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
    ax.add_collection3d(Line3DCollection(edges, colors="#9aa0a6", linewidths=0.6, linestyles="--"))


def _draw_frame_2d(frame: SceneFrame, width: int, height: int, title: str, dpi: int):
    from matplotlib.collections import EllipseCollection, LineCollection

    fig = figure(width, height, dpi)
    ax = fig.add_axes((0.05, 0.05, 0.9, 0.85))
    ax.set_title(title, fontsize=9)
    lo3, hi3, show_box = _view_bounds(frame, np.zeros(frame.count))
    radius, note = _radii(frame, lo3, hi3)
    lo3, hi3, show_box = _view_bounds(frame, radius)
    lo, hi = lo3[:2], hi3[:2]
    xy = frame.position[:, :2]
    circles = EllipseCollection(2 * radius, 2 * radius, np.zeros(frame.count), units="xy",
                                offsets=xy, offset_transform=ax.transData,
                                facecolors=_colours(frame.kind), edgecolors="#222222", linewidths=0.3)
    ax.add_collection(circles)
    segments = _bond_segments(frame)[:, :, :2]
    if len(segments):
        ax.add_collection(LineCollection(segments, colors=BOND_COLOUR, linewidths=0.8))
    liquid = _bond_segments(frame, frame.liquid_bonds)[:, :, :2]
    if len(liquid):
        ax.add_collection(LineCollection(liquid, colors=LIQUID_BOND_COLOUR, linewidths=1.6,
                                         linestyles="--"))
    lines = 0
    if frame.box is not None:
        b_lo, b_hi = np.asarray(frame.box[0], float)[:2], np.asarray(frame.box[1], float)[:2]
        for normal, point in frame.planes:
            poly = _plane_polygon(np.append(np.asarray(normal, float)[:2], 0.0),
                                  np.append(np.asarray(point, float)[:2], 0.0),
                                  np.append(b_lo, -1.0), np.append(b_hi, 1.0))
            if len(poly):
                ax.plot(poly[:, 0], poly[:, 1], color=WALL_COLOUR, lw=2.5)
                lines += 1
        if show_box:
            ax.add_patch(_rectangle(b_lo, b_hi))
    pad = 0.03 * float(np.max(hi - lo))
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=8)
    offsets = np.asarray(circles.get_offsets(), float)
    drawn = DrawnScene(np.column_stack([offsets, frame.position[:, 2]]), 2 * radius, len(segments),
                       lines, float("nan"), [note] if note else [], len(liquid))
    return fig, drawn


def _rectangle(lo: np.ndarray, hi: np.ndarray):
    from matplotlib.patches import Rectangle

    return Rectangle(tuple(lo), *(hi - lo), fill=False, ls="--", lw=0.8, ec="#9aa0a6")
