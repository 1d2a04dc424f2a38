"""Turn a ``GranularModel`` (MUSEN scene / DEMDF document) into a LAMMPS job on disk.

``in.lammps`` + ``data.lammps`` are stock LAMMPS (GRANULAR + BPM packages, no Python hooks):
``lmp -in in.lammps`` inside the job folder replays exactly what ``fibrelmp run`` executes
line by line.  The mapping and every deviation from MUSEN are described in docs/granular.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ContactLaw, Geometry, GranularModel
from fibrelmp.lammps_text import LammpsText, comment_text, template_environment
from fibrelmp.sanity import close_pairs
from fibrelmp.textio import atomic_write
from fibrelmp.translate.granular_walls import (BoxShape, CylinderShape, Kinematics, detect_cylinder, detect_oriented_box,
                             geometry_kinematics, geometry_triangle_rows, particle_side,
                             piecewise_expression, tile_triangles, tile_triangles_within,
                             triangle_normals)
from fibrelmp.translate.lammps_job import _block, _fmt
from fibrelmp.translate.steps import SaveSteps

SCRIPT_NAME = "in.lammps"
DATA_NAME = "data.lammps"
FRAMES_NAME = "frames.dump"
BONDS_NAME = "bonds.dump"
TILES_NAME = "walls.dump"
BREAKS_NAME = "breaks.dump"

BOND_BIN_RTOL = 1e-3        # bond types: diameter and L0 binned to 0.1 % (log bins)
ROLL_OMEGA_DT = 0.1         # rolling spring: angular frequency * dt of the stiffest case
TILE_SPACING_FACTOR = 0.5   # wall tiles: spacing = 0.5 * smallest sphere contact radius
TILE_RADIUS_FACTOR = 0.6    # wall tile radius = 0.6 * spacing
TILE_MASS_FACTOR = 1e20     # wall tiles weigh 1e20 x the heaviest sphere (m* = m_p)
BIG = 1e300                 # "never breaks"
MAX_STEPS = 2.0 ** 63 - 1   # LAMMPS counts time steps in a 64-bit integer
# box and binning (docs/granular.md, "Domain, activity, periodicity, 2D")
OVERSIZED_BINS = 1_000_000  # a domain box with more neighbour bins than this ...
OVERSIZED_RATIO = 64        # ... and this many times those of the spheres' box is oversized
BIN_CAP = 10_000_000        # above this many default-size bins (and BINS_PER_ATOM x the
BINS_PER_ATOM = 8           # atoms), bins are coarsened
REACH_SAFETY = 2.0          # wall particles: kept within twice the distance a sphere can travel
TILE_CLIP_MIN = 100_000     # geometries needing more wall particles are tiled within reach only
CHECK_EVERY_MAX = 100       # domain removal / reach check at least every this many steps
NSQ_RATIO = 50.0            # coarse bins > this x the thinnest box extent: neighbor nsq instead


@dataclass
class WallPlan:
    """How one geometry (group of triangles) or plane is represented."""

    name: str
    kind: str                        # box | cylinder | tiles | plane
    description: str
    triangle_rows: np.ndarray        # rows into model.triangles (empty for planes)
    kinematics: Kinematics
    material: int
    shape: BoxShape | CylinderShape | None = None
    region: str | None = None        # LAMMPS region id
    fixes: list[str] = field(default_factory=list)
    contact_vars: list[str] = field(default_factory=list)   # 6 dump columns (fx fy fz cx cy cz)
    tile_ids: np.ndarray | None = None       # LAMMPS ids of its wall tiles
    tile_owner: np.ndarray | None = None     # triangle row of each tile
    plane_index: int | None = None           # index into model.planes


@dataclass
class GranularJob:
    folder: Path
    script: Path
    data: Path
    total_steps: int
    save_steps: SaveSteps                # lazy: iterate, len(), `in`
    frames: Path                     # spheres, one write_dump per saved frame
    bond_dump: Path | None           # alive bonds (compute bond/local) per frame
    tile_dump: Path | None           # wall tiles (forces) per frame
    breaks: Path | None              # one line "step id1 id2" per broken bond, every step
    walls: list[tuple[str, str]]     # geometry name -> representation
    dt: float
    t_start: float
    sphere_rows: np.ndarray          # rows simulated (LAMMPS id = row + 1)
    outside_rows: np.ndarray         # active at t_start but outside the domain: dropped
    late_rows: np.ndarray            # active only after t_start: not simulated
    bond_rows: np.ndarray            # bonds simulated
    deletions: list[tuple[int, np.ndarray]]   # (step, sphere rows) removed at activity end
    wall_plans: list[WallPlan]
    domain_lo: np.ndarray | None     # removal box (non-periodic axes), None: nothing removed
    domain_hi: np.ndarray | None
    removal_axes: np.ndarray         # (3,) bool: axes where leaving the box removes a sphere
    frame_columns: list[str] = field(default_factory=list)
    warnings: list[tuple[str, str]] = field(default_factory=list)


# ----------------------------------------------------------------------------------------
# contact laws
def law_args(law: ContactLaw, mu_roll: float, roll_k: float, roll_g: float,
             scale: float = 1.0) -> str:
    """pair_coeff / wall/gran arguments reproducing ``law`` (E*, G* optionally scaled).

    LAMMPS (explicit pair_coeff i j, and every fix wall/gran) uses E_eff = E/(2(1-nu^2)) and
    G_eff = E/(4(2-nu)(1+nu)); with r = G*/E*, nu = (4r-1)/(2r-1), E = 2(1-nu^2) E* both equal
    the model's values.  Outside 0 < r < 1/3 no |nu| < 1 exists: then k_t = 8 G* is given
    explicitly (identical force; see docs/granular.md).
    """
    e_star, g_star = law.youngs_eff * scale, law.shear_eff * scale
    r = g_star / e_star
    if 0 < r < 1.0 / 3.0:
        nu = (4 * r - 1) / (2 * r - 1)
        kt = "NULL"
    else:
        nu = 0.0
        kt = _fmt(8.0 * g_star)
    e_in = 2.0 * (1.0 - nu * nu) * e_star
    parts = [f"hertz/material {_fmt(e_in)} {_fmt(law.restitution)} {_fmt(nu)}"]
    if g_star > 0 and law.friction > 0:
        xt = 2.0 * math.sqrt(g_star / e_star)
        parts.append(f"tangential mindlin {kt} {_fmt(xt)} {_fmt(law.friction)}")
    else:
        parts.append("tangential linear_nohistory 0.0 0.0")
    if law.rolling_friction > 0:
        parts.append(f"rolling sds {_fmt(roll_k)} {_fmt(roll_g)} {_fmt(mu_roll)}")
    parts.append("damping coeff_restitution")
    return " ".join(parts)


def _check_law(model: GranularModel, a: int, b: int) -> ContactLaw:
    key = (min(a, b), max(a, b))
    if key not in model.contacts:
        na, nb = model.materials[a].name, model.materials[b].name
        raise InputError(model.source, None, f"no contact parameters for materials '{na}' and '{nb}'")
    law = model.contacts[key]
    na, nb = model.materials[key[0]].name, model.materials[key[1]].name
    if not (law.youngs_eff > 0 and math.isfinite(law.youngs_eff)):
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': effective Young's modulus "
                         f"must be > 0, got {law.youngs_eff!r}")
    if not (law.shear_eff >= 0 and math.isfinite(law.shear_eff)):
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': effective shear modulus "
                         f"must be >= 0, got {law.shear_eff!r}")
    if not (0 < law.restitution <= 1):
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': restitution coefficient must "
                         f"be in (0, 1], got {law.restitution!r}")
    if law.friction < 0 or law.rolling_friction < 0:
        raise InputError(model.source, None, f"materials '{na}'/'{nb}': friction coefficients must "
                         "be >= 0")
    return law


def _note(text: str) -> LammpsText:
    """A comment line of fibrelmp's own in the script (escaped like user text all the same)."""
    return LammpsText("# " + comment_text(text))


def rolling_spring(m_min: float, dt: float, source=None) -> tuple[float, float]:
    """k and gamma of ``rolling sds``: the rolling spring's angular frequency is at most
    ROLL_OMEGA_DT/dt for the lightest sphere involved (I = 2/5 m R^2, R_eff <= R), critically
    damped; MUSEN's rolling torque is a constant plateau, reached after mu F/k of rolling.

    k grows as 1/dt^2: a step so small that k or gamma leaves the double range is an
    InputError (``source``: the input path for the message), never an OverflowError."""
    try:
        k = 0.4 * m_min * (ROLL_OMEGA_DT / dt) ** 2
        g = 2.0 * math.sqrt(0.4 * k * m_min)
    except (OverflowError, ZeroDivisionError, ValueError):
        k = g = math.nan
    if not (math.isfinite(k) and math.isfinite(g)):
        raise InputError(source, None, f"time step {dt:g} is too small for spheres of mass "
                         f"{m_min:g}: the rolling-resistance spring (stiffness ~ m/dt^2) "
                         "overflows; use a larger time step")
    return k, g


# ----------------------------------------------------------------------------------------
# explicit (irregular) save schedules longer than this are refused: regular ones are loops
MAX_IRREGULAR_SAVES = 100_000


def _schedule(total: int, saves: SaveSteps, deletions: list[tuple[int, np.ndarray]]):
    """Actions of the script: runs (in pieces of at most 1/50 of the run, for progress),
    activity-end deletions and frames.  A stretch of regular saves with no deletion in it is
    one LAMMPS loop ("loop" ... "end"), so the script does not grow with the number of frames."""
    piece = max(1, min(math.ceil(total / 50), 2 ** 31 - 1))     # LAMMPS: run N <= 2^31-1
    acts: list[tuple] = [("run0",), ("frame", 0)]
    dels = {s: rows for s, rows in deletions}
    step, pre = 0, False

    def event(ev: int) -> None:
        nonlocal step, pre
        while step < ev:
            n = min(piece, ev - step)
            acts.append(("run", n, pre))
            pre = False
            step += n
        if ev in dels:
            acts.append(("delete", ev, dels[ev]))
            pre = True
        if ev in saves:
            acts.append(("frame", ev))

    if saves.explicit is not None:
        for ev in sorted(set(saves.explicit) | set(dels)):
            if ev > 0:
                event(ev)
        return acts
    k = saves.period
    last_regular = (total // k) * k
    for stop in sorted(d for d in dels if d > 0) + [None]:
        limit = min(stop - 1 if stop is not None else total, last_regular)
        first = (step // k + 1) * k
        if first <= limit:
            event(first)                  # its gap (or pre) may differ from the regular ones
            more = (limit - first) // k
            if more == 1:
                event(first + k)
            elif more > 1:
                name = f"fl_loop{sum(1 for a in acts if a[0] == 'loop') + 1}"
                acts.append(("loop", name, more))
                body_step, n_left = step, k
                while n_left > 0:
                    n = min(piece, n_left)
                    acts.append(("run", n, False))
                    n_left -= n
                acts.append(("frame", None))
                acts.append(("end", name))
                step = body_step + more * k
        if stop is not None:
            event(stop)
    if step < total:
        event(total)
    return acts


def _save_steps(model: GranularModel, total: int, dt: float) -> SaveSteps:
    plan = model.plan
    if plan.save_every_steps:
        k = int(plan.save_every_steps)
        if k <= 0:
            raise InputError(model.source, None, f"save interval must be > 0 steps, got {k}")
        return SaveSteps(total, period=k)
    if plan.save_every_time:
        dts = float(plan.save_every_time)
        if not dts > 0:
            raise InputError(model.source, None, f"save interval must be > 0, got {dts!r}")
        count = int(math.floor(total * dt / dts * (1 + 1e-12)))     # saves after the first
        ratio = dts / dt
        k = int(round(ratio))
        # j * ratio rounds to j * k for every j <= count: the saves are regular
        if k >= 1 and abs(ratio - k) * count + 1e-15 * ratio * count < 0.25:
            return SaveSteps(total, period=k)
        if count > MAX_IRREGULAR_SAVES:
            raise InputError(model.source, None, f"the saving step {dts:g} s is not a multiple of "
                             f"the simulation step {dt:g} s and the run saves {count + 1} times: "
                             "make the saving step a multiple of the simulation step")
        j = np.arange(0, count + 1)
        steps = {0, total}
        steps.update(int(s) for s in np.rint(j * dts / dt) if 0 <= s <= total)
        return SaveSteps(total, explicit=sorted(steps))
    return SaveSteps(total, explicit=[0, total])


def _tol_bins(values: np.ndarray, rtol: float) -> np.ndarray:
    """Integer bin per value: logarithmic bins of relative width rtol (values > 0)."""
    return np.rint(np.log(values) / math.log1p(rtol)).astype(np.int64)


def _compress_ids(ids: np.ndarray) -> str:
    ids = np.sort(np.asarray(ids, np.int64))
    if not len(ids):
        return ""
    breaks = np.flatnonzero(np.diff(ids) != 1)
    starts = np.r_[ids[0], ids[breaks + 1]]
    ends = np.r_[ids[breaks], ids[-1]]
    return " ".join(str(a) if a == b else f"{a}:{b}" for a, b in zip(starts, ends))


# ----------------------------------------------------------------------------------------
# box, binning and reach
@dataclass
class BoxFit:
    oversized: bool              # removal axes shrink-wrapped, fix evaporate at the domain faces
    domain_bins: float           # default-size neighbour bins of the box with 'f' domain faces
    bins: float                  # default-size neighbour bins of the box used
    binsize: float | None        # coarser neighbour / sort bin size, None: LAMMPS' default
    nsq: bool = False            # no bins at all: neighbor nsq, no atom sorting


def _bin_count(lo: np.ndarray, hi: np.ndarray, binsize: float, dim: int) -> float:
    """Approximate number of LAMMPS bins of size ``binsize`` over a box (float: never
    overflows; z is not binned in 2D)."""
    ext = np.maximum(np.asarray(hi, float) - np.asarray(lo, float), 0.0)[:dim]
    with np.errstate(over="ignore", invalid="ignore"):
        n = float(np.prod(ext / binsize + 1.0))
    return n if n == n else math.inf


def _fit_box(pts, box_lo, box_hi, bnd, removal_axes, dom_lo, face_hi, r_max: float,
             r_bin: float, dim: int, atoms: int) -> BoxFit:
    """Fill box_lo/box_hi (and 'm' into ``bnd`` when the domain is oversized) in place.

    LAMMPS allocates neighbour bins (and atom-sort bins) of half the neighbour cutoff over the
    whole box, 1.25 x the largest radius here (cutoff 2 r + skin r/2).  A MUSEN domain of 2 m
    around 1 mm spheres is ~4e9 bins: "Too many atom sorting bins" after minutes and GBs.
    So a domain whose box has > OVERSIZED_BINS bins and > OVERSIZED_RATIO x the bins of the
    box around spheres and wall particles is not used as the box: its axes are shrink-wrapped
    like axes without a domain, and the caller deletes spheres beyond the domain faces.

    If the box used still has more than max(BIN_CAP, BINS_PER_ATOM x atoms) bins (sparse
    spheres, a huge periodic box), the bins are made just large enough to stay below that.
    LAMMPS refuses bins > 100 x the box's thinnest extent, so a box that needs more (one sphere
    1e6 radii away from the others along one axis) gets no bins at all: ``neighbor nsq``,
    O(N^2) but only ever for such sparse scenes."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = np.maximum(np.maximum(r_max, 1e-6 * (hi - lo)), 1e-12)
    c_lo, c_hi = lo - pad, hi + pad
    for a in range(3):
        if bnd[a] == "m":
            box_lo[a], box_hi[a] = c_lo[a], c_hi[a]
    binsize = 1.25 * r_bin
    oversized = False
    domain_bins = 0.0
    if removal_axes.any():
        f_lo, f_hi = box_lo.copy(), box_hi.copy()
        m_lo, m_hi = box_lo.copy(), box_hi.copy()
        f_lo[removal_axes], f_hi[removal_axes] = dom_lo[removal_axes], face_hi[removal_axes]
        m_lo[removal_axes], m_hi[removal_axes] = c_lo[removal_axes], c_hi[removal_axes]
        domain_bins = _bin_count(f_lo, f_hi, binsize, dim)
        oversized = (domain_bins > OVERSIZED_BINS
                     and domain_bins > OVERSIZED_RATIO * _bin_count(m_lo, m_hi, binsize, dim))
        src_lo, src_hi = (m_lo, m_hi) if oversized else (f_lo, f_hi)
        box_lo[removal_axes], box_hi[removal_axes] = src_lo[removal_axes], src_hi[removal_axes]
        if oversized:
            for a in np.flatnonzero(removal_axes):
                bnd[a] = "m"
    bins = _bin_count(box_lo, box_hi, binsize, dim)
    coarse = None
    cap = max(BIN_CAP, BINS_PER_ATOM * atoms)
    if bins > cap:
        # smallest bin size with <= cap bins (bisection on log(size); monotone)
        lo_b, hi_b = math.log(binsize), math.log(max(float(np.max((box_hi - box_lo)[:dim])), binsize)) + 1.0
        for _ in range(100):
            mid = 0.5 * (lo_b + hi_b)
            if _bin_count(box_lo, box_hi, math.exp(mid), dim) > cap:
                lo_b = mid
            else:
                hi_b = mid
        coarse = math.exp(hi_b)
        if coarse > NSQ_RATIO * float(np.min(box_hi - box_lo)):
            return BoxFit(oversized, domain_bins, bins, None, True)
    return BoxFit(oversized, domain_bins, bins, coarse)


def speed_bound(model: GranularModel, rows: np.ndarray, crad: np.ndarray, mass: np.ndarray,
                smat: np.ndarray) -> float:
    """Estimate of the fastest a sphere can get without gravity and moving walls: the largest
    |v| + |w| r in the input, plus the speed the elastic (Hertz) energy of all initial
    overlaps would give the lightest sphere."""
    sp = model.spheres
    if not len(rows):
        return 0.0
    r = crad[rows]
    with np.errstate(all="ignore"):
        fast = float(np.max(np.linalg.norm(sp.velocity[rows], axis=1)
                            + np.linalg.norm(sp.omega[rows], axis=1) * r))
    if not math.isfinite(fast):
        return math.inf
    try:
        pairs = close_pairs(sp.position[rows], 2.0 * float(r.max()))
    except ImportError:                  # pragma: no cover - scipy comes with MDAnalysis
        return fast
    if not len(pairs):
        return fast
    i, j = pairs[:, 0], pairs[:, 1]
    delta = r[i] + r[j] - np.linalg.norm(sp.position[rows][i] - sp.position[rows][j], axis=1)
    sel = delta > 0
    if not sel.any():
        return fast
    i, j, delta = i[sel], j[sel], delta[sel]
    estar = np.array([getattr(model.contacts.get((min(a, b), max(a, b))), "youngs_eff", 0.0)
                      for a, b in zip(smat[i].tolist(), smat[j].tolist())], float)
    reff = r[i] * r[j] / (r[i] + r[j])
    with np.errstate(all="ignore"):
        energy = float(np.sum(8.0 / 15.0 * estar * np.sqrt(reff) * delta ** 2.5))
        fast += math.sqrt(2.0 * energy / float(mass.min()))
    return fast if math.isfinite(fast) else math.inf


def _wall_speed(wall_plans: list[WallPlan]) -> float:
    """Fastest translation speed of any moving geometry (pacing only)."""
    out = 0.0
    for wp in wall_plans:
        for _, _, vel in wp.kinematics.intervals:
            out = max(out, float(np.linalg.norm(vel)))
    return out


def _tile_counts(v: np.ndarray, spacing: float) -> np.ndarray:
    """Per triangle the grid divisions ``tile_triangles`` uses."""
    e = np.max(np.stack([np.linalg.norm(v[:, 1] - v[:, 0], axis=1),
                         np.linalg.norm(v[:, 2] - v[:, 0], axis=1),
                         np.linalg.norm(v[:, 2] - v[:, 1], axis=1)]), axis=0)
    with np.errstate(all="ignore"):
        return np.maximum(1.0, np.ceil(e / spacing - 1e-9))


def tile_estimate(v: np.ndarray, spacing: float) -> float:
    """Number of grid points ``tile_triangles`` generates (before de-duplication)."""
    if not len(v):
        return 0.0
    n = _tile_counts(v, spacing)
    return float(np.sum((n + 1) * (n + 2) / 2))


# ----------------------------------------------------------------------------------------
def plan_walls(model: GranularModel, dt: float, t_end: float) -> list[WallPlan]:
    """Representation of every geometry / plane (no files, used by ``fibrelmp check`` too)."""
    plans: list[WallPlan] = []
    tris = model.triangles
    t0 = model.plan.t_start
    for name, geom, rows in geometry_triangle_rows(model):
        v = tris.vertices[rows]
        if geom is not None:
            _check_motion(model, geom)
            kin = geometry_kinematics(geom, v, t0, t_end)
        else:
            kin = Kinematics()
        mats, counts = np.unique(tris.material[rows], return_counts=True)
        material = int(mats[np.argmax(counts)])
        shape = detect_oriented_box(v) or detect_cylinder(v) if len(rows) else None
        if shape is not None and kin.rotating and not _region_can_rotate(shape, kin):
            shape = None        # a region rotates about one fixed axis direction only
        if isinstance(shape, BoxShape):
            kind = "box"
        elif isinstance(shape, CylinderShape):
            kind = "cylinder"
        else:
            kind = "tiles"
        desc = shape.describe() if shape is not None else "tiled with frozen wall particles"
        if kin.moving:
            desc += ", moving (time-dependent motion)"
        if len(mats) > 1:
            desc += f"; mixed wall materials, uses '{model.materials[material].name}' for all"
        plans.append(WallPlan(name, kind, desc, rows, kin, material, shape))
    for k, pl in enumerate(model.planes):
        n = np.asarray(pl.normal, float)
        n = n / np.linalg.norm(n)
        axis = int(np.argmax(np.abs(n)))
        aligned = abs(abs(n[axis]) - 1) < 1e-12
        if aligned:
            ax = "xyz"[axis]
            sign = "+" if n[axis] > 0 else "-"
            desc = f"plane {ax} = {pl.point[axis]:.6g} (normal {sign}{ax}) -> fix wall/gran {ax}plane"
        else:
            desc = "plane through " + ", ".join(f"{c:.6g}" for c in pl.point) + " -> LAMMPS region plane"
        plans.append(WallPlan(f"plane {k + 1}", "plane", desc, np.zeros(0, np.int64), Kinematics(),
                              int(pl.material), plane_index=k))
    return plans


def _region_can_rotate(shape, kin: Kinematics) -> bool:
    if kin.single_axis is None:
        return False
    if isinstance(shape, BoxShape) and shape.frame is not None:
        ax, th = shape.rotation()
        return th == 0.0 or abs(abs(float(ax @ kin.single_axis)) - 1) < 1e-9
    return True


def _check_motion(model: GranularModel, geom: Geometry) -> None:
    if geom.motion_type in (2, 3):
        raise InputError(model.source, None, f"geometry '{geom.name}': force-dependent geometry "
                         "motion is not supported yet")
    if geom.motion_type not in (0, 1):
        raise InputError(model.source, None, f"geometry '{geom.name}': unknown motion type "
                         f"{geom.motion_type}")
    if any(geom.free) and geom.mass > 0:
        raise InputError(model.source, None, f"geometry '{geom.name}': free (force-driven) geometry "
                         "motion is not supported yet")


def describe_walls(model: GranularModel) -> list[str]:
    """One line per geometry / plane: how LAMMPS represents it."""
    plan = model.plan
    out = []
    for wp in plan_walls(model, plan.dt, plan.t_end):
        out.append(f"{wp.name}: {wp.description}" + (f" ({len(wp.triangle_rows)} triangles)"
                                                     if len(wp.triangle_rows) else ""))
    return out


# ----------------------------------------------------------------------------------------
def write_granular_job(model: GranularModel, folder: str | Path) -> GranularJob:
    """Write ``in.lammps`` + ``data.lammps`` for ``model`` into ``folder``."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(folder, None, f"cannot create job folder: {exc.strerror or exc}") from None
    job, script, write_data = build_granular_job(model, folder)
    write_data()
    atomic_write(job.script, script)
    for kind, message in job.warnings:
        if (kind, message) not in model.warnings:
            model.warn(kind, message)
    return job


def build_granular_job(model: GranularModel, folder: str | Path):
    """(job, script text, data-file writer) without touching the disk (MPI ranks > 0 need
    the script text only: LAMMPS reads data files on rank 0)."""
    folder = Path(folder)
    plan = model.plan
    sp = model.spheres
    dim = int(plan.dimension)
    if dim not in (2, 3):
        raise InputError(model.source, None, f"dimension must be 2 or 3, got {dim}")
    dt = float(plan.dt)
    if not (dt > 0 and math.isfinite(dt)):
        raise InputError(model.source, None, f"time step must be > 0, got {plan.dt!r}")
    span = float(plan.t_end) - float(plan.t_start)
    if not span >= 0:
        raise InputError(model.source, None, f"end time {plan.t_end!r} is before start time {plan.t_start!r}")
    steps = span / dt
    if not steps <= MAX_STEPS:
        raise InputError(model.source, None, f"time step {dt:g} is too small: {span:g} time units "
                         f"take {steps:.3g} steps, more than LAMMPS can count ({MAX_STEPS:.3g})")
    total = int(round(steps))
    t_start = float(plan.t_start)
    t_end = t_start + total * dt
    warnings: list[tuple[str, str]] = []

    # ---- which spheres are simulated
    eps = 0.5 * dt
    active_now = (sp.active_start <= t_start + eps) & (sp.active_end > t_start + eps)
    late = sp.active_start > t_start + eps
    periodic = np.array(plan.periodic, bool) if dim == 3 else np.array([plan.periodic[0], plan.periodic[1], True])
    x = np.asarray(sp.position, float)
    inside = np.ones(sp.count, bool)
    dom_lo = dom_hi = None
    if plan.domain is not None:
        dom_lo, dom_hi = (np.asarray(plan.domain[0], float), np.asarray(plan.domain[1], float))
        for a in range(dim):
            if not periodic[a]:
                inside &= (x[:, a] >= dom_lo[a]) & (x[:, a] <= dom_hi[a])
    keep = active_now & inside
    outside_rows = np.flatnonzero(active_now & ~inside)
    late_rows = np.flatnonzero(late & ~active_now)
    if len(late_rows):
        warnings.append(("late spheres", f"{len(late_rows)} sphere(s) become active only after the "
                         "start time; fibrelmp does not insert particles during a run, so they are "
                         "left out"))
    if len(outside_rows):
        warnings.append(("outside domain", f"{len(outside_rows)} sphere(s) lie outside the "
                         "simulation domain at the start and are left out"))
    rows = np.flatnonzero(keep)
    if (sp.radius[rows] <= 0).any() or (sp.mass[rows] <= 0).any():
        raise InputError(model.source, None, "every sphere needs a radius > 0 and a mass > 0")
    crad = np.where(sp.contact_radius > 0, sp.contact_radius, sp.radius)
    if (np.abs(crad[rows] - sp.radius[rows]) > 1e-12 * sp.radius[rows]).any():
        warnings.append(("contact radius", "spheres with contact radius != radius: LAMMPS has one "
                         "radius and uses the contact radius (moments of inertia 2/5 m Rc^2)"))
    # finite activity ends inside the run: delete at that step
    deletions: list[tuple[int, np.ndarray]] = []
    ends = sp.active_end[rows]
    fin = np.isfinite(ends) & (ends < t_end)
    if fin.any():
        dsteps = np.ceil((ends[fin] - t_start) / dt - 1e-9).astype(np.int64)
        for s in np.unique(dsteps):
            deletions.append((int(max(s, 1)), rows[fin][dsteps == s]))

    # ---- LAMMPS types: one per sphere material, then one per wall-tile material
    smat = sp.material[rows].astype(np.int64)
    mats = [int(m) for m in np.unique(smat)] if len(rows) else []
    type_of_mat = {m: i + 1 for i, m in enumerate(mats)}
    mass = sp.mass[rows]
    m_min = {m: float(mass[smat == m].min()) for m in mats}
    r_mean = {m: float(crad[rows][smat == m].mean()) for m in mats}
    r_min = float(crad[rows].min()) if len(rows) else 1.0
    r_max = float(crad[rows].max()) if len(rows) else 1.0
    if m_min:                       # the rolling spring of the heaviest sphere is the stiffest
        rolling_spring(max(m_min.values()), dt, model.source)

    # ---- walls
    wall_plans = plan_walls(model, dt, t_end)
    tile_spacing = TILE_SPACING_FACTOR * r_min
    tile_radius = TILE_RADIUS_FACTOR * tile_spacing
    tile_mats = sorted({wp.material for wp in wall_plans if wp.kind == "tiles"})
    type_of_tile_mat = {m: len(mats) + 1 + i for i, m in enumerate(tile_mats)}
    ntypes = len(mats) + len(tile_mats)
    if ntypes == 0:
        ntypes = 1

    # ---- box: periodic axes = periodic box; non-periodic axes with a domain = 'f' faces at the
    # domain (leaving it removes a sphere), unless the domain is oversized (see _fit_box);
    # otherwise shrink-wrapped ('m') around spheres and wall particles
    box_lo, box_hi = np.zeros(3), np.zeros(3)
    bnd = [""] * 3
    removal_axes = np.zeros(3, bool)
    face_hi = np.zeros(3)
    for a in range(3):
        if dim == 2 and a == 2:
            h = max(2.0 * r_max, 1e-9)
            box_lo[a], box_hi[a] = -h, h
            bnd[a] = "p"
        elif periodic[a]:
            pb = plan.periodic_box if plan.periodic_box is not None else plan.domain
            if pb is None:
                raise InputError(model.source, None, f"periodic {'xyz'[a]} axis needs a periodic box")
            box_lo[a], box_hi[a] = float(pb[0][a]), float(pb[1][a])
            bnd[a] = "p"
        elif dom_lo is not None:
            face_hi[a] = dom_hi[a] + 1e-12 * max(dom_hi[a] - dom_lo[a], abs(dom_hi[a]), 1e-300)
            bnd[a] = "f"
            removal_axes[a] = True
        else:
            bnd[a] = "m"
    if dim == 2 and len(rows) and np.abs(x[rows, 2]).max() > 0:
        raise InputError(model.source, None, "2D model with non-zero z coordinates")

    # how far a sphere can travel during the run (bounds the wall particles that matter); the
    # speed bound needs a pair search, so only for many wall particles or an oversized domain
    span_run = total * dt
    gabs = float(np.linalg.norm(plan.gravity))
    v_bound: list[float] = []

    def speed() -> float:
        if not v_bound:
            v_bound.append(speed_bound(model, rows, crad, mass, smat))
        return v_bound[0]

    many_tiles = any(wp.kind == "tiles" and tile_estimate(model.triangles.vertices[wp.triangle_rows],
                                                          tile_spacing) > TILE_CLIP_MIN
                     for wp in wall_plans)
    reach = math.inf
    if many_tiles and not any(wp.kinematics.moving for wp in wall_plans):
        reach = max(REACH_SAFETY * (speed() * span_run + 0.5 * gabs * span_run ** 2), 2.0 * r_max)
    keep_lo = keep_hi = None
    if len(rows) and math.isfinite(reach):
        pad_keep = reach + 2.0 * (r_max + tile_radius)
        keep_lo = x[rows].min(axis=0) - pad_keep
        keep_hi = x[rows].max(axis=0) + pad_keep
        for a in range(3):
            if bnd[a] == "p":
                keep_lo[a], keep_hi[a] = -math.inf, math.inf
    clipped: list[str] = []

    # ---- wall tiles
    tile_x, tile_type, tile_v, tile_ids_all = [], [], [], []
    next_id = int(sp.count) + 1
    tile_total = 0
    for wp in wall_plans:
        if wp.kind != "tiles":
            continue
        v = model.triangles.vertices[wp.triangle_rows]
        clip = (keep_lo is not None and not wp.kinematics.moving
                and tile_estimate(v, tile_spacing) > TILE_CLIP_MIN
                and not ((v >= keep_lo) & (v <= keep_hi)).all())
        if clip:
            p, owner = tile_triangles_within(v, tile_spacing, keep_lo - tile_radius, keep_hi + tile_radius)
        else:
            p, owner = tile_triangles(v, tile_spacing)
        side = particle_side(v, x[rows], 4.0 * r_max)
        nrm = triangle_normals(v)
        # offset tiles behind the face by their radius so the contact surface is the face
        p = p - (side[owner] * tile_radius)[:, None] * nrm[owner]
        if clip:
            near = ((p >= keep_lo) & (p <= keep_hi)).all(axis=1)
            p, owner = p[near], owner[near]
            clipped.append(wp.name)
        inbox = np.ones(len(p), bool)
        for a in range(3):
            if removal_axes[a]:
                inbox &= (p[:, a] >= dom_lo[a]) & (p[:, a] < face_hi[a])
        if not inbox.all():
            warnings.append(("wall tiles outside domain", f"{wp.name}: {int((~inbox).sum())} wall "
                             "particle(s) outside the simulation domain are left out"))
        p, owner = p[inbox], owner[inbox]
        ids = np.arange(next_id, next_id + len(p))
        next_id += len(p)
        tile_total += len(p)
        wp.tile_ids = ids
        wp.tile_owner = wp.triangle_rows[owner]
        tile_x.append(p)
        tile_type.append(np.full(len(p), type_of_tile_mat[wp.material]))
        seg = wp.kinematics.segment(t_start) if wp.kinematics.moving else None
        if seg is not None:
            dr, db = seg.rate(t_start)
            vel = p @ dr.T + db
        else:
            vel = np.zeros_like(p)
        tile_v.append(vel)
        tile_ids_all.append(ids)
        wp.description += (f" ({len(p)} wall particles, spacing {tile_spacing:.4g}, radius "
                           f"{tile_radius:.4g}{', only within reach of the spheres' if clip else ''})")
    if tile_total > 2_000_000:
        warnings.append(("many wall particles", f"{tile_total} wall particles tile the triangle "
                         "walls; the run will be slow"))
    pts = np.vstack([x[rows]] + tile_x)
    if not len(pts):
        pts = np.zeros((1, 3))
    fit = _fit_box(pts, box_lo, box_hi, bnd, removal_axes, dom_lo, face_hi, r_max,
                   max(r_max, tile_radius if tile_total else 0.0), dim, len(rows) + tile_total)
    for a in range(3):
        if not box_hi[a] > box_lo[a]:
            raise InputError(model.source, None, f"empty simulation box along {'xyz'[a]}")
    # LAMMPS re-neighbours when a sphere has moved half the skin: the same interval (at the
    # fastest speed the run can reach) paces the domain removal and the reach check below
    skin_est = 0.5 * max(r_max, tile_radius if tile_total else 0.0)
    every = CHECK_EVERY_MAX
    if fit.oversized or clipped:
        v_end = speed() + gabs * span_run + 2.0 * _wall_speed(wall_plans)
        if v_end > 0:
            every = int(min(CHECK_EVERY_MAX, max(1, math.floor(0.5 * skin_est / (v_end * dt)))))
    box_cmds: list[str] = []
    if fit.oversized:
        warnings.append(("oversized domain", f"the simulation domain spans {fit.domain_bins:.3g} "
                         "neighbour bins, far more than the spheres and walls need: the LAMMPS box "
                         "is shrink-wrapped around them and spheres beyond the domain faces are "
                         f"deleted every {every} step(s) (fix evaporate)"))
        lim = " ".join(f"{_fmt(dom_lo[a])} {_fmt(dom_hi[a])}" if removal_axes[a] else "INF INF"
                       for a in range(3))
        box_cmds += [_note("the domain is far larger than the spheres need: shrink-wrapped box, spheres "
                           "beyond the domain faces are deleted"),
                     f"region          fl_domain block {lim} side out units box",
                     f"fix             fl_domain spheres evaporate {every} {max(1, len(rows))} "
                     "fl_domain 4711"]
    if fit.binsize is not None:
        box_cmds += [_note(f"coarse bins: the box spans {fit.bins:.3g} bins of the default size"),
                     f"neigh_modify    binsize {_fmt(fit.binsize)}",
                     f"atom_modify     sort 1000 {_fmt(fit.binsize)}"]
    elif fit.nsq:
        box_cmds += [_note(f"no bins: the box spans {fit.bins:.3g} bins of the default size and is too "
                           "thin for coarse ones"),
                     f"neighbor        {_fmt(skin_est)} nsq",
                     "atom_modify     sort 0 0.0"]
    if fit.binsize is not None or fit.nsq:
        warnings.append(("sparse spheres", f"the LAMMPS box spans {fit.bins:.3g} neighbour bins of "
                         "the default size (spheres far apart): "
                         + (f"bins of {fit.binsize:.3g} are used" if fit.binsize is not None else
                            "neighbour lists are built without bins (O(N^2))")))
    if clipped and len(rows):
        lim = " ".join(f"{_fmt(keep_lo[a] + 2.0 * (r_max + tile_radius))} "
                       f"{_fmt(keep_hi[a] - 2.0 * (r_max + tile_radius))}" if math.isfinite(keep_lo[a])
                       else "INF INF" for a in range(3))
        warnings.append(("wall particles within reach", f"{', '.join(clipped)}: wall particles are "
                         f"placed only within {reach:.3g} of the spheres (twice the distance they can "
                         "travel in the run from their speeds, initial overlaps and gravity); the run "
                         "stops with an error if a sphere gets farther"))
        box_cmds += [_note("wall particles exist only within reach of the spheres: stop if one gets farther"),
                     f"region          fl_reach block {lim} side out units box",
                     "variable        fl_reach_out equal count(spheres,fl_reach)",
                     f"fix             fl_sphere_beyond_wall_particles spheres halt {every} "
                     "v_fl_reach_out > 0 error hard message yes"]

    # ---- bonds
    bonds = model.bonds
    bond_rows = np.zeros(0, np.int64)
    btypes: list[dict] = []
    btype = np.zeros(0, np.int64)
    max_bond = 0.0
    if bonds is not None and bonds.count:
        pair = bonds.pair.astype(np.int64)
        alive = ((bonds.active_start <= t_start + eps) & (bonds.active_end > t_start + eps)
                 & keep[pair[:, 0]] & keep[pair[:, 1]])
        bond_rows = np.flatnonzero(alive)
        if np.isfinite(bonds.active_end[bond_rows]).any():
            warnings.append(("bond activity end", "finite bond activity ends in the future are "
                             "ignored: bonds live until they break or a sphere is removed"))
        if len(bond_rows):
            d = bonds.diameter[bond_rows].astype(float)
            L0 = bonds.length0[bond_rows].astype(float)
            if (d <= 0).any() or (L0 <= 0).any():
                raise InputError(model.source, None, "solid bonds need diameter > 0 and initial length > 0")
            bm = bonds.material[bond_rows].astype(np.int64)
            key = np.stack([bm, _tol_bins(d, BOND_BIN_RTOL), _tol_bins(L0, BOND_BIN_RTOL)], 1)
            ukeys, btype = np.unique(key, axis=0, return_inverse=True)
            btype = btype.reshape(-1)
            for t in range(len(ukeys)):
                sel = btype == t
                btypes.append(_bond_coeffs(model, int(ukeys[t, 0]), float(d[sel].mean()),
                                           float(L0[sel].mean()), int(sel.sum())))
            dist = np.linalg.norm(x[pair[bond_rows, 0]] - x[pair[bond_rows, 1]], axis=1)
            pre = np.abs(dist - L0) > 1e-3 * L0
            if pre.any() and not periodic.any():
                warnings.append(("bond prestress", f"{int(pre.sum())} bond(s) whose sphere distance "
                                 "differs from the stored initial length by > 0.1 %: LAMMPS bonds "
                                 "start unstressed at the current distance"))
            max_bond = float(max(L0.max(), dist.max() if not periodic.any() else L0.max()))

    # ---- pair coefficients (all type pairs)
    pair_lines = []
    dt_roll = dt
    types_mat = [("s", m) for m in mats] + [("t", m) for m in tile_mats]
    if not types_mat:
        types_mat = [("none", 0)]
    any_law = None
    for i, (ki, mi) in enumerate(types_mat):
        for j in range(i, len(types_mat)):
            kj, mj = types_mat[j]
            if ki == "s" and kj == "s":
                law = _check_law(model, mi, mj)
                k, g = rolling_spring(min(m_min[mi], m_min[mj]), dt_roll)
                args = law_args(law, 2.0 * law.rolling_friction, k, g)
            elif ki == "s" and kj == "t":
                law = _check_law(model, mi, mj)
                rp = r_mean[mi]
                scale = math.sqrt((rp + tile_radius) / tile_radius)
                k, g = rolling_spring(m_min[mi], dt_roll)
                args = law_args(law, law.rolling_friction * (rp + tile_radius) / tile_radius, k, g, scale)
            else:
                args = None
            if args is not None and any_law is None:
                any_law = args
            pair_lines.append([i + 1, j + 1, args])
    fallback = any_law or "hertz/material 1.0 1.0 0.0 tangential linear_nohistory 0.0 0.0 damping coeff_restitution"
    pair_lines = [f"pair_coeff      {i} {j} {a if a is not None else fallback}" for i, j, a in pair_lines]

    # ---- wall fixes (regions and planes)
    wall_cmds: list[str] = list(box_cmds)
    var_cmds: list[str] = []
    frame_columns: list[str] = []
    mat_groups = [(type_of_mat[m], m) for m in mats]
    for gi, wp in enumerate(wall_plans):
        tag = f"w{gi + 1}"
        if wp.kind in ("box", "cylinder"):
            _region_wall(model, wp, tag, mat_groups, x[rows], smat, m_min, dt, wall_cmds, var_cmds,
                         frame_columns)
        elif wp.kind == "plane":
            _plane_wall(model, model.planes[wp.plane_index], wp, tag, mat_groups, m_min, dt, wall_cmds)
        elif wp.kind == "tiles" and wp.kinematics.moving:
            _tile_motion(wp, tag, var_cmds, wall_cmds)

    # ---- data file
    data_path = folder / DATA_NAME
    def write_data() -> None:
        _write_data(model, data_path, rows, type_of_mat, smat, crad, box_lo, box_hi, ntypes,
                    np.concatenate(tile_x) if tile_x else np.zeros((0, 3)),
                    np.concatenate(tile_type) if tile_type else np.zeros(0, np.int64),
                    np.concatenate(tile_v) if tile_v else np.zeros((0, 3)),
                    np.concatenate(tile_ids_all) if tile_ids_all else np.zeros(0, np.int64),
                    tile_radius, TILE_MASS_FACTOR * float(mass.max() if len(mass) else 1.0),
                    bond_rows, btype, len(btypes))

    # ---- script
    save_steps = _save_steps(model, total, dt)
    acts = _schedule(total, save_steps, deletions)
    skin = 0.5 * max(r_max, tile_radius if tile_total else 0.0)
    pair_cut = 2.0 * max(r_max, tile_radius if tile_total else 0.0)
    comm_cut = max(pair_cut, 1.5 * max_bond) + skin
    overlay = bool(plan.contacts_between_bonded)
    breakage = int(plan.bond_breakage) != 0
    has_bonds = len(bond_rows) > 0
    g = np.asarray(plan.gravity, float)
    if dim == 2 and g[2] != 0:
        raise InputError(model.source, None, "2D model with a z component of gravity")
    env = template_environment()
    tile_groups = [(wp, f"w{k + 1}") for k, wp in enumerate(wall_plans)
                   if wp.kind == "tiles" and wp.tile_ids is not None and len(wp.tile_ids)]
    script = env.get_template("granular.lammps.j2").render(
        model=model, fmt=_fmt, dim=dim, bnd=bnd, data_name=DATA_NAME, frames_name=FRAMES_NAME,
        bonds_name=BONDS_NAME, tiles_name=TILES_NAME, breaks_name=BREAKS_NAME,
        comm_cut=comm_cut, skin=skin, pair_lines=pair_lines, has_bonds=has_bonds,
        overlay=overlay, breakage=breakage, bond_types=btypes,
        sphere_types=[type_of_mat[m] for m in mats],
        sphere_type_names=[model.materials[m].name for m in mats],
        tile_types=[type_of_tile_mat[m] for m in tile_mats],
        tile_type_names=[model.materials[m].name for m in tile_mats],
        tile_groups=[(tag, _compress_ids(wp.tile_ids)) for wp, tag in tile_groups],
        mat_groups=mat_groups, dt=dt, t_start=t_start, gravity=g, gnorm=float(np.linalg.norm(g)),
        var_cmds=var_cmds, wall_cmds=wall_cmds, frame_columns=frame_columns,
        acts=acts, compress_ids=_compress_ids, lost=bool(removal_axes.any()),
        walls=[(wp.name, wp.description) for wp in wall_plans],
    )
    script_path = folder / SCRIPT_NAME
    job = GranularJob(
        folder=folder, script=script_path, data=data_path, total_steps=total,
        save_steps=save_steps,
        frames=folder / FRAMES_NAME,
        bond_dump=folder / BONDS_NAME if has_bonds else None,
        tile_dump=folder / TILES_NAME if tile_total else None,
        breaks=folder / BREAKS_NAME if has_bonds and breakage else None,
        walls=[(wp.name, wp.description) for wp in wall_plans], dt=dt, t_start=t_start,
        sphere_rows=rows, outside_rows=outside_rows, late_rows=late_rows, bond_rows=bond_rows,
        deletions=deletions, wall_plans=wall_plans, domain_lo=dom_lo, domain_hi=dom_hi,
        removal_axes=removal_axes, frame_columns=frame_columns, warnings=warnings)
    return job, script, write_data


def _bond_coeffs(model: GranularModel, mat: int, d: float, L0: float, count: int) -> dict:
    m = model.materials[mat]
    E, G = m.youngs, m.shear_modulus
    if not (E > 0 and math.isfinite(E) and G > 0 and math.isfinite(G)):
        raise InputError(model.source, None, f"material '{m.name}' of solid bonds needs Young's "
                         "modulus > 0 and a Poisson ratio in (-1, 0.5]")
    A = math.pi * d * d / 4.0
    I = math.pi * d ** 4 / 64.0
    breakage = int(model.plan.bond_breakage) != 0
    sn = m.normal_strength if breakage and math.isfinite(m.normal_strength) and m.normal_strength > 0 else None
    ts = m.shear_strength if breakage and math.isfinite(m.shear_strength) and m.shear_strength > 0 else None
    return dict(
        kr=E * A / L0, ks=G * A / L0, kt=2.0 * G * I / L0, kb=E * I / L0,
        frc=sn * A if sn else BIG, fsc=ts * A if ts else BIG,
        tbc=sn * math.pi * d ** 3 / 32.0 if sn else BIG,
        ttc=ts * math.pi * d ** 3 / 16.0 if ts else BIG,
        comment=f"{comment_text(m.name)} d={d:.6g} L0={L0:.6g} ({count} bonds)")


def _region_wall(model, wp: WallPlan, tag: str, mat_groups, xs, smat, m_min, dt, wall_cmds,
                 var_cmds, frame_columns) -> None:
    """Region (+ wall/gran/region fixes).  LAMMPS places a dynamic region at
    P + R_n(theta) (x_region - P) + d: with the geometry's motion x = R(t) x0 + b(t) and a
    region frame E (x0 = P + E (x_region - P)), R_n(theta) = R(t) E and d = R(t) P + b - P."""
    sh = wp.shape
    kin = wp.kinematics
    frame = isinstance(sh, BoxShape) and sh.frame is not None
    P = sh.pivot if frame else np.zeros(3)
    dyn = ""
    if kin.moving:
        for i, ax in enumerate("xyz"):
            def coeff(s, i=i):
                k = np.einsum("kij,j->ki", s.kr, P)[:, i] + s.kb[:, i]
                k[0] -= P[i]
                return k
            var_cmds.append(f"variable        {tag}_b{ax} equal \"{piecewise_expression(kin, coeff)}\"")
        dyn = f" move v_{tag}_bx v_{tag}_by v_{tag}_bz"
    if kin.rotating or frame:
        ax0, th0 = sh.rotation() if frame else (np.array([0.0, 0.0, 1.0]), 0.0)
        n = kin.single_axis if kin.rotating else ax0
        th0 = th0 * (1.0 if float(ax0 @ n) >= 0 else -1.0)
        expr = _angle_expression(kin, th0) if kin.rotating else _fmt(th0)
        var_cmds.append(f"variable        {tag}_th equal \"{expr}\"")
        dyn += (f" rotate v_{tag}_th {_fmt(P[0])} {_fmt(P[1])} {_fmt(P[2])} "
                f"{_fmt(n[0])} {_fmt(n[1])} {_fmt(n[2])}")
    if dyn:
        dyn += " units box"
    if isinstance(sh, BoxShape):
        geo = "block " + " ".join(f"{_fmt(sh.lo[a])} {_fmt(sh.hi[a])}" for a in range(3))
        opened = " ".join(f"open {f}" for f in sh.open_faces)
        if sh.flat_axis is not None:
            inside = np.zeros(len(xs), bool)
        else:
            xl = sh.to_local(xs)
            inside = ((xl > sh.lo) & (xl < sh.hi)).all(1)
    else:
        ax = "xyz"[sh.axis]
        geo = f"cylinder {ax} {_fmt(sh.c1)} {_fmt(sh.c2)} {_fmt(sh.radius)} {_fmt(sh.lo)} {_fmt(sh.hi)}"
        opened = " ".join(f"open {f}" for f in sh.open_faces)
        b, c = [k for k in range(3) if k != sh.axis]
        rho = np.hypot(xs[:, b] - sh.c1, xs[:, c] - sh.c2)
        inside = (rho < sh.radius) & (xs[:, sh.axis] > sh.lo) & (xs[:, sh.axis] < sh.hi)
    sides = []
    if inside.any():
        sides.append("in")
    if (~inside).any() or not len(xs):
        sides.append("out")
    fx, cx = [[] for _ in range(3)], [[] for _ in range(3)]
    for side in sides:
        rid = f"{tag}{side}"
        wall_cmds.append(f"region          {rid} {geo} side {side} {opened}{dyn}".rstrip())
        grp = "spheres"
        if len(sides) == 2:
            static = ""
            if frame:
                ax0, th0 = sh.rotation()
                wall_cmds.append(f"variable        {rid}_th0 equal {_fmt(th0)}")
                static = (f" rotate v_{rid}_th0 {_fmt(P[0])} {_fmt(P[1])} {_fmt(P[2])} "
                          f"{_fmt(ax0[0])} {_fmt(ax0[1])} {_fmt(ax0[2])} units box")
            wall_cmds.append(f"region          {rid}_probe {geo} side {side} {opened}{static}".rstrip())
            wall_cmds.append(f"group           {rid} region {rid}_probe")
            grp = rid
        for t, m in mat_groups:
            if not ((smat == m) & (inside if side == "in" else ~inside)).any():
                continue
            law = _check_law(model, m, wp.material)
            k, g = rolling_spring(m_min[m], dt)
            fid = f"{rid}_m{t}"
            g_use = f"m{t}" if grp == "spheres" else f"{rid}_m{t}"
            if grp != "spheres":
                wall_cmds.append(f"group           {rid}_m{t} intersect {rid} m{t}")
            wall_cmds.append(f"fix             {fid} {g_use} wall/gran/region granular "
                             f"{law_args(law, law.rolling_friction, k, g)} region {rid} contacts")
            wp.fixes.append(fid)
            for i in range(3):
                fx[i].append(f"f_{fid}[{2 + i}]")
                cx[i].append(f"f_{fid}[{5 + i}]")
        wp.region = rid
    if wp.fixes:
        for i, ax in enumerate("xyz"):
            wall_cmds.append(f"variable        {tag}_f{ax} atom \"{'+'.join(fx[i])}\"")
        for i, ax in enumerate("xyz"):
            wall_cmds.append(f"variable        {tag}_c{ax} atom \"{'+'.join(cx[i])}\"")
        wp.contact_vars = [f"v_{tag}_f{a}" for a in "xyz"] + [f"v_{tag}_c{a}" for a in "xyz"]
        frame_columns.extend(wp.contact_vars)


def _angle_expression(kin: Kinematics, th0: float = 0.0) -> str:
    """th0 + rotation angle theta(t) about kin.single_axis (all segments share the axis)."""
    n = kin.single_axis

    def coeff(s):
        ws = float(s.axis @ n) * s.w if s.w else 0.0
        return np.array([th0 + kin.angle(s.t0), ws, 0.0, 0.0])
    return piecewise_expression(kin, coeff)


def _plane_wall(model, pl, wp: WallPlan, tag: str, mat_groups, m_min, dt, wall_cmds) -> None:
    n = np.asarray(pl.normal, float)
    n = n / np.linalg.norm(n)
    axis = int(np.argmax(np.abs(n)))
    aligned = abs(abs(n[axis]) - 1) < 1e-12
    if not aligned:
        p = pl.point
        wall_cmds.append(f"region          {tag} plane {_fmt(p[0])} {_fmt(p[1])} {_fmt(p[2])} "
                         f"{_fmt(n[0])} {_fmt(n[1])} {_fmt(n[2])} side in units box")
    for t, m in mat_groups:
        law = _check_law(model, m, wp.material)
        k, g = rolling_spring(m_min[m], dt)
        fid = f"{tag}_m{t}"
        if aligned:
            pos = _fmt(pl.point[axis])
            lohi = f"{pos} NULL" if n[axis] > 0 else f"NULL {pos}"
            where = f"{'xyz'[axis]}plane {lohi}"
            wall_cmds.append(f"fix             {fid} m{t} wall/gran granular "
                             f"{law_args(law, law.rolling_friction, k, g)} {where}")
        else:
            wall_cmds.append(f"fix             {fid} m{t} wall/gran/region granular "
                             f"{law_args(law, law.rolling_friction, k, g)} region {tag}")
        wp.fixes.append(fid)


def _tile_motion(wp: WallPlan, tag: str, var_cmds, wall_cmds) -> None:
    """fix move variable: x = R(t) x0 + b(t) for every tile (x0 kept in d_x0 d_y0 d_z0)."""
    if wp.tile_ids is None or not len(wp.tile_ids):
        return
    kin = wp.kinematics

    def var(name: str, pick, rate: bool = False) -> None:
        var_cmds.append(f"variable        {tag}_{name} equal \"{piecewise_expression(kin, pick, rate)}\"")

    for i, ax in enumerate("xyz"):
        var(f"b{ax}", lambda s, i=i: s.kb[:, i])
        var(f"vb{ax}", lambda s, i=i: s.kb[:, i], True)
    move = f"fix             {tag}_move {tag}_tiles move variable "
    if not kin.rotating:
        wall_cmds.append(move + " ".join(f"v_{tag}_b{a}" for a in "xyz") + " "
                         + " ".join(f"v_{tag}_vb{a}" for a in "xyz"))
        return
    for i in range(3):
        for j in range(3):
            var(f"R{i}{j}", lambda s, i=i, j=j: s.kr[:, i, j])
            var(f"dR{i}{j}", lambda s, i=i, j=j: s.kr[:, i, j], True)
    x0 = ["d_x0", "d_y0", "d_z0"]
    for i, ax in enumerate("xyz"):
        disp = "+".join(f"(v_{tag}_R{i}{j}{'-1' if i == j else ''})*{x0[j]}" for j in range(3))
        vel = "+".join(f"v_{tag}_dR{i}{j}*{x0[j]}" for j in range(3))
        var_cmds.append(f"variable        {tag}_dx{ax} atom \"{disp}+v_{tag}_b{ax}\"")
        var_cmds.append(f"variable        {tag}_vx{ax} atom \"{vel}+v_{tag}_vb{ax}\"")
    wall_cmds.append(move + " ".join(f"v_{tag}_dx{a}" for a in "xyz") + " "
                     + " ".join(f"v_{tag}_vx{a}" for a in "xyz"))


def _write_data(model, path: Path, rows, type_of_mat, smat, crad, lo, hi, ntypes,
                tx, ttype, tv, tids, tile_radius, tile_mass, bond_rows, btype, nbtypes) -> None:
    sp = model.spheres
    n = len(rows) + len(tx)
    parts = [f"LAMMPS data file written by fibrelmp from {comment_text(model.source.name)}\n\n",
             f"{n} atoms\n{ntypes} atom types\n"]
    if len(bond_rows):
        parts.append(f"{len(bond_rows)} bonds\n{nbtypes} bond types\n")
    parts.append("\n")
    for a, name in enumerate("xyz"):
        parts.append(f"{_fmt(lo[a])} {_fmt(hi[a])} {name}lo {name}hi\n")
    r = crad[rows]
    # LAMMPS sets rmass = 4/3 pi r^3 density (also in 2D): density chosen to give the mass
    dens = sp.mass[rows] / (4.0 * math.pi / 3.0 * r * r * r)
    ids = rows + 1
    lut = np.zeros(max(type_of_mat, default=0) + 1, np.int64)
    for mat, t in type_of_mat.items():
        lut[mat] = t
    types = lut[smat]
    x = sp.position[rows]
    if len(tx):
        ids = np.r_[ids, tids]
        types = np.r_[types, ttype]
        diam = np.r_[2.0 * r, np.full(len(tx), 2.0 * tile_radius)]
        dens = np.r_[dens, np.full(len(tx), tile_mass / (4.0 * math.pi / 3.0 * tile_radius ** 3))]
        x = np.vstack([x, tx])
    else:
        diam = 2.0 * r
    parts.append("\nAtoms # bpm/sphere\n\n")
    parts.append(_block("%d 0 %d %.17g %.17g %.17g %.17g %.17g\n",
                        [ids, types, diam, dens, x[:, 0], x[:, 1], x[:, 2]]))
    v = sp.velocity[rows]
    w = sp.omega[rows]
    if len(tx):
        v = np.vstack([v, tv])
        w = np.vstack([w, np.zeros_like(tv)])
    parts.append("\nVelocities\n\n")
    parts.append(_block("%d %.17g %.17g %.17g %.17g %.17g %.17g\n",
                        [ids, v[:, 0], v[:, 1], v[:, 2], w[:, 0], w[:, 1], w[:, 2]]))
    if len(bond_rows):
        b = model.bonds.pair[bond_rows].astype(np.int64) + 1
        parts.append("\nBonds\n\n")
        parts.append(_block("%d %d %d %d\n", [np.arange(1, len(b) + 1), btype + 1, b[:, 0], b[:, 1]]))
    atomic_write(path, "".join(parts))
