"""ModelPPLinearElastic (translate/granular/models/pp_linear_elastic.py, pair_style
musen/linear) against the real cmusen: an oblique, spinning impact of two glass spheres
(tests/data/real-outputs/musen/models/pp_linear_elastic/README.md).  The opt-in test
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

DATA = data_path("real-outputs/musen/models/pp_linear_elastic")
# cmusen saves the half-step velocity during a contact (README.md): compare outside it
IN_CONTACT = (2e-4, 4e-4)
PARAMS = "Kn 2000 Kt 1500"


def _job(tmp_path: Path, params: str = PARAMS) -> Path:
    return model_job(tmp_path, DATA, "le", PARAMS, params)


def test_two_sphere_impact_is_cmusens(tmp_path):
    styles_or_skip()
    python_api.run(_job(tmp_path), work=tmp_path / "work")
    ours = read_time_points(tmp_path / "le_result_prec17.txt")
    theirs = read_time_points(DATA / "cmusen_le_result_prec17.txt")
    # cmusen's saved times are sums of steps (4.9999999999999955e-05), fibrelmp's step * dt
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours.ids, theirs.ids)
    assert "musen/linear 2000.0 1500.0" in (tmp_path / "work" / "job2" / "in.lammps").read_text()
    # the impact happened: both spheres were turned and slowed by it
    v0, v1 = theirs.fields[VEL][0], theirs.fields[VEL][-1]
    assert np.linalg.norm(v1 - v0, axis=1).min() > 0.1
    np.testing.assert_allclose(ours.fields[COORD], theirs.fields[COORD], rtol=0, atol=1e-15)
    outside = (theirs.times < IN_CONTACT[0]) | (theirs.times > IN_CONTACT[1])
    np.testing.assert_allclose(ours.fields[VEL][outside], theirs.fields[VEL][outside],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(ours.fields[ANGVEL][outside], theirs.fields[ANGVEL][outside],
                               rtol=1e-12, atol=1e-12)


def test_check_gives_the_linear_contact_time(tmp_path):
    """The time-step figure is the linear spring's half period pi sqrt(m*/Kn), not Hertz's."""
    m_eff = 2500.0 * 4.0 / 3.0 * np.pi * 1e-3 ** 3 / 2
    lines = python_api.check(_job(tmp_path)).lines
    line = next(t for t in lines if t.startswith("contact time"))
    assert line.startswith(f"contact time {np.pi * np.sqrt(m_eff / 2000.0):.3g} (linear elastic, "
                           "Glass-Glass"), line


# a value out of range is reported at MODEL_PP_PARAMS (line 11), one that is no number at the
# MODEL_PP line the parameters belong to (line 10), as for every model
@pytest.mark.parametrize("params,word,line", [("Kn -5", "Kn", 11), ("Kt 0", "Kt", 11),
                                              ("Kn x", "Kn", 10)])
def test_bad_stiffness_is_an_input_error(tmp_path, params, word, line):
    styles_or_skip()
    job = _job(tmp_path, params)
    with pytest.raises(InputError, match=rf"ModelPPLinearElastic parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:{line}: ")
    assert not (tmp_path / "le_init.mdem").exists()


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "le")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPPLinearElastic", 10, tmp_path / "le_init.mdem")
