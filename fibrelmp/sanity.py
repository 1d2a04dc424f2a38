"""Derived quantities ``fibrelmp check`` prints so a user can sanity-check an input's time
step, and the warnings they trigger.  Plain physics on the neutral models, no LAMMPS.

* granular inputs (MUSEN, DEMDF): the Hertz contact duration against the time step;
* FibreNet: the shortest spring oscillation period against the time step;
* any run under MPI: particles per rank against the size below which more ranks are slower
  (``rank_check``).

Either warns when the step exceeds ``STEP_FRACTION`` of the time it has to resolve: a
contact or an oscillation spanning fewer than ten steps is integrated poorly, and one
spanning fewer than about three is unstable.
"""

from __future__ import annotations

import math
import re

import numpy as np

from fibrelmp.granmodel import GranularModel
from fibrelmp.model import Model
from fibrelmp.units import system

STEP_FRACTION = 0.1
# 2 * integral_0^1 dx / sqrt(1 - x^(5/2)): the duration of an elastic Hertz impact in units of
# (peak overlap / impact speed) (Johnson 1985)
HERTZ_DURATION = 2.943


def close_pairs(points: np.ndarray, reach: float) -> np.ndarray:
    """Index pairs (k, 2), i < j, of points whose Euclidean distance is <= ``reach``.

    Robust for any finite coordinates: ``cKDTree`` with the Euclidean metric squares the
    coordinate differences and overflows beyond ~1e154 (``ValueError: Encountering floating
    point overflow``), and the tree's extent overflows when the points span more than the
    double range.  So candidates come from the Chebyshev metric (p = inf, no squares) on
    coordinates scaled by an exact power of two, and are confirmed with the true distance
    (the difference of two candidates is at most ``reach`` per axis, so it cannot overflow).
    """
    x = np.asarray(points, float)
    if len(x) < 2 or not reach >= 0:
        return np.zeros((0, 2), np.int64)
    from scipy.spatial import cKDTree

    big = float(np.abs(x).max())
    scale = 1.0
    if big > 1e300:                      # keep max - min finite; exact (power of two)
        scale = 2.0 ** -4
    r = reach * scale
    if not math.isfinite(r):
        r = np.inf
    pairs = cKDTree(x * scale).query_pairs(r, p=np.inf, output_type="ndarray")
    if not len(pairs):
        return np.zeros((0, 2), np.int64)
    d = x[pairs[:, 0]] - x[pairs[:, 1]]
    with np.errstate(over="ignore"):
        # hypot-style scaling keeps the norm finite even for differences near the double max
        m = np.abs(d).max(axis=1)
        safe = np.where(m > 0, m, 1.0)
        dist = m * np.sqrt(((d / safe[:, None]) ** 2).sum(axis=1))
    return pairs[dist <= reach].astype(np.int64)


def hertz_peak_overlap(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
    """Peak overlap of an elastic Hertz impact at normal speed ``speed``:
    ``(15 m* v^2 / (16 E* sqrt(R*)))^(2/5)``."""
    return (15.0 * m_eff * speed ** 2 / (16.0 * e_star * math.sqrt(r_eff))) ** 0.4


def hertz_contact_time(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
    """Duration of that impact; faster impacts are shorter (t ~ v^-1/5)."""
    return HERTZ_DURATION * hertz_peak_overlap(m_eff, r_eff, e_star, speed) / speed


def speed_bounds(velocity: np.ndarray, gravity: np.ndarray, extent: np.ndarray) -> np.ndarray:
    """Per sphere: the fastest it can move, ``sqrt(|v|^2 + 2 |g| L)``: its own speed plus
    what gravity can add over the extent ``L`` of the domain along g."""
    g = float(np.linalg.norm(gravity))
    fall = 0.0
    if g > 0:
        fall = float(np.sum(np.abs(gravity) / g * extent))   # extent of the box along g
    return np.sqrt(np.einsum("ij,ij->i", velocity, velocity) + 2.0 * g * fall)


def pair_speed(bounds_a: np.ndarray, bounds_b: np.ndarray | None) -> float:
    """Largest possible approach speed: same group -> its two fastest; else the fastest of
    each; ``bounds_b`` None -> a wall (the sphere's own bound).  0 when no such pair exists."""
    if bounds_b is None:
        return float(bounds_a.max()) if bounds_a.size else 0.0
    if bounds_a is bounds_b:
        return float(np.sort(bounds_a)[-2:].sum()) if bounds_a.size >= 2 else 0.0
    if not bounds_a.size or not bounds_b.size:
        return 0.0
    return float(bounds_a.max() + bounds_b.max())


def granular_extent(model: GranularModel) -> np.ndarray:
    """The box gravity can accelerate spheres over: the domain, else the spheres' and walls'
    bounding box grown by a diameter."""
    if model.plan.domain is not None:
        return model.plan.domain[1] - model.plan.domain[0]
    s = model.spheres
    parts = [s.position] + [p.point[None, :] for p in model.planes]
    if model.triangles is not None and model.triangles.count:
        parts.append(model.triangles.vertices.reshape(-1, 3))
    points = np.vstack(parts)
    return points.max(axis=0) - points.min(axis=0) + 2 * float(s.contact_radius.max(initial=0))


def granular_contact_time(model: GranularModel) -> tuple[float, str, str] | None:
    """The shortest contact duration (Hertz's, or the PP / PW model's ``plan.pp_contact_time``,
    ``plan.pw_contact_time``) of the contacts the input can have, at the fastest
    approach: for each material pair with a contact law, the smallest spheres of each
    (m* = m1 m2 / (m1 + m2), R* = r1 r2 / (r1 + r2); a sphere-sphere pair of one material
    needs two spheres of it) approaching at the sum of the two fastest speed bounds, and
    for a wall material, the smallest sphere (m* = m, R* = r) at its material's fastest
    bound (``speed_bounds``).  Where nothing can move (no speed, no gravity), at an
    approach speed of 1.  (time, "material-material", law); None when there are no spheres.
    DEMDF's reader sizes its contact stiffness and time step by this same figure."""
    s = model.spheres
    if s.count == 0:
        return None
    bounds = speed_bounds(s.velocity, model.plan.gravity, granular_extent(model))
    walls = {int(p.material) for p in model.planes}
    if model.triangles is not None and model.triangles.count:
        walls |= {int(m) for m in np.unique(model.triangles.material)}
    smallest: dict[int, tuple[float, float, np.ndarray]] = {}
    for mat in np.unique(s.material).tolist():
        rows = np.flatnonzero(s.material == mat)
        # the contact time grows as (m^2 / r)^(1/5): the smallest sphere of a material
        k = rows[int(np.argmin(s.mass[rows] ** 2 / s.contact_radius[rows]))]
        smallest[mat] = (float(s.mass[k]), float(s.contact_radius[k]), bounds[rows])
    partners = []                      # (m*, R*, E*, approach speed, name, duration law)
    pp_time = model.plan.pp_contact_time or hertz_contact_time
    pp_law = model.plan.pp_contact_law if model.plan.pp_contact_time else "Hertz"
    pw_time = model.plan.pw_contact_time or hertz_contact_time
    pw_law = model.plan.pw_contact_law if model.plan.pw_contact_time else "Hertz"
    for (a, b), law in model.contacts.items():
        if not law.youngs_eff > 0:
            continue
        name = f"{model.materials[a].name}-{model.materials[b].name}"
        if a in smallest and b in smallest:
            (ma, ra, va), (mb, rb, vb) = smallest[a], smallest[b]
            partners.append((ma * mb / (ma + mb), ra * rb / (ra + rb), law.youngs_eff,
                             pair_speed(va, va if a == b else vb), name, pp_time, pp_law))
        for sphere, wall in ((a, b), (b, a)):
            if sphere in smallest and wall in walls:
                m, r, v = smallest[sphere]
                partners.append((m, r, law.youngs_eff, pair_speed(v, None), name, pw_time, pw_law))
    possible = [p for p in partners if p[3] > 0] or [p[:3] + (1.0,) + p[4:] for p in partners]
    best = None
    for m_eff, r_eff, e_star, speed, name, contact_time, law in possible:
        tc = contact_time(m_eff, r_eff, e_star, speed)
        if best is None or tc < best[0]:
            best = (tc, name, law)
    return best


def spring_period(model: Model) -> tuple[float, int] | None:
    """Shortest oscillation period 2 pi sqrt(mu / k) over the springs (mu the reduced mass of
    the two beads; a mass-0 bead moves at constant velocity, i.e. acts as infinitely heavy),
    and that spring's row.  None without a spring that can oscillate."""
    p, b = model.particles, model.bonds
    if not p.count or not b.count:
        return None
    inv = np.zeros(p.count)
    np.divide(1.0, p.masses, out=inv, where=p.masses > 0)
    omega2 = b.k * (inv[b.atoms[:, 0]] + inv[b.atoms[:, 1]])
    if not (omega2 > 0).any():
        return None
    row = int(np.argmax(omega2))
    return 2 * math.pi / math.sqrt(float(omega2[row])), row


def units_line(model: Model | GranularModel) -> str:
    return f"units        {system(model.units).describe()}"


def spring_check(model: Model) -> list[str]:
    """The spring period against the time step; warns (kind "time step")."""
    lines: list[str] = []
    found = spring_period(model)
    dt = model.dynamics.dt
    if found is not None:
        period, row = found
        i, j = (int(x) for x in model.bonds.atoms[row])
        lines.append(f"spring period {period:.4g} (shortest, spring {row}: beads {i}-{j}) = "
                     f"{period / dt:.1f} time steps")
        if dt > STEP_FRACTION * period:
            model.warn("time step", f"the time step {dt:g} exceeds 1/10 of the shortest spring "
                       f"period {period:.4g} (spring {row}, beads {i}-{j}): the run will be "
                       "inaccurate or blow up")
    return lines


def contact_check(model: GranularModel) -> list[str]:
    """The Hertz contact time against the time step; warns (kind "time step")."""
    lines: list[str] = []
    plan = model.plan
    with np.errstate(all="ignore"):
        tc = granular_contact_time(model)
    if tc is not None and math.isfinite(plan.dt) and plan.dt > 0 and math.isfinite(tc[0]):
        lines.append(f"contact time {tc[0]:.3g} ({tc[2]}, {tc[1]}, fastest approach in the input) "
                     f"= {tc[0] / plan.dt:.1f} time steps")
        if plan.dt > STEP_FRACTION * tc[0]:
            model.warn("time step", f"the time step {plan.dt:g} exceeds 1/10 of the {tc[2]} "
                       f"contact time {tc[0]:.3g}: contacts will be poorly resolved")
    return lines


def time_step_check(model: Model | GranularModel) -> list[str]:
    """``spring_check`` or ``contact_check``, by the kind of model (``run`` warns before it
    starts, as ``check`` does)."""
    if isinstance(model, GranularModel):
        return contact_check(model)
    if isinstance(model, Model):
        return spring_check(model)
    return []                  # a CardioProof case checks its own step (cardioproof.job)


# Particles per MPI rank below which a run is faster on fewer ranks (measured on 2 cores,
# docs/performance.md#ranks-and-threads): a rank's fixed costs (ghost exchange every step,
# every rank reading the input) outweigh its share of the work on smaller systems
MIN_PER_RANK = {"beads": 2_000, "spheres": 1_000}


def rank_check(model: Model | GranularModel, ranks: int) -> None:
    """Warns (kind "ranks"; said once, on rank 0, like every warning) when ``ranks`` MPI
    ranks leave fewer particles per rank than ``MIN_PER_RANK`` (not measured for SPH cases)."""
    if not isinstance(model, (Model, GranularModel)):
        return
    granular = isinstance(model, GranularModel)
    what = "spheres" if granular else "beads"
    count = model.spheres.count if granular else model.particles.count
    limit = MIN_PER_RANK[what]
    if ranks > 1 and count < limit * ranks:
        best = max(1, count // limit)
        named = what if count != 1 else what[:-1]          # 1 sphere, 2 spheres
        share = f"{count // ranks} per rank" if count >= ranks else "fewer than one per rank"
        model.warn("ranks", f"{ranks} MPI ranks for {count} {named} ({share}): below "
                   f"~{limit} {what} per rank more ranks make the run slower; use "
                   f"{'1 (no mpiexec)' if best == 1 else f'mpiexec -n {best}'} (docs/performance.md)")


def time_step_scale(model: Model | GranularModel) -> dict | None:
    """The time the step has to resolve, for the run summary: ``{"name": "spring period" |
    "contact time", "value", "where"}`` (None: no spring / no sphere with a contact law)."""
    if isinstance(model, GranularModel):
        with np.errstate(all="ignore"):
            found = granular_contact_time(model)
        if found is None or not math.isfinite(found[0]):
            return None
        return {"name": "contact time", "value": found[0],
                "where": f"{found[2]}, {found[1]}, fastest approach in the input"}
    found = spring_period(model)
    if found is None:
        return None
    period, row = found
    i, j = (int(x) for x in model.bonds.atoms[row])
    return {"name": "spring period", "value": period, "where": f"spring {row}: beads {i}-{j}"}


# LAMMPS errors of atoms that moved too far in one step (a blown-up run)
_BLOW_UP = re.compile(r"(Bond|Angle|Dihedral|Improper) atoms? .*missing|Lost atoms|Non-numeric atom coords|"
                      r"Out of range atoms|extent > half of periodic box|atom missing in box size check|"
                      r"Neighbor list overflow|Too many neighbor bins|domain too large for neighbor bins",
                      re.IGNORECASE)


def blow_up_hint(model: Model | GranularModel, message: str) -> str | None:
    """The hint a LAMMPS error gets when atoms flew apart: the time step warning ``run``
    printed before it started, or the figures to check; None for other errors."""
    if not _BLOW_UP.search(message):
        return None
    warned = [text for kind, text in model.warnings if kind == "time step"]
    if warned:
        return (f"hint: atoms moved too far in one step, as the 'time step' warning above "
                f"foresaw ({warned[0].split(':')[0]}): run again with a smaller time step")
    if not isinstance(model, (Model, GranularModel)):
        return ("hint: atoms moved too far in one step: the SPH run became unstable; a higher "
                "fluid.sound_speed (with its smaller step), more artificial_viscosity or a finer "
                "spacing usually help")
    what = "Hertz contact time" if isinstance(model, GranularModel) else "shortest spring period"
    return (f"hint: atoms moved too far in one step: the run became unstable. `fibrelmp check` "
            f"shows the time step against the {what}; a smaller step, stiffer walls or less "
            "overlap at the start usually help")


# ---------------------------------------------------------------------------------------
# runs that cannot finish: steps LAMMPS cannot count, output no disk holds, years of CPU
MAXSMALLINT = 2 ** 31 - 1         # LAMMPS: the steps of one 'run', a 'variable loop' count
MAXBIGINT = 2 ** 63 - 1           # LAMMPS: the time step counter
# the estimate (docs/python.md "Refused before LAMMPS starts"): the work dump alone holds a
# header per frame and a row of at least id, type and three %.17g coordinates per particle;
# a result written as one file per frame (DEMDF snapshots, VTK frames) takes a disk block each
FRAME_HEADER_BYTES = 150
ROW_BYTES = 64
FILE_BYTES = 4096
# optimistic LAMMPS speeds: no run goes faster, so a run refused by them cannot finish
FASTEST_STEPS_PER_SECOND = 1e6            # LAMMPS's own overhead per step, tiny systems
FASTEST_PARTICLE_STEPS_PER_SECOND = 1e9   # per MPI rank
LONGEST_RUN_SECONDS = 30 * 86400
# a LAMMPS 'run' command sets up again (neighbour lists, forces): 0.44 ms measured for one-step
# FibreNet relaxation chunks of the example network on this machine; 1e-4 s is optimistic
FASTEST_RUNS_PER_SECOND = 1e4
LONG_RUN_SECONDS = 86400                   # beyond: warned (kind 'long run'), still run


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB", "EB"):
        if n < 1000 or unit == "EB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{n:.0f} B"
        n /= 1000
    return f"{n:.3g} EB"


def _duration(seconds: float) -> str:
    days = seconds / 86400
    return f"{days / 365.25:.3g} years" if days > 730 else f"{days:.3g} days"


# a run beyond this many steps is refused even with --yes-i-mean-it: 31 years at the fastest
# LAMMPS speed, and its job could not even be rendered (millions of 'run' pieces)
MOST_STEPS = 10 ** 15


def planned_steps(model) -> int | None:
    """The time steps a model's run takes, known before its job is rendered (None: only the
    rendered job says)."""
    plan = getattr(model, "plan", None)
    stages = getattr(plan, "stages", None)
    if stages is not None:                                  # FibreNet: relaxation + production
        return int(sum(st.steps for st in stages))
    if isinstance(model, GranularModel):
        span = (plan.t_end - plan.t_start) / plan.dt
        return int(math.ceil(span)) if math.isfinite(span) else MAXBIGINT + 1
    return None


def check_steps(model, where, allow_huge: bool) -> None:
    """Refuse (InputError at ``where``) before the job is rendered a run of more steps than
    LAMMPS counts, than ``MOST_STEPS``, or (unless ``allow_huge``) than it can make in
    ``LONGEST_RUN_SECONDS`` at ``FASTEST_STEPS_PER_SECOND``."""
    from fibrelmp.errors import InputError

    steps = planned_steps(model)
    if steps is None:
        return
    if steps > MAXBIGINT:
        raise InputError(where, None, f"the run has {steps} time steps; LAMMPS counts at most "
                         f"{MAXBIGINT} (2^63-1)")
    seconds = _least_seconds(model, steps)
    if steps > MOST_STEPS or (seconds > LONGEST_RUN_SECONDS and not allow_huge):
        override = "" if steps > MOST_STEPS else ", or give --yes-i-mean-it"
        raise InputError(where, None, f"the run has {steps} time steps: at least "
                         f"{_duration(seconds)} even at {FASTEST_STEPS_PER_SECOND:.0e} steps/s "
                         f"and {FASTEST_RUNS_PER_SECOND:.0e} LAMMPS runs (chunks) per second "
                         f"(LAMMPS is slower): run fewer steps{override}")


def long_run_check(model) -> None:
    """Warn (kind 'long run') before a run that takes more than a day even at the optimistic
    speeds ``check_steps`` refuses beyond a month with."""
    steps = planned_steps(model)
    if steps is None or not hasattr(model, "warn"):
        return
    seconds = _least_seconds(model, steps)
    if seconds > LONG_RUN_SECONDS:
        model.warn("long run", f"the run has {steps} time steps in {planned_runs(model)} LAMMPS runs (chunks): "
                   f"at least {_duration(seconds)} even at {FASTEST_STEPS_PER_SECOND:.0e} steps/s "
                   f"and {FASTEST_RUNS_PER_SECOND:.0e} runs/s (the progress line gives the ETA)")


def _least_seconds(model, steps: int) -> float:
    """The wall time of ``steps`` steps at the fastest speeds LAMMPS could reach (per step, and
    per separate 'run' command)."""
    return steps / FASTEST_STEPS_PER_SECOND + planned_runs(model) / FASTEST_RUNS_PER_SECOND


def planned_runs(model) -> int:
    """The separate LAMMPS 'run' commands a FibreNet model's stages make (one per chunk; each
    sets the system up again: neighbour lists, forces), known before rendering; 0 otherwise."""
    stages = getattr(getattr(model, "plan", None), "stages", None) or []
    return int(sum(-(-st.steps // max(st.chunk, 1)) for st in stages if st.steps > 0))


def needs_job(model, outputs) -> bool:
    """Must the job be rendered to tell whether the run can finish?  Not when even a frame at
    every step (``planned_steps`` + 1 frames) fits the estimate: every count then fits a
    LAMMPS int, and the output and the time are within bounds (rendering a large model twice
    costs a tenth of a second per 50,000 beads)."""
    steps = planned_steps(model)
    if steps is None or steps >= MAXSMALLINT - 1:
        return True
    n = particle_count(model)
    frames = steps + 1
    size = frames * (FRAME_HEADER_BYTES + n * ROW_BYTES + (FILE_BYTES if outputs.patterns else 0))
    seconds = n * steps / FASTEST_PARTICLE_STEPS_PER_SECOND
    folders = [outputs.work] + [f.parent for f in outputs.files[:1]]
    return seconds > LONGEST_RUN_SECONDS or any(size > _free_space(f)[0] for f in folders)


def particle_count(model) -> int:
    """Beads, spheres or SPH particles of a model (for the estimates; 0 when unknown)."""
    for name in ("particles", "spheres"):
        group = getattr(model, name, None)
        if group is not None and hasattr(group, "count"):
            return int(group.count)
    return 0


def representable(rendered, where) -> None:
    """Refuse a job whose step counts LAMMPS cannot hold (an InputError at ``where``): a
    'run' or loop count above 2^31-1, a total above 2^63-1."""
    from fibrelmp.errors import InputError

    if rendered.total_steps > MAXBIGINT:
        raise InputError(where, None, f"the run has {rendered.total_steps} time steps; LAMMPS "
                         f"counts at most {MAXBIGINT} (2^63-1)")
    for number, line in enumerate(rendered.text.splitlines(), 1):
        words = line.split()
        count = None
        if words[:1] == ["run"] and len(words) > 1:
            count = words[1]
        elif words[:1] == ["variable"] and len(words) > 3 and words[2] == "loop":
            count = words[-1] if len(words) > 4 and words[4].isdigit() else words[3]
        if count is not None and count.isdigit() and int(count) > MAXSMALLINT:
            raise InputError(where, None, f"the job needs '{line.strip()}' ({rendered.script.name}"
                             f" line {number}): more than the {MAXSMALLINT} (2^31-1) LAMMPS takes "
                             "there; run fewer steps or save fewer frames")


def _free_space(folder) -> tuple[int, int]:
    """(free bytes, device) of the file system ``folder`` is (or will be) on."""
    import os
    import shutil
    from pathlib import Path

    probe = Path(folder)
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    return shutil.disk_usage(probe).free, os.stat(probe).st_dev


def run_budget(jobs: list[tuple[object, object]], outputs, ranks: int, allow_huge: bool,
               disk: bool = True) -> None:
    """Refuse, as an InputError before anything is written, a run that cannot finish: the
    estimated output (``jobs``: (model, rendered job) pairs) larger than the free space where
    it goes, or an optimistic wall time beyond ``LONGEST_RUN_SECONDS``.  ``allow_huge``
    (run --yes-i-mean-it) skips both (step counts LAMMPS cannot hold are refused always).
    ``disk``: check the free space (MPI: rank 0, which writes every file)."""
    from fibrelmp.errors import InputError

    for _, rendered in jobs:
        representable(rendered, outputs.source)
    if allow_huge:
        return
    per_file = bool(outputs.patterns)                 # numbered files: one per frame
    results_folder = (outputs.files[0].parent if outputs.files else
                      outputs.patterns[0][0] if outputs.patterns else outputs.work)
    need: dict[int, list] = {}                        # device -> [bytes, folder, what]
    seconds = 0.0
    frames_total = 0
    for model, rendered in jobs:
        n = particle_count(model)
        try:
            frames = len(rendered.schedule)
        except TypeError:
            frames = 0
        frames_total += frames
        steps = rendered.total_steps
        seconds += max(steps / FASTEST_STEPS_PER_SECOND,
                       n * steps / (FASTEST_PARTICLE_STEPS_PER_SECOND * max(ranks, 1)))
        for folder, size in ((rendered.folder, frames * (FRAME_HEADER_BYTES + n * ROW_BYTES)),
                             (results_folder, frames * FILE_BYTES if per_file else 0)):
            free, device = _free_space(folder)
            entry = need.setdefault(device, [0, folder, free])
            entry[0] += size
    if seconds > LONGEST_RUN_SECONDS:
        raise InputError(outputs.source, None, f"the run would take at least {_duration(seconds)} "
                         f"even at {FASTEST_STEPS_PER_SECOND:.0e} steps/s and "
                         f"{FASTEST_PARTICLE_STEPS_PER_SECOND:.0e} particle-steps/s per MPI rank "
                         f"(LAMMPS is slower): run fewer steps, or give --yes-i-mean-it")
    for size, folder, free in need.values():
        if disk and size > free:
            raise InputError(outputs.source, None, f"the run would write about {_size(size)} "
                             f"({frames_total} saved frames) but {folder} has {_size(free)} free: "
                             "save fewer frames or run less, free space, or give --yes-i-mean-it")
