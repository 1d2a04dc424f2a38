"""Models merged as cmusen merges them (ConsoleSimulator::SetupModelManager: the file's
models, then the job's added; a model already active takes the job's parameters on top of
the file's).  Every active model acts: several solid-bond models -- MUSEN's Example 3: the
file's Kelvin bond and the script's Elastic bond, both listed in cmusen's log -- act on each
bond in turn (tests/test_musen_several_bond_models.py compares that with cmusen); and so do
several particle-particle and particle-wall models (tests/test_musen_several_models.py); two
models of another kind are refused, never silently reduced to one."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from fibrelmp import lammps_styles
from fibrelmp.errors import InputError
from fibrelmp.registry import INPUT, detect

from .conftest import REPO

CASE = REPO / "tests" / "data" / "real-outputs" / "musen" / "example3_models"
SCRIPT = CASE / "Example 3 - Model specification.txt"
SCENE = REPO / "tests" / "data" / "real-inputs" / "musen" / "CompressionTest.mdem"
TEXT_SCENE = REPO / "tests" / "data" / "real-inputs" / "musen" / "SphericalAgglomerate_text.txt"


def _model(script):
    return detect(script).load(INPUT)().model(script)


def _staged(tmp_path, text: str | None = None):
    """MUSEN's example layout: InitScenes/CompressionTest.mdem, Scripts/<script>."""
    (tmp_path / "InitScenes").mkdir()
    (tmp_path / "Scripts").mkdir()
    shutil.copy(SCENE, tmp_path / "InitScenes")
    script = tmp_path / "Scripts" / SCRIPT.name
    script.write_text(SCRIPT.read_text() if text is None else text)
    return script


def test_cmusen_runs_the_files_and_the_scripts_bond_model():
    log = (CASE / "cmusen_example3_short.log").read_text()
    # cmusen's own labels are shifted by one kind; the models and their parameters are not
    assert "Kelvin bond\n\tCONSIDER_BREAKAGE 1 MAX_DAMP_RATIO 1" in log
    assert "Elastic bond\n\tCONSIDER_BREAKAGE 1" in log


def test_example_3_runs_the_files_kelvin_then_the_scripts_elastic(tmp_path):
    model = _model(_staged(tmp_path))
    plan = model.plan
    # cmusen's model manager order: the file's Kelvin bond, then the script's Elastic bond
    assert (plan.bond_law.model, plan.bond_law.form, plan.bond_breakage) == (
        "ModelSBKelvin", "kelvin", 1)
    assert plan.bond_law.max_damp_ratio == 1.0
    assert [(law.model, law.form, law.breakage) for law in plan.then_bond_laws] == [
        ("ModelSBElastic", "elastic", 1)]
    assert model.models["SB"].name == "ModelSBKelvin"


def test_example_3_job_applies_both_laws_in_cmusens_order(tmp_path):
    from fibrelmp.translate.granular_job import write_granular_job

    job = write_granular_job(_model(_staged(tmp_path)), tmp_path / "job")
    script = job.script.read_text()
    assert "bond_style      musen/elastic breakage 1 kelvin 1.0 then elastic 1 geometry" in script
    assert "MUSEN's Kelvin then elastic solid bond" in script


def test_two_particle_particle_models_both_act_in_the_scripts_order(tmp_path):
    """cmusen runs both (tests/test_musen_several_models.py compares that with cmusen)."""
    from fibrelmp.translate.granular_job import write_granular_job

    shutil.copy(TEXT_SCENE, tmp_path)
    script = tmp_path / "job.txt"
    script.write_text(f"SOURCE_FILE {TEXT_SCENE.name}\nRESULT_FILE ./r.txt\n"
                      "MODEL_PP ModelPPHertzMindlin\nMODEL_PP ModelPPLinearElastic\nMODEL_SB ModelSBElastic\n"
                      "MODEL_PARAMS ModelPPLinearElastic Kn 3e5 Kt 2e5\nSIMULATION_STEP 1e-8\nEND_TIME 1e-7\n")
    model = _model(script)
    assert model.models["PP"].name == "ModelPPHertzMindlin"
    assert [(c.name, c.parameters, c.line) for c in model.later_models] == [
        ("ModelPPLinearElastic", {"Kn": 3e5, "Kt": 2e5}, 4)]
    if lammps_styles.plugin().available:
        lines = write_granular_job(model, tmp_path / "job").script.read_text().splitlines()
        assert "pair_style      musen/hm then linear/elastic 300000.0 200000.0" in lines


def test_the_files_model_named_again_takes_the_scripts_parameters_on_top(tmp_path):
    # the file stores ModelSBKelvin "CONSIDER_BREAKAGE 1 MU 1" (MU is no parameter of it)
    text = SCRIPT.read_text().replace("MODEL_SB             ModelSBElastic",
                                      "MODEL_SB             ModelSBKelvin")
    text = text.replace("MODEL_SB_PARAMS      CONSIDER_BREAKAGE 1 BIMODULARITY 1 COMPRESSIVE_BREAK 0",
                        "MODEL_SB_PARAMS      MAX_DAMP_RATIO 0.5")
    model = _model(_staged(tmp_path, text))
    sb = model.models["SB"]
    assert (sb.name, sb.parameters) == ("ModelSBKelvin", {"CONSIDER_BREAKAGE": 1.0,
                                                          "MAX_DAMP_RATIO": 0.5})
    assert (sb.line, model.models["PP"].name) == (9, "ModelPPHertzMindlin")


def test_the_files_model_named_again_without_parameters_keeps_the_files(tmp_path):
    text = SCRIPT.read_text().replace("MODEL_SB             ModelSBElastic",
                                      "MODEL_SB             ModelSBKelvin")
    text = "\n".join(ln for ln in text.splitlines() if not ln.startswith("MODEL_SB_PARAMS"))
    sb = _model(_staged(tmp_path, text)).models["SB"]
    assert (sb.name, sb.parameters, sb.line) == ("ModelSBKelvin", {"CONSIDER_BREAKAGE": 1.0,
                                                                   "MAX_DAMP_RATIO": 1.0}, None)


def _elastic_then_kelvin_job(tmp_path: Path, max_damp_ratio: str) -> Path:
    """A script with MODEL_SB Elastic, then Kelvin with this MAX_DAMP_RATIO."""
    shutil.copy(TEXT_SCENE, tmp_path)
    script = tmp_path / "job.txt"
    script.write_text(f"SOURCE_FILE {TEXT_SCENE.name}\nRESULT_FILE ./r.txt\n"
                      "MODEL_PP ModelPPHertzMindlin\nMODEL_SB ModelSBElastic\n"
                      f"MODEL_SB ModelSBKelvin\nMODEL_PARAMS ModelSBKelvin MAX_DAMP_RATIO {max_damp_ratio}\n"
                      "SIMULATION_STEP 1e-8\nEND_TIME 1e-7\n")
    return script


def test_two_bond_models_in_one_script_act_in_script_order(tmp_path):
    plan = _model(_elastic_then_kelvin_job(tmp_path, "0.25")).plan
    assert (plan.bond_law.form, plan.bond_breakage) == ("elastic", 1)
    assert [(law.form, law.breakage, law.max_damp_ratio) for law in plan.then_bond_laws] == [
        ("kelvin", 1, 0.25)]


def test_a_later_bond_models_bad_parameter_names_its_line(tmp_path):
    script = _elastic_then_kelvin_job(tmp_path, "-1")
    with pytest.raises(InputError) as err:
        _model(script)
    assert (err.value.path, err.value.line) == (str(script), 5)
    assert "MAX_DAMP_RATIO must be >= 0" in err.value.message
