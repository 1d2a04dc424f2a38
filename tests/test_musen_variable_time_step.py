"""MUSEN's variable time step (VARIABLE_TIME_STEP 1) as the real cmusen runs it
(tests/data/real-outputs/musen/variable_time_step/README.md): three spheres hit a rising floor.

fibrelmp still refuses the setting; these tests pin down MUSEN's rule from cmusen's own
per-step export with numpy alone (no fibrelmp code under test), so that docs/musen.md's
statement of it is measured, and whoever implements it has the reference to meet."""

from __future__ import annotations

import gzip
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import TimePoints, read_time_points

from .conftest import data_path
from .musen_model_checks import CMUSEN, needs_cmusen

DATA = data_path("real-outputs/musen/variable_time_step")
COORD, VEL, WALL = 12, 15, 44
SPHERES, FLOOR = slice(0, 3), slice(3, 5)
MAX_PART_MOVE, STEP_INC_FACTOR, SIMULATION_STEP = 1e-10, 1.05, 1e-6
SAVING_STEP, END_TIME, FLOOR_SPEED = 1e-5, 3e-4, 0.02


@pytest.fixture(scope="module")
def every_step(tmp_path_factory) -> TimePoints:
    text = tmp_path_factory.mktemp("vardt") / "steps_prec17.txt"
    with gzip.open(DATA / "cmusen_vardt_steps_result_prec17.txt.gz", "rb") as packed:
        text.write_bytes(packed.read())
    return read_time_points(text)


def _steps(run: TimePoints) -> np.ndarray:
    """The step that led to each saved point after the first (the summed times' differences)."""
    return np.diff(run.times)


def test_new_step_is_musens_rule(every_step):
    """CPUSimulator::MoveParticles: dt_max = sqrt(MAX_PART_MOVE * min m/|F|); a larger step
    becomes dt_max, a smaller one grows by STEP_INC_FACTOR up to SIMULATION_STEP."""
    dt = _steps(every_step)
    dv = np.linalg.norm(np.diff(every_step.fields[VEL][:, SPHERES], axis=0), axis=2).max(axis=1)
    dt_max = np.sqrt(MAX_PART_MOVE * dt / dv)          # m/|F| = dt_new/|dv|: the kick uses dt_new
    predicted = np.where(dt[:-1] > dt_max[1:] * (1 + 1e-9), dt_max[1:],
                         np.minimum(dt[:-1] * STEP_INC_FACTOR, SIMULATION_STEP))
    np.testing.assert_allclose(predicted, dt[1:], rtol=1e-10, atol=0)
    shrinks = dt[1:] < dt[:-1] * (1 - 1e-9)
    grows = dt[1:] > dt[:-1] * (1 + 1e-9)
    assert shrinks.sum() > 100 and grows.sum() > 100 and dt.min() < 0.05 * SIMULATION_STEP
    assert dt.max() == pytest.approx(SIMULATION_STEP, rel=1e-12)


def test_spheres_move_with_the_new_step_walls_with_the_old(every_step):
    """The new step moves the spheres; MoveWalls gets the value from before the change."""
    dt = _steps(every_step)
    x, v = every_step.fields[COORD][:, SPHERES], every_step.fields[VEL][:, SPHERES]
    moved = np.diff(x, axis=0)
    assert np.max(np.abs(moved - v[1:] * dt[:, None, None])) <= 1e-12 * np.max(np.abs(moved))
    floor_z = every_step.fields[WALL][:, FLOOR][:, :, 2::3]          # every vertex's z
    rise = np.diff(floor_z, axis=0)[1:]
    old, new = FLOOR_SPEED * dt[:-1], FLOOR_SPEED * dt[1:]
    assert np.max(np.abs(rise - old[:, None, None])) <= 1e-12 * FLOOR_SPEED * SIMULATION_STEP
    assert np.max(np.abs(rise - new[:, None, None])) > 1e-3 * FLOOR_SPEED * SIMULATION_STEP


def test_saves_follow_the_summed_time(every_step):
    """BaseSimulator::PreCalculationStep saves when |t - t_last| + 0.1 dt > SAVING_STEP (dt: the
    step that reached t); the run ends after the first step reaching END_TIME and saves it."""
    saved = read_time_points(DATA / "cmusen_vardt_result_prec17.txt")
    t, dt = every_step.times, _steps(every_step)
    picks, last = [], 0.0
    for k in range(1, len(t)):
        if abs(t[k] - last) + 0.1 * dt[k - 1] > SAVING_STEP:
            picks.append(k)
            last = t[k]
    assert t[-2] < END_TIME <= t[-1] and picks[-1] != len(t) - 1
    picks.append(len(t) - 1)                                         # FinalizeSimulation's save
    assert np.array_equal(t[picks], saved.times[1:])                 # bit for bit
    assert np.ptp(np.diff(saved.times[12:])) > 1e-7                  # not on a fixed grid
    for tag in (COORD, VEL, WALL):                                   # saving changes nothing
        assert np.array_equal(every_step.fields[tag][picks], saved.fields[tag][1:], equal_nan=True)


def test_fibrelmp_refuses_it_at_the_line(tmp_path):
    shutil.copy(DATA / "vardt_scene.txt", tmp_path)
    job = tmp_path / "job_vardt.txt"
    job.write_text((DATA / "job_vardt.txt").read_text())
    with pytest.raises(InputError, match="variable time step is not supported") as err:
        python_api.run(job, work=tmp_path / "work")
    assert str(err.value).startswith(f"{job}:16: ")
    assert not (tmp_path / "vardt_init.mdem").exists()


@needs_cmusen
@pytest.mark.parametrize("job, export, stored", [
    ("job_vardt.txt", "vardt_result_prec17.txt", "cmusen_vardt_result_prec17.txt"),
    ("job_vardt_steps.txt", "vardt_steps_result_prec17.txt", "cmusen_vardt_steps_result_prec17.txt.gz"),
])
def test_references_are_cmusens_output(tmp_path: Path, job: str, export: str, stored: str):
    for name in ("vardt_scene.txt", job):
        shutil.copy(DATA / name, tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", f"-s={job}"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    reference = (DATA / stored).read_bytes()
    if stored.endswith(".gz"):
        reference = gzip.decompress(reference)
    assert (tmp_path / export).read_bytes() == reference
