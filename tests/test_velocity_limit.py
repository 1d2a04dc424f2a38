"""MUSEN's particle velocity limit (fix musen/leapfrog vlimit) against the real cmusen
(tests/data/real-outputs/musen/velocity_limit/README.md): a force-controlled plate pushes a
free sphere that may not move faster than 0.01 m/s, from the script's
LIMIT_PARTICLE_VELOCITY and from a `.mdem`'s stored limit."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.mdem.model import read_scene
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import check_reference_is_cmusens_output, needs_cmusen, styles_or_skip

DATA = data_path("real-outputs/musen/velocity_limit")
COORD, VEL, WALL = 12, 15, 44
CONTACT = (3.95e-4, 4.95e-4)      # the plate touches the sphere (cmusen saves half-step velocities)


def _compare(result: Path) -> None:
    ours = read_time_points(result)
    theirs = read_time_points(DATA / "cmusen_vlim_result_prec17.txt")
    n = len(ours.times)
    assert len(theirs.times) in (n, n + 1)        # cmusen's extra point after END_TIME
    np.testing.assert_allclose(ours.times, theirs.times[:n], rtol=0, atol=1e-15)
    spheres, walls = slice(0, 3), slice(3, 5)
    for tag, objects in ((COORD, spheres), (WALL, walls)):
        a, b = ours.fields[tag][:, objects], theirs.fields[tag][:n, objects]
        scale = np.max(np.abs(b - b[:1]))
        assert np.max(np.abs(a - b)) <= 1e-6 * scale, tag
    outside = (ours.times < CONTACT[0]) | (ours.times > CONTACT[1])
    v_ours, v_theirs = ours.fields[VEL][outside, spheres], theirs.fields[VEL][:n][outside, spheres]
    np.testing.assert_allclose(v_ours, v_theirs, rtol=0, atol=1e-6 * 0.01)
    # the pushed sphere: capped at the limit while the plate pushed it, slower after
    vz = theirs.fields[VEL][:n, 0, 2]
    assert np.isclose(vz, -0.01, rtol=0, atol=1e-15).sum() >= 5 and vz[-1] > -0.01


def _job(tmp_path: Path, name: str = "job_vlim.txt", text: str | None = None) -> Path:
    shutil.copy(DATA / "vlim_scene.txt", tmp_path)
    (tmp_path / name).write_text(text if text is not None else (DATA / name).read_text())
    return tmp_path / name


def test_script_velocity_limit_is_cmusens(tmp_path):
    styles_or_skip()
    python_api.run(_job(tmp_path), work=tmp_path / "work")
    _compare(tmp_path / "vlim_result_prec17.txt")
    assert "musen/leapfrog vlimit 0.01" in (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert read_scene(tmp_path / "vlim_result.mdem").plan.velocity_limit == 0.01   # written back


def test_mdem_velocity_limit_is_cmusens(tmp_path):
    """cmusen's own result `.mdem` stores the limit; simulated again without the keyword it
    gives the same result (cmusen: identical export, README.md)."""
    styles_or_skip()
    shutil.copy(DATA / "cmusen_vlim_result.mdem", tmp_path)
    job = _job(tmp_path, "job_vlim_mdem.txt")
    assert read_scene(tmp_path / "cmusen_vlim_result.mdem").plan.velocity_limit == 0.01
    python_api.run(job, work=tmp_path / "work")
    _compare(tmp_path / "mdem_result_prec17.txt")


def test_zero_removes_the_limit(tmp_path):
    """LIMIT_PARTICLE_VELOCITY 0 (cmusen: <= 0 is no limit): the sphere is pushed faster."""
    styles_or_skip()
    text = (DATA / "job_vlim.txt").read_text().replace("LIMIT_PARTICLE_VELOCITY 0.01",
                                                       "LIMIT_PARTICLE_VELOCITY 0")
    python_api.run(_job(tmp_path, text=text), work=tmp_path / "work")
    assert "vlimit" not in (tmp_path / "work" / "job2" / "in.lammps").read_text()
    vz = read_time_points(tmp_path / "vlim_result_prec17.txt").fields[VEL][:, 0, 2]
    assert vz.min() < -0.03


def test_refused_without_fibrelmps_styles(tmp_path):
    job = _job(tmp_path)
    with lammps_styles.stock(True), pytest.raises(InputError, match="LIMIT_PARTICLE_VELOCITY needs "
                                                  "fibrelmp's LAMMPS styles") as err:
        python_api.run(job)
    line = job.read_text().splitlines().index("LIMIT_PARTICLE_VELOCITY 0.01") + 1
    assert str(err.value).startswith(f"{job}:{line}: ")


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "vlim")


FLEX_JOB = """JOB
SOURCE_FILE ./cmusen_flex_result.mdem
RESULT_FILE ./again.mdem
COMPONENT SIMULATOR
MODEL_PP ModelPPHertzMindlin
MODEL_PW ModelPWHertzMindlin
END_TIME 2e-5
"""


def test_mdem_variable_step_and_criterion_are_read(tmp_path):
    """cmusen's .mdem stores VARIABLE_TIME_STEP 1 (with MUSEN's default MAX_PART_MOVE 1e-8 m
    and STEP_INC_FACTOR 1.01, which job_flex.txt left alone) and STOP_CRITERION BROKEN_BONDS 5:
    both are read and the job runs (no bonds: the criterion cannot act; the variable step
    itself is compared with cmusen in tests/test_musen_variable_time_step.py); a job script's
    VARIABLE_TIME_STEP 0 switches the step off."""
    from fibrelmp.translate.musen import script as ms

    styles_or_skip()
    shutil.copy(DATA / "cmusen_flex_result.mdem", tmp_path)
    mdem = tmp_path / "cmusen_flex_result.mdem"
    plan = read_scene(mdem).plan
    assert plan.variable_step == (1e-8, 1.01) and plan.stop_broken_bonds == 5
    job = tmp_path / "job.txt"
    job.write_text(FLEX_JOB)
    python_api.run(job, work=tmp_path / "work")
    assert read_scene(tmp_path / "again.mdem").plan.variable_step == (1e-8, 1.01)
    job.write_text(FLEX_JOB + "VARIABLE_TIME_STEP 0\n")
    (simulator,) = ms.read_script(job)
    model = read_scene(mdem)
    ms.apply_simulator_settings(model, simulator)
    assert model.plan.variable_step is None


def test_mdem_moving_periodic_box_is_read():
    """A moving periodic box (SPBC::vVel, the .mdem's periodic_conditions_vel) is the plan's
    periodic_velocity (tests/test_moving_pbc.py runs it), not a refused setting."""
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.model import _refused_settings
    from fibrelmp.translate.musen.scene_record import scene_record

    model = read_scene(DATA / "cmusen_vlim_result.mdem")
    assert model.plan.periodic_velocity is None
    with MdemFile(DATA / "cmusen_vlim_result.mdem") as mdem:
        storage = mdem.storage
        storage.info.periodic_conditions_enabled = True
        storage.info.periodic_conditions_vel.x = 1e-3
        _refused_settings(model, storage)
    assert scene_record(model).refused == {}
    assert list(model.plan.periodic_velocity) == [1e-3, 0, 0]
