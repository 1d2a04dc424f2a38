"""Walls of granular models: shape detection, rigid-motion kinematics, wall-particle tiling.

Used by ``granular.walls`` / ``granular.tiles`` (LAMMPS script) and ``granular_run.frames`` (frames).
Everything here is numpy only; nothing writes files.

Shapes a triangle group can be represented by exactly (LAMMPS regions + fix wall/gran/region):

* ``box``: every triangle lies in a face of the group's axis-aligned bounding box and every
  face is either fully covered (closed) or empty (open).  A planar axis-aligned rectangle is
  the degenerate case (zero thickness).
* ``cylinder``: an axis-aligned faceted cylinder: side facets with all vertices on a circle of
  radius R, optional flat end caps.  Represented with the facets' inscribed radius R cos(pi/n).

Anything else is tiled with frozen wall particles (see ``tile_triangles``).

Rigid motion (MUSEN geometry motion type 1) and its exact piecewise solution: ``kinematics.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fibrelmp.granmodel import Geometry, GranularModel

AREA_RTOL = 1e-6


# ----------------------------------------------------------------------------------------
# shapes
@dataclass
class BoxShape:
    """A block in its own frame.  ``frame`` (columns = the block's axes in world coordinates)
    is None for an axis-aligned block; otherwise world = pivot + frame (local - pivot)."""

    lo: np.ndarray
    hi: np.ndarray
    open_faces: list[int]          # LAMMPS block face numbers 1..6 (xlo xhi ylo yhi zlo zhi)
    flat_axis: int | None = None   # planar rectangle: its normal axis (local frame)
    frame: np.ndarray | None = None
    pivot: np.ndarray | None = None

    def to_local(self, x: np.ndarray) -> np.ndarray:
        if self.frame is None:
            return x
        return (x - self.pivot) @ self.frame + self.pivot

    def rotation(self) -> tuple[np.ndarray, float]:
        """Axis and angle of ``frame`` (identity: z axis, 0)."""
        if self.frame is None:
            return np.array([0.0, 0.0, 1.0]), 0.0
        return axis_angle(self.frame)

    def describe(self) -> str:
        rng = " x ".join(f"[{a:.6g}, {b:.6g}]" for a, b in zip(self.lo, self.hi))
        how = "axis-aligned"
        if self.frame is not None:
            ax, th = self.rotation()
            how = (f"rotated ({math.degrees(th):.6g} deg about {', '.join(f'{c:.6g}' for c in ax)};"
                   f" in its own frame)")
        if self.flat_axis is not None:
            return f"{how} rectangular plate {rng} -> LAMMPS region block of zero thickness"
        names = ["xlo", "xhi", "ylo", "yhi", "zlo", "zhi"]
        opened = f", open faces {' '.join(names[f - 1] for f in self.open_faces)}" if self.open_faces else ""
        return f"{how} box {rng}{opened} -> LAMMPS region block"


def axis_angle(R: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit axis and angle in [0, pi] of a rotation matrix (right-handed)."""
    c = max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0))
    th = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if np.linalg.norm(w) > 1e-9:
        return w / np.linalg.norm(w), th
    if th < 0.5:
        return np.array([0.0, 0.0, 1.0]), 0.0
    # angle ~ pi: axis from R + I (symmetric, rank 1)
    m = R + np.eye(3)
    k = int(np.argmax(np.linalg.norm(m, axis=0)))
    ax = m[:, k] / np.linalg.norm(m[:, k])
    return ax, th


def detect_oriented_box(v: np.ndarray) -> BoxShape | None:
    """detect_box in the frame of the triangles' own face normals (rotated boxes / plates)."""
    box = detect_box(v)
    if box is not None:
        return box
    nrm = triangle_normals(v)
    if not len(v) or (np.linalg.norm(nrm, axis=1) == 0).any():
        return None
    dirs: list[np.ndarray] = []
    for n in nrm:
        if not any(abs(abs(float(n @ d)) - 1) < 1e-9 for d in dirs):
            dirs.append(n)
        if len(dirs) > 3:
            return None
    frames = []
    if len(dirs) >= 2:
        e1 = dirs[0]
        e2 = next((d for d in dirs[1:] if abs(float(d @ e1)) < 1e-9), None)
        if e2 is None:
            return None
        frames.append(np.column_stack([e1, e2, np.cross(e1, e2)]))
    else:
        e3 = dirs[0]
        seen: list[np.ndarray] = []
        for tri in v[:8]:
            for a, b in ((0, 1), (1, 2), (2, 0)):
                d = tri[b] - tri[a]
                d = d - (d @ e3) * e3
                ln = np.linalg.norm(d)
                if ln == 0:
                    continue
                d = d / ln
                if any(abs(abs(float(d @ q)) - 1) < 1e-9 for q in seen):
                    continue
                seen.append(d)
                frames.append(np.column_stack([d, np.cross(e3, d), e3]))
    pivot = v.reshape(-1, 3).mean(0)
    for E in frames:
        local = (v - pivot) @ E + pivot
        box = detect_box(local)
        if box is not None:
            box.frame, box.pivot = E, pivot
            return box
    return None


@dataclass
class CylinderShape:
    axis: int
    c1: float
    c2: float
    radius: float          # inscribed radius of the facets
    vertex_radius: float
    lo: float
    hi: float
    open_faces: list[int]  # 1 lo cap, 2 hi cap
    nseg: int

    def describe(self) -> str:
        ax = "xyz"[self.axis]
        caps = {(): "closed", (1,): "open at the low end", (2,): "open at the high end",
                (1, 2): "open at both ends"}[tuple(self.open_faces)]
        return (f"{ax}-axis cylinder of {self.nseg} facets, radius {self.radius:.6g} (inscribed; "
                f"vertices at {self.vertex_radius:.6g}), {ax} in [{self.lo:.6g}, {self.hi:.6g}], {caps}"
                f" -> LAMMPS region cylinder")


def triangle_areas(v: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)


def area_centroid(v: np.ndarray) -> np.ndarray:
    """The area-weighted centroid of triangles (k,3,3): the centre a geometry rotating "around
    its centre" turns about in MUSEN (CPUSimulator::MoveWalls)."""
    if not len(v):
        return np.zeros(3)
    a = triangle_areas(v)
    total = float(a.sum())
    if total == 0.0:
        return np.zeros(3)
    return (a[:, None] * (v.sum(axis=1) / 3.0)).sum(axis=0) / total


def detect_box(v: np.ndarray) -> BoxShape | None:
    pts = v.reshape(-1, 3)
    lo, hi = pts.min(0), pts.max(0)
    size = hi - lo
    scale = float(np.linalg.norm(size))
    if scale == 0:
        return None
    tol = 1e-9 * scale
    flat = np.flatnonzero(size <= tol)
    areas = triangle_areas(v)
    if len(flat) > 1 or (areas <= 0).any():
        return None
    if len(flat) == 1:
        a = int(flat[0])
        b, c = [k for k in range(3) if k != a]
        rect = size[b] * size[c]
        if rect <= 0 or abs(areas.sum() - rect) > AREA_RTOL * rect:
            return None
        return BoxShape(lo.copy(), hi.copy(), [], flat_axis=a)
    face_area = np.zeros(6)
    for a in range(3):
        for side, bound in enumerate((lo[a], hi[a])):
            on = (np.abs(v[:, :, a] - bound) <= tol).all(1)
            face_area[2 * a + side] = areas[on].sum()
            areas = np.where(on, 0.0, areas)      # each triangle counted on one face only
    if (areas > 0).any():                          # a triangle not lying on any face
        return None
    open_faces = []
    for f in range(6):
        a = f // 2
        b, c = [k for k in range(3) if k != a]
        full = size[b] * size[c]
        if face_area[f] <= AREA_RTOL * full:
            open_faces.append(f + 1)
        elif abs(face_area[f] - full) > AREA_RTOL * full:
            return None
    if len(open_faces) == 6:
        return None
    return BoxShape(lo.copy(), hi.copy(), open_faces)


def detect_cylinder(v: np.ndarray) -> CylinderShape | None:
    pts = v.reshape(-1, 3)
    lo, hi = pts.min(0), pts.max(0)
    scale = float(np.linalg.norm(hi - lo))
    if scale == 0:
        return None
    tol = 1e-9 * scale
    areas = triangle_areas(v)
    for a in range(3):
        b, c = [k for k in range(3) if k != a]
        cb, cc = 0.5 * (lo[b] + hi[b]), 0.5 * (lo[c] + hi[c])
        rho = np.hypot(v[:, :, b] - cb, v[:, :, c] - cc)
        rmax = float(rho.max())
        height = hi[a] - lo[a]
        if rmax <= 0 or height <= tol:
            continue
        side = (rho >= rmax * (1 - 1e-6)).all(1)
        at_lo = (np.abs(v[:, :, a] - lo[a]) <= tol).all(1)
        at_hi = (np.abs(v[:, :, a] - hi[a]) <= tol).all(1)
        cap = (at_lo | at_hi) & ~side
        if not side.any() or not (side | cap).all():
            continue
        sv = v[side].reshape(-1, 3)
        ang = np.round(np.arctan2(sv[:, c] - cc, sv[:, b] - cb) * 1e9 / (2 * math.pi))
        nseg = len(np.unique(np.mod(ang, 1e9)))
        if nseg < 6:
            continue
        chord = 2 * rmax * math.sin(math.pi / nseg)
        if abs(areas[side].sum() - nseg * chord * height) > 1e-5 * nseg * chord * height:
            continue
        disc = 0.5 * nseg * rmax ** 2 * math.sin(2 * math.pi / nseg)
        open_faces = []
        for face, sel in ((1, at_lo & cap), (2, at_hi & cap)):
            s = areas[sel].sum()
            if s <= AREA_RTOL * disc:
                open_faces.append(face)
            elif abs(s - disc) > 1e-5 * disc:
                break
        else:
            return CylinderShape(a, cb, cc, rmax * math.cos(math.pi / nseg), rmax,
                                 float(lo[a]), float(hi[a]), open_faces, nseg)
    return None


# ----------------------------------------------------------------------------------------
# tiling
def _grid_divisions(tri: np.ndarray, spacing: float) -> int:
    """Barycentric grid divisions n of a triangle: every sub-triangle edge is <= spacing."""
    e = max(np.linalg.norm(tri[1] - tri[0]), np.linalg.norm(tri[2] - tri[0]),
            np.linalg.norm(tri[2] - tri[1]))
    return max(1, int(math.ceil(e / spacing - 1e-9)))


def _unique_tiles(pts: list, owner: list, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The tiles of all triangles, a point shared by neighbouring triangles kept once (with
    the first triangle that produced it)."""
    if not pts:
        return np.zeros((0, 3)), np.zeros(0, np.int64)
    p = np.concatenate(pts)
    o = np.concatenate(owner)
    key = np.round(p / (spacing * 1e-6)).astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)
    first.sort()
    return p[first], o[first]


def tile_triangles(v: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points covering each triangle on a barycentric grid whose sub-triangle edges are all
    <= spacing; points shared by neighbouring triangles are kept once.

    Returns (points (p,3), triangle index (p,) of the first triangle that produced each)."""
    pts, owner = [], []
    for k, tri in enumerate(v):
        n = _grid_divisions(tri, spacing)
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = (i + j) <= n
        a, b = i[keep] / n, j[keep] / n
        p = tri[0] + a[:, None] * (tri[1] - tri[0]) + b[:, None] * (tri[2] - tri[0])
        pts.append(p)
        owner.append(np.full(len(p), k))
    return _unique_tiles(pts, owner, spacing)


def tile_triangles_within(v: np.ndarray, spacing: float, lo: np.ndarray, hi: np.ndarray):
    """``tile_triangles`` restricted to the points inside [lo, hi]: the same points in the same
    order, without generating the others (a 1 m triangle tiled for 1 mm spheres has 4e6)."""
    pts, owner = [], []
    for k, tri in enumerate(v):
        n = _grid_divisions(tri, spacing)
        if (tri.max(axis=0) < lo).any() or (tri.min(axis=0) > hi).any():
            continue
        i = np.arange(n + 1)
        e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
        base = tri[0] + (i / n)[:, None] * e1
        jlo, jhi = np.zeros(n + 1), (n - i).astype(float)
        with np.errstate(all="ignore"):
            for ax in range(3):
                if e2[ax] != 0:
                    t1 = (lo[ax] - base[:, ax]) / e2[ax] * n
                    t2 = (hi[ax] - base[:, ax]) / e2[ax] * n
                    jlo = np.maximum(jlo, np.minimum(t1, t2) - 1.0)
                    jhi = np.minimum(jhi, np.maximum(t1, t2) + 1.0)
                else:
                    jhi[(base[:, ax] < lo[ax]) | (base[:, ax] > hi[ax])] = -1.0
        jlo = np.ceil(np.clip(jlo, 0, n)).astype(np.int64)
        jhi = np.floor(np.clip(jhi, -1, n)).astype(np.int64)
        ok = jhi >= jlo
        cnt = (jhi - jlo + 1)[ok]
        if not cnt.sum():
            continue
        ii = np.repeat(i[ok], cnt)
        start = np.repeat(np.cumsum(cnt) - cnt, cnt)
        jj = np.repeat(jlo[ok], cnt) + (np.arange(int(cnt.sum())) - start)
        p = tri[0] + (ii / n)[:, None] * (tri[1] - tri[0]) + (jj / n)[:, None] * (tri[2] - tri[0])
        p = p[((p >= lo) & (p <= hi)).all(axis=1)]
        pts.append(p)
        owner.append(np.full(len(p), k))
    return _unique_tiles(pts, owner, spacing)


def triangle_normals(v: np.ndarray) -> np.ndarray:
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(ln > 0, ln, 1.0)


def particle_side(v: np.ndarray, spheres_x: np.ndarray, reach: float) -> np.ndarray:
    """Per triangle: +1 if the spheres near it lie on the normal side, -1 if on the other
    side, 0 if on both or none (then tiles are not offset)."""
    nrm = triangle_normals(v)
    out = np.zeros(len(v), np.int64)
    if not len(spheres_x):
        return out
    lo = v.min(1) - reach
    hi = v.max(1) + reach
    for k in range(len(v)):
        near = ((spheres_x >= lo[k]) & (spheres_x <= hi[k])).all(1)
        if not near.any():
            continue
        d = (spheres_x[near] - v[k, 0]) @ nrm[k]
        if (d > 0).all():
            out[k] = 1
        elif (d < 0).all():
            out[k] = -1
    return out


# ----------------------------------------------------------------------------------------
# attribution of wall contacts to triangles
def closest_points(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Squared distances (P, K) from points p (P,3) to triangles tri (K,3,3) (Ericson)."""
    a, b, c = tri[None, :, 0], tri[None, :, 1], tri[None, :, 2]
    P = p[:, None, :]
    ab, ac, ap = b - a, c - a, P - a
    d1, d2 = (ab * ap).sum(-1), (ac * ap).sum(-1)
    bp = P - b
    d3, d4 = (ab * bp).sum(-1), (ac * bp).sum(-1)
    cp = P - c
    d5, d6 = (ab * cp).sum(-1), (ac * cp).sum(-1)
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = 1.0 / (va + vb + vc)
        v = vb * denom
        w = vc * denom
        q = a + ab * v[..., None] + ac * w[..., None]                  # interior
        # edges and vertices
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    q = np.where(((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0))[..., None],
                 b + t_bc[..., None] * (c - b), q)
    q = np.where(((vb <= 0) & (d2 >= 0) & (d6 <= 0))[..., None], a + t_ac[..., None] * ac, q)
    q = np.where(((vc <= 0) & (d1 >= 0) & (d3 <= 0))[..., None], a + t_ab[..., None] * ab, q)
    q = np.where(((d6 >= 0) & (d5 <= d6))[..., None], c, q)
    q = np.where(((d3 >= 0) & (d4 <= d3))[..., None], b, q)
    q = np.where(((d1 <= 0) & (d2 <= 0))[..., None], a, q)
    d = P - q
    return (d * d).sum(-1)


def nearest_triangle(p: np.ndarray, tri: np.ndarray, chunk: int = 2_000_000) -> np.ndarray:
    """Index of the nearest triangle for each point (bounded memory)."""
    out = np.zeros(len(p), np.int64)
    if not len(p) or not len(tri):
        return out
    step = max(1, chunk // max(len(tri), 1))
    for s in range(0, len(p), step):
        out[s:s + step] = np.argmin(closest_points(p[s:s + step], tri), axis=1)
    return out


def geometry_triangle_rows(model: GranularModel) -> list[tuple[str, Geometry | None, np.ndarray]]:
    """(name, geometry or None, triangle rows) for every geometry, plus triangles in none."""
    out = []
    if model.triangles is None or model.triangles.count == 0:
        return out
    used = np.zeros(model.triangles.count, bool)
    for g in model.geometries:
        rows = np.asarray(g.triangle_rows, np.int64)
        used[rows] = True
        out.append((g.name, g, rows))
    rest = np.flatnonzero(~used)
    if len(rest):
        out.append(("(walls in no geometry)", None, rest))
    return out
