"""Several solid-bond models acting together, as cmusen runs them (CCPUSimulator::
CalculateForcesSB: each active SB model in turn over the still-active bonds, continuing the
bond's state the previous one left and adding its own force; each applies its own breakage
test).  Reference: the real cmusen 1.74.2 on three glass spheres joined by two bonds, pulled
apart with spins and sideways velocities, under ModelSBKelvin (MAX_DAMP_RATIO 0.3, breakage 1)
then ModelSBElastic (CONSIDER_BREAKAGE 2); one bond breaks at step 18
(tests/data/real-outputs/musen/several_bond_models/README.md)."""

from __future__ import annotations

import gzip
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

from fibrelmp.translate.musen.scene import read, read_time_points

from .conftest import data_path
from .musen_model_checks import sphere_differences

CASE = data_path("real-outputs", "musen", "several_bond_models")
JOB = "job_kelvin_elastic.txt"
SCENE = "kelvin_elastic_scene.txt"
RESULT = "ke_result_prec17.txt"
TAGS = (12, 15, 16)    # position, velocity, angular velocity


def _run_fibrelmp(folder, job_text: str | None = None) -> None:
    shutil.copy(CASE / SCENE, folder)
    (folder / JOB).write_text((CASE / JOB).read_text() if job_text is None else job_text)
    done = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", JOB],
                          cwd=folder, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="module")
def real_result(tmp_path_factory):
    path = tmp_path_factory.mktemp("real") / RESULT
    with gzip.open(CASE / f"cmusen_{RESULT}.gz", "rb") as src, open(path, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return path


def test_cmusen_lists_both_bond_models_in_script_order():
    log = (CASE / "cmusen_ke.log").read_text()
    kelvin = log.index("Kelvin bond\n\tCONSIDER_BREAKAGE 1 MAX_DAMP_RATIO 0.3")
    elastic = log.index("Elastic bond\n\tCONSIDER_BREAKAGE 2")
    assert kelvin < elastic


def test_kelvin_then_elastic_matches_cmusen_at_every_saved_time(tmp_path, real_result):
    _run_fibrelmp(tmp_path)
    script = next(tmp_path.glob("*_work/job2/in.lammps")).read_text()
    assert "musen/elastic breakage 1 kelvin 0.3 then elastic 2 " in script
    diffs = sphere_differences(real_result, tmp_path / RESULT, TAGS)
    assert all(d < 1e-6 for d in diffs.values()), diffs
    # the same bond breaks at the same step (its activity end is cmusen's time of that step)
    real_end = read(real_result).bonds.active_end
    ours_end = read(tmp_path / RESULT).bonds.active_end
    assert real_end[0] == pytest.approx(1.8e-7, abs=1e-20) and np.isinf(real_end[1])
    np.testing.assert_array_equal(ours_end, real_end)


def test_one_bond_model_alone_is_far_from_cmusen(tmp_path, real_result):
    """The comparison above can fail: the Kelvin bond alone (what fibrelmp ran before several
    models acted together) is off by the order of the motion itself."""
    text = (CASE / JOB).read_text()
    text = text.replace("MODEL_SB             ModelSBElastic\n", "")
    text = text.replace("MODEL_PARAMS         ModelSBElastic CONSIDER_BREAKAGE 2\n", "")
    _run_fibrelmp(tmp_path, text)
    diffs = sphere_differences(real_result, tmp_path / RESULT, TAGS)
    assert min(diffs.values()) > 0.1, diffs


@pytest.mark.skipif(not os.environ.get("FIBRELMP_CMUSEN"), reason="set FIBRELMP_CMUSEN to the "
                    "cmusen program to rerun the reference")
def test_cmusen_gives_the_stored_reference_again(tmp_path, real_result):
    shutil.copy(CASE / SCENE, tmp_path)
    shutil.copy(CASE / JOB, tmp_path)
    subprocess.run([os.environ["FIBRELMP_CMUSEN"], "-t=1", f"-s={JOB}"], cwd=tmp_path,
                   capture_output=True, text=True, timeout=120, check=True)
    assert (tmp_path / RESULT).read_bytes() == real_result.read_bytes()


EX3 = data_path("real-outputs", "musen", "example3_models")


def test_example_3_first_step_equals_cmusens(tmp_path):
    """MUSEN's Example 3 (the file's Kelvin bond, then the script's Elastic bond, on
    CompressionTest.mdem's 18,802 bonds) after one step: every sampled sphere's velocity is
    cmusen's to 1e-6 of the speed scale (Kelvin alone: all 5,696 spheres differ, by up to 0.76
    of it).  The sample leaves out nothing chosen: ids that are multiples of 8 (sphere 1913,
    touching the moving plate at t = 0, differs in every bond-model setting: docs/musen.md)."""
    (tmp_path / "InitScenes").mkdir()
    (tmp_path / "Scripts").mkdir()
    (tmp_path / "InitScenes" / "CompressionTest.mdem").symlink_to(
        data_path("real-inputs", "musen", "CompressionTest.mdem"))
    job = (EX3 / "example3_steps_job.txt").read_text().replace("END_TIME             2e-7",
                                                               "END_TIME             2e-8")
    (tmp_path / "Scripts" / "ex3.txt").write_text(job)
    done = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", "ex3.txt"],
                          cwd=tmp_path / "Scripts", capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    ours = read_time_points(tmp_path / "Scripts" / "s_prec17.txt", tags=(15,))
    k = int(np.flatnonzero(np.isclose(ours.times, 2e-8, rtol=0, atol=1e-15))[0])
    velocity = dict(zip(ours.ids.tolist(), ours.fields[15][k]))
    with gzip.open(EX3 / "cmusen_example3_step1_velocities.txt.gz", "rt") as f:
        rows = np.loadtxt(f, comments="#")
    real = rows[:, 1:]
    got = np.array([velocity[int(i)] for i in rows[:, 0]])
    assert len(rows) == 712
    assert np.abs(got - real).max() < 1e-6 * np.abs(real).max()
    # the result file's model manager keeps both bond models, in cmusen's order
    from fibrelmp.registry import INPUT, detect
    from fibrelmp.translate.musen.scene_record import scene_record

    result = tmp_path / "Scripts" / "Result_CompressionTest.mdem"
    stored = scene_record(detect(result).load(INPUT)().model(result)).file_models
    assert [m.name for m in stored if m.name.startswith("ModelSB")] == ["ModelSBKelvin",
                                                                        "ModelSBElastic"]
