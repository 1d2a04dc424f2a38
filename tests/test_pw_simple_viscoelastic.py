"""ModelPWSimpleViscoElastic (translate/granular/models/pw_simple_viscoelastic.py, law
simple/viscoelastic of fix musen/wall/mesh) against the real cmusen: a spinning glass sphere
bouncing obliquely on a steel plate
(tests/data/real-outputs/musen/models/pw_simple_viscoelastic/README.md).  The opt-in test
(FIBRELMP_CMUSEN) reruns cmusen and checks the stored reference is still its output."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_reference_is_cmusens_output,
                                 check_refused_without_styles, model_job, needs_cmusen,
                                 styles_or_skip)

DATA = data_path("real-outputs/musen/models/pw_simple_viscoelastic")
PARAMS = "NORMAL_FORCE_COEFF 3000 NORMAL_DAMPING_PARAMETER 0.002"
# cmusen saves the half-step velocity during a contact (README.md): compare outside it
IN_CONTACT = (0.9e-4, 3.1e-4)


def _job(tmp_path: Path, params: str = PARAMS) -> Path:
    return model_job(tmp_path, DATA, "sve", PARAMS, params)


def test_oblique_bounce_is_cmusens(tmp_path):
    styles_or_skip()
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
    styles_or_skip()
    job = _job(tmp_path, params)
    with pytest.raises(InputError, match=rf"ModelPWSimpleViscoElastic parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:{line}: ")
    assert not (tmp_path / "sve_init.mdem").exists()


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "sve")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPWSimpleViscoElastic", 11, tmp_path / "sve_init.mdem")
