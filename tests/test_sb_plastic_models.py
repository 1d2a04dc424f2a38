"""MUSEN's plastic solid bonds (translate/granular/models/sb_elastic_perfectly_plastic.py,
sb_linear_plastic.py, sb_creep.py, sb_weakening.py, sb_aerogel.py, sb_plastic_concrete.py; ``bond_style
musen/elastic ... plastic | linear/plastic | creep | weakening | aerogel | concrete``) against the real cmusen: three spheres joined by two bonds of a soft binder, pulled
apart with spins and sideways velocities, past yield and back
(tests/data/real-outputs/musen/models/sb_*/README.md).  Compared at every cmusen time point:
positions (displacements), velocities, angular velocities, which bonds broke and when.  The
same scene under ModelSBElastic is far from each (the comparison can fail); the plastic
strain lives in the bond's history and goes through a checkpoint and resume unchanged."""

from __future__ import annotations

import gzip
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError, RunError
from fibrelmp.translate.musen.scene import read

from .conftest import data_path
from .musen_model_checks import (CMUSEN, check_refused_without_styles, check_resume_is_bitwise,
                                 needs_cmusen, sphere_differences, styles_or_skip)

MODELS = data_path("real-outputs", "musen", "models")
TAGS = (12, 15, 16)    # position, velocity, angular velocity
# (folder, job prefix, result prefix, MUSEN model, bond_style words, when each bond breaks)
CASES = {
    "plastic": ("sb_elastic_perfectly_plastic", "epp", "epp", "ModelSBElasticPerfectlyPlastic",
                "breakage 0 plastic 0.03 0.2 1.0 0.5 ", [3.5e-5, np.inf]),
    "elastic-then-plastic": ("sb_elastic_perfectly_plastic", "epp_then", "eppthen", None,
                             "breakage 0 then plastic 0 0.03 0.2 1.0 0.5 ", [np.inf, np.inf]),
    "linear-plastic": ("sb_linear_plastic", "lp", "lp", "ModelSBLinearPlastic",
                       "breakage 1 linear/plastic 5000000.0 20000000.0 ", [np.inf, np.inf]),
    "creep": ("sb_creep", "creep", "creep", "ModelSBCreep",
              "breakage 1 creep 0.1 0.0 1.0 0.5 0.2 0.5 ", [np.inf, np.inf]),
    "weakening": ("sb_weakening", "wk", "wk", "ModelSBWeakening",
                  "breakage 1 weakening 1.0 0.03 0.0 ", [2.75e-5, np.inf]),
    "aerogel": ("sb_aerogel", "ag", "ag", "ModelSBAerogel",
                "breakage 0 aerogel 0.01 0.005 -2.0 -0.5 0.5 0.1 0.1 ", [np.inf, np.inf]),
    "plastic-concrete": ("sb_plastic_concrete", "pc", "pc", "ModelSBPlasticConcrete",
                         "breakage 1 concrete ", [1.08e-5, 1.6e-5]),
}
SINGLE = ["plastic", "linear-plastic", "creep", "weakening", "aerogel", "plastic-concrete"]


def _case_folder(tmp_path: Path, case: str, job_text: str | None = None) -> Path:
    folder, prefix, *_ = CASES[case]
    data = MODELS / folder
    for scene in data.glob("*_scene.txt"):
        shutil.copy(scene, tmp_path)
    job = tmp_path / f"job_{prefix}.txt"
    job.write_text((data / job.name).read_text() if job_text is None else job_text)
    return job


def _cmusen_result(tmp_path: Path, case: str) -> Path:
    folder, _, result, *_ = CASES[case]
    path = tmp_path / f"cmusen_{result}_result_prec17.txt"
    with gzip.open(MODELS / folder / f"{path.name}.gz", "rb") as src, open(path, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return path


@pytest.mark.parametrize("case", list(CASES))
def test_matches_cmusen_at_every_saved_time(tmp_path, case):
    styles_or_skip()
    _, prefix, result, _, words, ends = CASES[case]
    real = _cmusen_result(tmp_path, case)
    job = _case_folder(tmp_path, case)
    python_api.run(job, work=tmp_path / "work")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert f"bond_style      musen/elastic {words}" in script
    diffs = sphere_differences(real, tmp_path / f"{result}_result_prec17.txt", TAGS, times_rtol=1e-12)
    assert all(d < 1e-6 for d in diffs.values()), diffs
    real_end = read(real).bonds.active_end
    np.testing.assert_array_equal(real_end, ends)       # the case is what its README says
    np.testing.assert_array_equal(read(tmp_path / f"{result}_result_prec17.txt").bonds.active_end,
                                  real_end)


@pytest.mark.parametrize("case", SINGLE)
def test_elastic_bond_is_far_from_cmusen(tmp_path, case):
    """The same scene with MUSEN's elastic bond (what fibrelmp ran before) is off by the
    order of the motion: the comparison above can fail."""
    styles_or_skip()
    folder, prefix, result, model, *_ = CASES[case]
    text = (MODELS / folder / f"job_{prefix}.txt").read_text()
    params = next(ln for ln in text.splitlines() if ln.startswith("MODEL_SB_PARAMS"))
    text = text.replace(model, "ModelSBElastic").replace(params, "MODEL_SB_PARAMS CONSIDER_BREAKAGE 0")
    real = _cmusen_result(tmp_path, case)
    python_api.run(_case_folder(tmp_path, case, text), work=tmp_path / "work")
    diffs = sphere_differences(real, tmp_path / f"{result}_result_prec17.txt", TAGS, times_rtol=1e-12)
    assert max(diffs.values()) > 0.5, diffs


def test_creep_is_not_the_plastic_law(tmp_path):
    """Creep off (A = 0: ModelSBCreep is then the elastic-perfectly-plastic law) differs from
    cmusen's creep run by several percent of the spin scale."""
    styles_or_skip()
    text = (MODELS / "sb_creep" / "job_creep.txt").read_text().replace(
        "CREEP_PARAMATER_A 0.2", "CREEP_PARAMATER_A 0")
    real = _cmusen_result(tmp_path, "creep")
    python_api.run(_case_folder(tmp_path, "creep", text), work=tmp_path / "work")
    diffs = sphere_differences(real, tmp_path / "creep_result_prec17.txt", TAGS, times_rtol=1e-12)
    assert max(diffs.values()) > 0.05


def test_checkpoint_and_resume_keep_the_plastic_state(tmp_path, monkeypatch):
    """The plastic strain and last normal stress are in the bond's history (restart file): a
    creep run stopped after a checkpoint while the bonds are yielded and creeping, then
    resumed, writes the uninterrupted run's result byte for byte."""
    check_resume_is_bitwise(tmp_path, monkeypatch, lambda at: _case_folder(at, "creep"),
                            "creep_result_prec17.txt", 1503)


@pytest.mark.parametrize("params,word", [
    ("FRACTURE_STRAIN_TENSION inf", "FRACTURE_STRAIN_TENSION"),
    ("CREEP_PARAMATER_A nan", "CREEP_PARAMATER_A")])
def test_bad_parameter_is_an_input_error(tmp_path, params, word):
    styles_or_skip()
    text = (MODELS / "sb_creep" / "job_creep.txt").read_text()
    old = next(ln for ln in text.splitlines() if ln.startswith("MODEL_SB_PARAMS"))
    job = _case_folder(tmp_path, "creep", text.replace(old, f"MODEL_SB_PARAMS      {params}"))
    with pytest.raises(InputError, match=rf"ModelSBCreep parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:12: ")


def test_kunload_zero_is_an_input_error(tmp_path):
    styles_or_skip()
    text = (MODELS / "sb_linear_plastic" / "job_lp.txt").read_text().replace("KUnLoad 2e7",
                                                                              "KUnLoad 0")
    job = _case_folder(tmp_path, "linear-plastic", text)
    with pytest.raises(InputError, match="KUnLoad must not be 0") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:12: ")


def test_random_weakening_stops_the_run_where_it_draws(tmp_path):
    """WEAKENING_FACTOR 0.5: MUSEN multiplies by 0.5 rand()/RAND_MAX once a bond exceeds its
    yield strength; the run stops there with an error naming the bond and the step (up to
    then the law is exact)."""
    styles_or_skip()
    text = (MODELS / "sb_weakening" / "job_wk.txt").read_text().replace("WEAKENING_FACTOR 0",
                                                                        "WEAKENING_FACTOR 0.5")
    with pytest.raises(RunError, match=r"bond 1-2 exceeds its yield strength at step 50, where "
                       r"MUSEN's weakening bond multiplies by WEAKENING_FACTOR rand\(\)"):
        python_api.run(_case_folder(tmp_path, "weakening", text), work=tmp_path / "work")


def test_missing_yield_strength_is_musens_default(tmp_path):
    """A bond material without a yield strength (property 15) has MUSEN's default, 2e10 Pa
    (DefinesMDB.h _YIELD_DEFAULT), as cmusen gives it."""
    styles_or_skip()
    job = _case_folder(tmp_path, "plastic")
    scene = tmp_path / "epp_scene.txt"
    scene.write_text(scene.read_text().replace(" 15 3e+04", ""))
    python_api.run(job, work=tmp_path / "work")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert " yield 20000000000.0  # Binder" in script


@pytest.mark.parametrize("case", SINGLE)
def test_refused_without_fibrelmps_styles(tmp_path, case):
    _, _, _, model, *_ = CASES[case]
    check_refused_without_styles(_case_folder(tmp_path, case), model, 11,
                                 tmp_path / f"{CASES[case][1]}_init.mdem")


@needs_cmusen
@pytest.mark.parametrize("case", list(CASES))
def test_reference_is_cmusens_output(tmp_path, case):
    _, prefix, result, *_ = CASES[case]
    job = _case_folder(tmp_path, case)
    done = subprocess.run([CMUSEN, "-t=1", f"-s={job.name}"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    assert ((tmp_path / f"{result}_result_prec17.txt").read_bytes()
            == _cmusen_result(tmp_path, case).read_bytes())
