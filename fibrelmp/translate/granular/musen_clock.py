"""MUSEN's clock (``CBaseSimulator::StartSimulation`` / ``PreCalculationStep``, MUSEN 1.74.2
e0ff360): the time is a running sum ``t += dt`` from the start, a time point is saved at the
first step whose time is more than ``saving step - 0.1 dt`` after the last save
(``|t - t_last| + 0.1 dt > saving step``), and the run stops after the step that brings ``t`` to
``END_TIME`` or beyond, saving that time point too.  So the saved times are cmusen's summed
ones (not multiples of the saving step), a saving step that is not a multiple of the step
saves where cmusen does, and the last time point is often ``END_TIME + dt`` (when the sum
falls short of ``END_TIME`` by rounding).

The sums are done in chunks with ``numpy.cumsum`` (a sequential sum: the same additions, in the
same order, as MUSEN's loop), so memory does not grow with the number of steps."""

from __future__ import annotations

import numpy as np

CHUNK = 1 << 20
EXACT_STEPS = 1e8        # longer runs get the nominal schedule (musen-save-drift warning)


def _times(t0: float, dt: float, count: int) -> np.ndarray:
    """t0 + dt, (t0 + dt) + dt, ... (``count`` values, each the previous plus dt)."""
    steps = np.full(count + 1, dt)
    steps[0] = t0
    return np.cumsum(steps)[1:]


class MusenClock:
    """MUSEN's time at a step (cheap when the steps asked for increase: it sums on from the
    last one)."""

    def __init__(self, t_start: float, dt: float):
        self.t_start, self.dt = float(t_start), dt
        self.step, self.t = 0, self.t_start

    def time(self, step: int) -> float:
        if step < self.step:
            self.step, self.t = 0, self.t_start
        while step > self.step:
            n = min(CHUNK, step - self.step)
            self.t = float(_times(self.t, self.dt, n)[-1])
            self.step += n
        return self.t


class SaveList:
    """The saved steps, held as a list while short or irregular and as (period, count) once
    longer than ``limit`` and regular, so memory does not grow with the number of saves."""

    def __init__(self, limit: int):
        self.limit, self.steps, self.period, self.count, self.last = limit, [0], None, 1, 0

    def add(self, step: int) -> None:
        if self.period is not None:
            if step - self.last != self.period:
                raise ValueError("irregular")
        else:
            self.steps.append(step)
            if len(self.steps) > self.limit:
                k = regular(self.steps)
                if k is None:
                    raise ValueError("irregular")
                self.period, self.steps = k, None
        self.count += 1
        self.last = step


def musen_run(t_start: float, dt: float, t_end: float, saving_step: float | None,
              max_saves: int) -> tuple[int, list[int] | int, bool]:
    """(steps of the run, the saved steps: a list, or the period k when they are every k
    steps up to the last, exact) as cmusen runs them.  The saved steps include 0 and the
    last step.  When there would be more than ``max_saves`` irregular saves (the summed clock
    drifts by 0.1 dt over a long run), the saves are every round(saving step / dt) steps and
    ``exact`` is False."""
    if (t_end - t_start) / dt > EXACT_STEPS:
        # summing 1e8+ steps at translation costs seconds per 1e9: the nominal schedule
        total = max(1, round((t_end - t_start) / dt))
        return total, max(1, round(saving_step / dt)) if saving_step else [0, total], False
    try:
        total, saves = _musen_run(t_start, dt, t_end, saving_step, max_saves)
        return total, saves, True
    except ValueError:
        total, _ = _musen_run(t_start, dt, t_end, None, max_saves)
        return total, max(1, round(saving_step / dt)), False


def _musen_run(t_start: float, dt: float, t_end: float, saving_step: float | None,
               max_saves: int) -> tuple[int, list[int] | int]:
    saves = SaveList(max_saves)
    last, t, n = float(t_start), float(t_start), 0
    while True:
        times = _times(t, dt, CHUNK)
        reached = np.flatnonzero(times >= t_end)
        stop = int(reached[0]) if len(reached) else CHUNK       # index of the final step
        j = 0
        if saving_step is not None and saves.period is not None:
            j, last = _regular_saves(saves, times, j, stop, last, n, dt, saving_step)
        while saving_step is not None and j < stop:               # saves before the final step
            # the first k with |t_k - last| + 0.1 dt > saving step (times increase)
            k = j + int(np.searchsorted(times[j:stop], last + saving_step - 0.1 * dt, "left"))
            k = max(j, k - 2)
            while k < stop and not abs(times[k] - last) + 0.1 * dt > saving_step:
                k += 1
            if k >= stop:
                break
            saves.add(n + k + 1)
            last = float(times[k])
            j = k + 1
        if len(reached):
            total = n + stop + 1
            break
        n += CHUNK
        t = float(times[-1])
    if saves.period is not None:
        return total, saves.period
    steps = saves.steps
    if steps[-1] != total:
        steps.append(total)
    k = regular(steps)
    return total, (k if k is not None and len(steps) > 2 else steps)


def _regular_saves(saves: SaveList, times: np.ndarray, j: int, stop: int, last: float, n: int,
                   dt: float, saving_step: float) -> tuple[int, float]:
    """Once the saves are every k steps: take, at once, every further save of this chunk that
    MUSEN's rule puts exactly k steps after the one before (the step before it not yet due);
    the per-save search goes on from the first that is not."""
    k = saves.period
    idx = np.arange(j + k - 1, stop, k)
    if not len(idx):
        return j, last
    prev = np.concatenate(([last], times[idx[:-1]]))
    due = np.abs(times[idx] - prev) + 0.1 * dt > saving_step
    if k > 1:
        due &= ~(np.abs(times[idx - 1] - prev) + 0.1 * dt > saving_step)
    good = len(idx) if due.all() else int(np.argmin(due))
    if good == 0:
        return j, last
    saves.count += good
    saves.last = n + int(idx[good - 1]) + 1
    return int(idx[good - 1]) + 1, float(times[idx[good - 1]])


def regular(saves: list[int]) -> int | None:
    """k when the saves (without the last) are 0, k, 2k, ... and the last is at most k
    after them, else None."""
    inner = np.diff(np.asarray(saves[:-1], np.int64))
    if len(inner) == 0:
        return None
    k = int(inner[0])
    return k if k > 0 and (inner == k).all() and 0 < saves[-1] - saves[-2] <= k else None
