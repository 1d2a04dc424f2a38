"""Derived quantities ``fibrelmp check`` prints so a user can sanity-check an input's time
step, and the warnings they trigger.  Plain physics on the particle models, no LAMMPS.

* the time the step has to resolve, which each model family computes itself
  (``ParticleModel.time_scale``: granular inputs (MUSEN, DEMDF) the Hertz contact duration,
  FibreNet the shortest spring oscillation period; a CardioProof case checks its own step);
* any run under MPI: particles per rank against the size below which more ranks are slower
  (``rank_check``, the family's ``min_per_rank``).

Either warns when the step exceeds ``STEP_FRACTION`` of the time it has to resolve: a
contact or an oscillation spanning fewer than ten steps is integrated poorly, and one
spanning fewer than about three is unstable.  This module asks a model; it never switches on
its family.
"""

from __future__ import annotations

import math
import re

from typing import TYPE_CHECKING

import numpy as np

from fibrelmp.units import system

if TYPE_CHECKING:
    from fibrelmp.particles import ParticleModel

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


def units_line(model: ParticleModel) -> str:
    return f"units        {system(model.units).describe()}"


def time_step_check(model: ParticleModel) -> list[str]:
    """The model's time scale (``time_scale``) against its time step: ``check``'s line, and a
    warning (kind "time step") when the step exceeds ``STEP_FRACTION`` of it (``run`` warns
    before it starts, as ``check`` does)."""
    scale = model.time_scale()
    dt = model.given_time_step()
    if scale is None or dt is None or not (math.isfinite(dt) and dt > 0):
        return []
    lines = [f"{scale.line} = {scale.value / dt:.1f} time steps"]
    if dt > STEP_FRACTION * scale.value:
        model.warn("time step", f"the time step {dt:g} exceeds 1/10 of the {scale.warning}")
    return lines


def rank_check(model: ParticleModel, ranks: int) -> None:
    """Warns (kind "ranks"; said once, on rank 0, like every warning) when ``ranks`` MPI
    ranks leave fewer particles per rank than the family's ``min_per_rank`` (measured on 2
    cores, docs/performance.md#ranks-and-threads: a rank's fixed costs, ghost exchange every
    step and every rank reading the input, outweigh its share of the work on smaller systems;
    not measured for SPH cases)."""
    limit = model.min_per_rank
    if limit is None:
        return
    what = model.particle_noun
    count = model.particle_count
    if ranks > 1 and count < limit * ranks:
        best = max(1, count // limit)
        named = what if count != 1 else what[:-1]          # 1 sphere, 2 spheres
        share = f"{count // ranks} per rank" if count >= ranks else "fewer than one per rank"
        model.warn("ranks", f"{ranks} MPI ranks for {count} {named} ({share}): below "
                   f"~{limit} {what} per rank more ranks make the run slower; use "
                   f"{'1 (no mpiexec)' if best == 1 else f'mpiexec -n {best}'} (docs/performance.md)")


def time_step_scale(model: ParticleModel) -> dict | None:
    """The time the step has to resolve, for the run summary: ``{"name": "spring period" |
    "contact time", "value", "where"}`` (None: no spring / no sphere with a contact law)."""
    scale = model.time_scale()
    if scale is None:
        return None
    return {"name": scale.name, "value": scale.value, "where": scale.where}


# LAMMPS errors of atoms that moved too far in one step (a blown-up run)
_BLOW_UP = re.compile(r"(Bond|Angle|Dihedral|Improper) atoms? .*missing|Lost atoms|Non-numeric atom coords|"
                      r"Out of range atoms|extent > half of periodic box|atom missing in box size check|"
                      r"Neighbor list overflow|Too many neighbor bins|domain too large for neighbor bins",
                      re.IGNORECASE)


def blow_up_hint(model: ParticleModel, message: str) -> str | None:
    """The hint a LAMMPS error gets when atoms flew apart: the time step warning ``run``
    printed before it started, or the family's advice (``unstable_hint``); None for other
    errors."""
    if not _BLOW_UP.search(message):
        return None
    warned = [text for kind, text in model.warnings if kind == "time step"]
    if warned:
        return (f"hint: atoms moved too far in one step, as the 'time step' warning above "
                f"foresaw ({warned[0].split(':')[0]}): run again with a smaller time step")
    return f"hint: atoms moved too far in one step: {model.unstable_hint()}"


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


def check_steps(model: ParticleModel, where, allow_huge: bool) -> None:
    """Refuse (InputError at ``where``) before the job is rendered a run of more steps than
    LAMMPS counts, than ``MOST_STEPS``, or (unless ``allow_huge``) than it can make in
    ``LONGEST_RUN_SECONDS`` at ``FASTEST_STEPS_PER_SECOND``."""
    from fibrelmp.errors import InputError

    steps = model.planned_steps()
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


def long_run_check(model: ParticleModel) -> None:
    """Warn (kind 'long run') before a run that takes more than a day even at the optimistic
    speeds ``check_steps`` refuses beyond a month with."""
    steps = model.planned_steps()
    if steps is None:
        return
    seconds = _least_seconds(model, steps)
    if seconds > LONG_RUN_SECONDS:
        model.warn("long run", f"the run has {steps} time steps in {planned_runs(model)} LAMMPS runs (chunks): "
                   f"at least {_duration(seconds)} even at {FASTEST_STEPS_PER_SECOND:.0e} steps/s "
                   f"and {FASTEST_RUNS_PER_SECOND:.0e} runs/s (the progress line gives the ETA)")


def _least_seconds(model: ParticleModel, steps: int) -> float:
    """The wall time of ``steps`` steps at the fastest speeds LAMMPS could reach (per step, and
    per separate 'run' command)."""
    return steps / FASTEST_STEPS_PER_SECOND + planned_runs(model) / FASTEST_RUNS_PER_SECOND


def planned_runs(model: ParticleModel) -> int:
    """The separate LAMMPS 'run' commands a model's run makes (each sets the system up again:
    neighbour lists, forces), known before rendering (``ParticleModel.planned_runs``)."""
    return model.planned_runs()


def needs_job(model: ParticleModel, outputs) -> bool:
    """Must the job be rendered to tell whether the run can finish?  Not when even a frame at
    every step (``planned_steps()`` + 1 frames) fits the estimate: every count then fits a
    LAMMPS int, and the output and the time are within bounds (rendering a large model twice
    costs a tenth of a second per 50,000 beads)."""
    steps = model.planned_steps()
    if steps is None or steps >= MAXSMALLINT - 1:
        return True
    n = model.particle_count
    frames = steps + 1
    size = frames * (FRAME_HEADER_BYTES + n * ROW_BYTES + (FILE_BYTES if outputs.patterns else 0))
    seconds = n * steps / FASTEST_PARTICLE_STEPS_PER_SECOND
    folders = [outputs.work] + [f.parent for f in outputs.files[:1]]
    return seconds > LONGEST_RUN_SECONDS or any(size > _free_space(f)[0] for f in folders)


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
        n = model.particle_count
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
