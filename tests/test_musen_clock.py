"""MUSEN's clock (translate/granular/musen_clock.py) against a literal transcription of cmusen's
loop (``CBaseSimulator::StartSimulation``/``PreCalculationStep``, e0ff360): ``t += dt`` step by
step, a save when ``|t - t_last| + 0.1 dt > SAVING_STEP``, the run ends with the step that
brings ``t`` to ``END_TIME``, whose time point is saved too."""

from __future__ import annotations

import pytest

from fibrelmp.translate.granular.musen_clock import MusenClock, musen_run


def cmusen_loop(dt: float, t_end: float, saving_step: float) -> tuple[int, list[int], list[float]]:
    t, last, step = 0.0, 0.0, 0
    steps, times = [0], [0.0]
    while t < t_end:
        t += dt
        step += 1
        if t >= t_end:
            break
        if abs(t - last) + 0.1 * dt > saving_step:
            steps.append(step)
            times.append(t)
            last = t
    steps.append(step)
    times.append(t)
    return step, steps, times


def expand(total: int, saves) -> list[int]:
    if isinstance(saves, int):
        return sorted(set(range(0, total, saves)) | {total})
    return list(saves)


@pytest.mark.parametrize("dt,t_end,saving_step", [
    (1e-6, 2e-4, 1e-5),          # the agglomerate's settings: last point at END_TIME + dt
    (3e-7, 1e-3, 1e-6),          # not a multiple: every 4 steps, not 1e-6 s
    (1e-7, 2e-4, 3.3e-7),
    (2e-8, 1e-4, 3.3e-7),
    (1e-6, 1e-2, 1e-6),
])
def test_saved_steps_and_times_are_cmusens(dt, t_end, saving_step):
    total, saves, exact = musen_run(0.0, dt, t_end, saving_step, 100_000)
    ref_total, ref_steps, ref_times = cmusen_loop(dt, t_end, saving_step)
    assert exact and total == ref_total
    assert expand(total, saves) == ref_steps
    clock = MusenClock(0.0, dt)
    assert [clock.time(s) for s in ref_steps] == ref_times       # bit for bit


def test_long_runs_with_many_saves_stay_exact_and_regular():
    """3.3 million steps saved every 4 (cmusen's rule for 1e-6 s with 3e-7 s steps): once the
    saves are regular they are held as a period, not a list of 833,334 steps."""
    total, saves, exact = musen_run(0.0, 3e-7, 1.0, 1e-6, 100_000)
    assert (total, saves, exact) == (3_333_334, 4, True)
    # the same with the whole list kept (no compression) agrees
    assert expand(*musen_run(0.0, 3e-7, 0.1, 1e-6, 10 ** 9)[:2]) == cmusen_loop(3e-7, 0.1, 1e-6)[1]
