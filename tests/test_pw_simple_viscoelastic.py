"""ModelPWSimpleViscoElastic (translate/granular/models/pw_simple_viscoelastic.py, law
simple/viscoelastic of fix musen/wall/mesh) against the real cmusen: a spinning glass sphere
bouncing obliquely on a steel plate
(tests/data/real-outputs/musen/models/pw_simple_viscoelastic/README.md).  The opt-in test
(FIBRELMP_CMUSEN) reruns cmusen and checks the stored reference is still its output."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path

DATA = data_path("real-outputs/musen/models/pw_simple_viscoelastic")
CMUSEN = os.environ.get("FIBRELMP_CMUSEN")
VEL, ANGVEL, COORD = 15, 16, 12                # MUSEN text tags
PARAMS = "NORMAL_FORCE_COEFF 3000 NORMAL_DAMPING_PARAMETER 0.002"
# cmusen saves the half-step velocity during a contact (README.md): compare outside it
IN_CONTACT = (0.9e-4, 3.1e-4)


def _styles_or_skip():
    if not lammps_styles.plugin().available:
        pytest.skip("fibrelmp's LAMMPS styles are not available")


def _job(tmp_path: Path, params: str = PARAMS) -> Path:
    shutil.copy(DATA / "sve_scene.txt", tmp_path)
    (tmp_path / "job_sve.txt").write_text((DATA / "job_sve.txt").read_text().replace(PARAMS, params))
    return tmp_path / "job_sve.txt"


def test_oblique_bounce_is_cmusens(tmp_path):
    _styles_or_skip()
    python_api.run(_job(tmp_path), work=tmp_path / "work")
    ours = read_time_points(tmp_path / "sve_result_prec17.txt")
    theirs = read_time_points(DATA / "cmusen_sve_result_prec17.txt")
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours.ids, theirs.ids)
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert "law simple/viscoelastic 3000.0 0.002" in script
    sphere = list(theirs.ids).index(0)
    ours_s, theirs_s = ({t: tp.fields[t][:, sphere] for t in (VEL, ANGVEL, COORD)} for tp in (ours, theirs))
    # it bounced (vz -0.4 -> +0.393), and kept vx and its spin: the law has no friction
    assert theirs_s[VEL][0, 2] == -0.4 and 0.39 < theirs_s[VEL][-1, 2] < 0.4
    np.testing.assert_allclose(ours_s[COORD], theirs_s[COORD], rtol=0, atol=1e-15)
    outside = (theirs.times < IN_CONTACT[0]) | (theirs.times > IN_CONTACT[1])
    np.testing.assert_allclose(ours_s[VEL][outside], theirs_s[VEL][outside], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(ours_s[ANGVEL], theirs_s[ANGVEL])


def test_check_gives_the_spring_contact_time(tmp_path):
    """The time-step figure is the wall spring's half period pi sqrt(m/Kn), not Hertz's."""
    m = 2500.0 * 4.0 / 3.0 * np.pi * 1e-3 ** 3
    lines = python_api.check(_job(tmp_path)).lines
    line = next(t for t in lines if t.startswith("contact time"))
    assert line.startswith(f"contact time {np.pi * np.sqrt(m / 3000.0):.3g} (simple viscoelastic, "), line


@pytest.mark.parametrize("params,word,line", [
    ("NORMAL_FORCE_COEFF 0", "NORMAL_FORCE_COEFF", 12),
    ("NORMAL_DAMPING_PARAMETER -1", "NORMAL_DAMPING_PARAMETER", 12),
    ("NORMAL_FORCE_COEFF x", "NORMAL_FORCE_COEFF", 11)])
def test_bad_parameter_is_an_input_error(tmp_path, params, word, line):
    _styles_or_skip()
    job = _job(tmp_path, params)
    with pytest.raises(InputError, match=rf"ModelPWSimpleViscoElastic parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:{line}: ")
    assert not (tmp_path / "sve_init.mdem").exists()


@pytest.mark.skipif(not CMUSEN, reason="set FIBRELMP_CMUSEN to the real cmusen")
def test_reference_is_cmusens_output(tmp_path):
    for name in ("sve_scene.txt", "job_sve.txt"):
        shutil.copy(DATA / name, tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", "-s=job_sve.txt"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    assert (tmp_path / "sve_result_prec17.txt").read_bytes() == \
        (DATA / "cmusen_sve_result_prec17.txt").read_bytes()


def test_refused_without_fibrelmps_styles(tmp_path):
    """Stock LAMMPS walls have no such law: an InputError at the model line, nothing written."""
    job = _job(tmp_path)
    with lammps_styles.stock(True), pytest.raises(InputError, match="ModelPWSimpleViscoElastic "
                                                  "needs fibrelmp's LAMMPS styles") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:11: ")
    assert not (tmp_path / "sve_init.mdem").exists()
