"""Time in a granular job: the run's length in steps, the steps a frame is saved at, and the
sequence of actions (runs, activity-end deletions, frames, loops) the script performs."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_flow import STOP_PRINT
from fibrelmp.translate.granular.musen_clock import MusenClock, musen_run
from fibrelmp.translate.steps import SaveSteps, run_piece

MAX_STEPS = 2.0 ** 63 - 1   # LAMMPS counts time steps in a 64-bit integer
# explicit (irregular) save schedules longer than this are refused: regular ones are loops
MAX_IRREGULAR_SAVES = 100_000


@dataclass
class RunTime:
    dim: int                 # 2 or 3
    dt: float
    total: int               # time steps of the run
    t_start: float
    t_end: float             # t_start + total * dt (MUSEN: its summed time)
    saves: SaveSteps | None = None       # MUSEN: cmusen's saved steps
    clock: MusenClock | None = None      # MUSEN: its summed time at a step (else t_start + step dt)


def run_time(model: GranularModel) -> RunTime:
    """Dimension, time step and number of steps of the run (checked)."""
    plan = model.plan
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
    t_start = float(plan.t_start)
    if model.kind == "musen":
        # cmusen's loop: summed time, saves by its rule, the step that reaches END_TIME last
        return _musen_run_time(model, dim, dt, t_start)
    total = int(round(steps))
    t_end = t_start + total * dt
    return RunTime(dim, dt, total, t_start, t_end)


def _musen_run_time(model: GranularModel, dim: int, dt: float, t_start: float) -> RunTime:
    plan = model.plan
    every = float(plan.save_every_time) if plan.save_every_time else None
    if every is not None and not every > 0:
        raise InputError(model.source, None, f"save interval must be > 0, got {every!r}")
    if plan.save_every_steps:          # not a MUSEN setting (a model built in Python)
        every = None
    t_end = float(plan.t_end)
    if not t_end > t_start:            # nothing to simulate: the scene as it is
        return RunTime(dim, dt, 0, t_start, t_start)
    if every is not None and every < 0.1 * dt:
        # PreCalculationStep at t = 0 after the prediction step: |0 - 0| + 0.1 dt > saving step
        model.warnings.append(("musen-first-time-point", "the saving step is below 0.1 x the "
                               "simulation step: cmusen then saves t = 0 a second time after its "
                               "prediction step (with the half-step velocities), over the first"
                               + (" (when its step is still above 10 x the saving step)"
                                  if plan.variable_step is not None else "")
                               + "; fibrelmp's first time point is the initial state"))
    if plan.variable_step is not None:
        # MUSEN's variable step: the steps, saves and end come from fix musen/leapfrog during
        # the run; the steps at SIMULATION_STEP (the largest) are the progress bar's estimate
        total = max(1, math.ceil((t_end - t_start) / dt))
        return RunTime(dim, dt, total, t_start, t_end, VariableSaves(total))
    total, saves, exact = musen_run(t_start, dt, t_end, every, MAX_IRREGULAR_SAVES)
    if not exact:
        model.warnings.append(("musen-save-drift", "over this long run cmusen's summed clock "
                               "drifts, so it may save some time points (and end) a step earlier "
                               "or later than fibrelmp's regular schedule; the times written are "
                               "cmusen's summed times of fibrelmp's steps"))
    if plan.save_every_steps:
        steps = None                   # save_steps' regular schedule
    elif isinstance(saves, int):
        steps = SaveSteps(total, period=saves)
    else:
        steps = SaveSteps(total, explicit=saves)
    clock = MusenClock(t_start, dt)
    end = clock.time(total) if exact else t_start + total * dt     # (not summed: too long)
    return RunTime(dim, dt, total, t_start, end, steps, clock)


def variable_step_refusals(model: GranularModel, integrator: bool, deletions: bool = False) -> str | None:
    """Why fibrelmp cannot run ``model`` with MUSEN's variable time step (None: it can).  It
    needs fibrelmp's integrator (fix musen/leapfrog: ``integrator``), and no event at a step
    fixed in advance (activity ends, ``deletions``; inlets).  Breaks are timed by the bond
    style (bond_style musen/elastic logs MUSEN's time with each)."""
    plan = model.plan
    refused = []
    if not integrator:
        refused.append("it needs fibrelmp's LAMMPS styles (fix musen/leapfrog)")
    if deletions:
        refused.append("spheres whose activity ends during the run are not supported with it")
    if plan.inlets:
        refused.append("dynamic generators (inlets) are not supported with it")
    return "MUSEN's variable time step: " + "; ".join(refused) if refused else None


UNKNOWN_STEP = -1          # a frame whose step the run decides (variable time step)


class VariableSaves:
    """The frames of a variable time step: their steps are known once the run makes them (fix
    musen/leapfrog stops the run where MUSEN saves), so the schedule gives UNKNOWN_STEP per frame
    and has no length."""

    period = None
    explicit = None

    def __init__(self, estimate: int):
        self.total = estimate          # steps at the largest step: the progress estimate

    def __iter__(self):
        while True:
            yield UNKNOWN_STEP

    def __contains__(self, step: int) -> bool:
        return False


VARIABLE_LOOP, VARIABLE_DONE = "fl_vardt", "fl_vardt_done"
RUN_CHUNK = 2 ** 31 - 1     # LAMMPS's largest run N: fix musen/leapfrog stops it much earlier


def variable_schedule() -> list[tuple]:
    """Actions of a variable-step script: MUSEN's start (first frame, prediction), then runs
    that fix musen/leapfrog stops after each step where MUSEN saves, a frame after each, until
    the step reaching END_TIME, whose frame is the last (a loop of LAMMPS: `lmp -in` replays it)."""
    return [("run0",), ("frame", 0), ("predict",),
            ("loop", VARIABLE_LOOP, RUN_CHUNK), ("run", RUN_CHUNK, False), ("vardt_check", VARIABLE_DONE),
            ("frame", None), ("end", VARIABLE_LOOP), ("label", VARIABLE_DONE), ("frame", None)]


def schedule(total: int, saves: SaveSteps, deletions: list[tuple[int, np.ndarray]],
             predict: bool = False):
    """Actions of the script: runs (in pieces of 1/50 of the run: ``steps.run_piece``),
    activity-end deletions and frames.  A stretch of regular saves with no deletion in it is
    one LAMMPS loop ("loop" ... "end"), so the script does not grow with the number of frames."""
    piece = run_piece(total)                  # progress pieces (translate.steps)
    acts: list[tuple] = [("run0",), ("frame", 0)] + ([("predict",)] if predict else [])
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
        # the last step is never inside a loop: its frame is MUSEN's FinalizeSimulation save,
        # which a stop criterion does not check (with_stop_criterion)
        limit = min(stop - 1 if stop is not None else total - 1, last_regular)
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


def save_steps(model: GranularModel, run: RunTime) -> SaveSteps:
    """The run's saved steps: MUSEN's (its clock, ``run.saves``), else every k steps or every
    time interval."""
    plan = model.plan
    if run.saves is not None:
        return run.saves
    total, dt = run.total, run.dt
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


def compress_ids(ids: np.ndarray) -> str:
    """LAMMPS id list of a group: runs of consecutive ids as a:b."""
    ids = np.sort(np.asarray(ids, np.int64))
    if not len(ids):
        return ""
    breaks = np.flatnonzero(np.diff(ids) != 1)
    starts = np.r_[ids[0], ids[breaks + 1]]
    ends = np.r_[ids[breaks], ids[-1]]
    return " ".join(str(a) if a == b else f"{a}:{b}" for a, b in zip(starts, ends))


def with_presaves(acts: list[tuple]) -> list[tuple]:
    """A ``("presave",)`` before every frame, one step before it: MUSEN's stress tensor of a
    saved time point sums the contact and bond forces of the previous evaluation (cmusen saves
    before the step's force evaluation), which LAMMPS has at the step before the frame.  The
    run reaching a frame is split into its steps but the last, the presave, and that last step;
    the first frame (step 0: no evaluation before it) gets a presave too, so every frame has
    one, in order."""
    out: list[tuple] = []
    first = True
    for act in acts:
        if act[0] == "frame":
            if first:
                out.append(("presave",))
                first = False
            else:
                j = len(out) - 1
                while out[j][0] == "delete":          # deletions come after the step
                    j -= 1
                if out[j][0] != "run":
                    raise RuntimeError(f"a frame after {out[j]!r}, not after a run")
                _, n, pre = out[j]
                if n > 1:
                    out[j:j + 1] = [("run", n - 1, pre), ("presave",), ("run", 1, False)]
                else:
                    # a one-step run after deletions: the presave goes before them (delete_atoms
                    # drops the ghost atoms until the next set-up, and the pairs with them)
                    k = j
                    while k > 0 and out[k - 1][0] == "delete":
                        k -= 1
                    out.insert(k, ("presave",))
        out.append(act)
    return out


STOP_LABEL, END_LABEL = "fl_stopped", "fl_finish"


def with_stop_criterion(acts: list[tuple], max_broken: int, bonds0: int,
                        last_unchecked: bool = False) -> list[tuple]:
    """MUSEN's stop criterion BROKEN_BONDS (BaseSimulator::PreCalculationStep): at every save
    after the first, more than ``max_broken`` bonds broken since the start (``bonds0`` at the
    start) stop the run; cmusen then still makes that step and saves once more
    (FinalizeSimulation), so the stop block is one step and its frame.  ``last_unchecked``: the
    last frame is FinalizeSimulation's save (the step reaching END_TIME), which checks nothing."""
    out: list[tuple] = [("stopvar", bonds0)]
    last = max((k for k, act in enumerate(acts) if act[0] == "frame"), default=-1)
    for k, act in enumerate(acts):
        out.append(act)
        if act[0] == "frame" and act[1] != 0 and not (last_unchecked and k == last):
            out.append(("stopcheck", max_broken))
    said = (f"{STOP_PRINT}: more than {max_broken} bonds broken (MUSEN BROKEN_BONDS): one more "
            "step, its frame, the end")
    return out + [("jump", END_LABEL), ("label", STOP_LABEL), ("stopped", said),
                  ("run", 1, False), ("frame", None), ("label", END_LABEL)]
