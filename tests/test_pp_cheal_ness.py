"""ModelPPChealNess (translate/granular/models/pp_cheal_ness.py) against the real cmusen on
spheres whose contact radius is their radius: cmusen's law is its Hertz-Mindlin part there
(tests/data/real-outputs/musen/models/pp_cheal_ness/README.md), and so is fibrelmp's, warned."""

from __future__ import annotations

from pathlib import Path

import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_other_contact_radius_is_refused,
                                 check_reference_is_cmusens_output, check_refused_without_styles,
                                 check_result_is_cmusens, model_job, needs_cmusen, styles_or_skip)

DATA = data_path("real-outputs/musen/models/pp_cheal_ness")
HERTZ = data_path("real-outputs/musen/models/pp_hertz_mindlin_liquid/"
                  "cmusen_liq_as_hertz_mindlin_result_prec17.txt")
PARAMS = "MIN_THICKNESS 2e-6 MAX_THICKNESS 1e-3 FLUID_VISCOSITY 1.0"


def _job(tmp_path: Path, params: str = PARAMS) -> Path:
    return model_job(tmp_path, DATA, "cn", PARAMS, params)


def test_run_is_cmusens_and_warned(tmp_path):
    styles_or_skip()
    result = python_api.run(_job(tmp_path), work=tmp_path / "work")
    assert "pair_style      musen/hm" in (tmp_path / "work" / "job2" / "in.lammps").read_text()
    # cmusen's ChealNess export here is byte for byte its Hertz-Mindlin one (stored once;
    # test_reference_is_cmusens_output reruns cmusen and checks that)
    check_result_is_cmusens(tmp_path / "cn_result_prec17.txt", HERTZ, {COORD: 1e-3, VEL: 2e-2, ANGVEL: 20.0})
    kinds = [k for k, _ in result.warnings]
    assert "musen-model-acts-as-hertz-mindlin" in kinds


def test_non_positive_min_thickness_is_refused(tmp_path):
    styles_or_skip()
    job = _job(tmp_path, "MIN_THICKNESS 0 MAX_THICKNESS 1e-3 FLUID_VISCOSITY 1.0")
    with pytest.raises(InputError, match="ModelPPChealNess parameter MIN_THICKNESS") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:11: ")


def test_contact_radius_other_than_radius_is_refused(tmp_path):
    """There cmusen's lubrication acts between the contact radii; LAMMPS holds one radius."""
    styles_or_skip()
    check_other_contact_radius_is_refused(_job(tmp_path), tmp_path / "cn_scene.txt", 10, "0.0012", -1)


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "cn", stored=HERTZ)


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPPChealNess", 10, tmp_path / "cn_init.mdem")
