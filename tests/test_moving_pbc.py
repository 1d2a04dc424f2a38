"""MUSEN's moving periodic box (a `.mdem`'s periodic_conditions_vel; fix musen/pbc/move)
against the real cmusen (tests/data/real-outputs/musen/moving_pbc/README.md): two spheres
meeting across a periodic boundary whose faces move outwards."""

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
from .musen_model_checks import CMUSEN, check_resume_is_bitwise, needs_cmusen, styles_or_skip

DATA = data_path("real-outputs/musen/moving_pbc")
COORD, VEL, ANGVEL = 12, 15, 16
IN_CONTACT = (2.45e-4, 2.55e-4)     # the one saved time during the contact


def _job(tmp_path: Path) -> Path:
    for name in ("pbc_init.mdem", "job_pbc.txt"):
        shutil.copy(DATA / name, tmp_path)
    return tmp_path / "job_pbc.txt"


def test_moving_periodic_box_is_cmusens(tmp_path):
    styles_or_skip()
    assert list(read_scene(DATA / "pbc_init.mdem").plan.periodic_velocity) == [0.05, 0.0, 0.0]
    python_api.run(_job(tmp_path), work=tmp_path / "work")
    assert "musen/pbc/move 0.05 0.0 0.0" in (tmp_path / "work" / "job1" / "in.lammps").read_text()
    ours = read_time_points(tmp_path / "pbc_result_prec17.txt")
    theirs = read_time_points(DATA / "cmusen_pbc_result_prec17.txt")
    n = len(ours.times)
    assert len(theirs.times) in (n, n + 1)          # cmusen's extra point after END_TIME
    np.testing.assert_allclose(ours.times, theirs.times[:n], rtol=0, atol=1e-15)
    # the spheres met across the boundary and bounced (vx changed sign)
    assert theirs.fields[VEL][0, 0, 0] == 0.2 and theirs.fields[VEL][n - 1, 0, 0] < 0
    a, b = ours.fields[COORD], theirs.fields[COORD][:n]
    assert np.max(np.abs(a - b)) <= 1e-6 * np.max(np.abs(b - b[:1]))
    outside = (ours.times < IN_CONTACT[0]) | (ours.times > IN_CONTACT[1])
    for tag in (VEL, ANGVEL):
        a, b = ours.fields[tag][outside], theirs.fields[tag][:n][outside]
        scale = np.max(np.abs(theirs.fields[tag]))
        assert np.max(np.abs(a - b)) <= 1e-6 * scale, tag


def test_contact_time_follows_the_moving_box(tmp_path):
    """Analytic: the x offset across the boundary closes at 0.4 - 2 x 0.05 m/s, so the contact
    starts at 0.242 ms (with a still box, at 0.4 m/s: 0.182 ms)."""
    styles_or_skip()
    python_api.run(_job(tmp_path), work=tmp_path / "work")
    ours = read_time_points(tmp_path / "pbc_result_prec17.txt")
    dx, dy = 5e-3 - (2.0e-3 + 0.95e-3), 0.3e-3           # centre offset across the boundary
    start = (dx - np.sqrt(2e-3 ** 2 - dy ** 2)) / 0.3      # x closes at 0.3 m/s until touching
    moved = np.flatnonzero(ours.fields[VEL][:, 0, 0] != 0.2)[0]
    assert ours.times[moved - 1] <= start < ours.times[moved]


def test_refused_without_fibrelmps_styles(tmp_path):
    job = _job(tmp_path)
    with lammps_styles.stock(True), pytest.raises(InputError, match="moving periodic box needs "
                                                  "fibrelmp's LAMMPS styles"):
        python_api.run(job)
    assert not (tmp_path / "pbc_result.mdem").exists()


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    import subprocess
    job = _job(tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", f"-s={job.name}"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    assert (tmp_path / "pbc_result_prec17.txt").read_bytes() == \
        (DATA / "cmusen_pbc_result_prec17.txt").read_bytes()


def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch):
    """The box of the checkpoint's time and the box at t = 0 go through the restart file."""
    check_resume_is_bitwise(tmp_path, monkeypatch, _job, "pbc_result_prec17.txt", 1700)
