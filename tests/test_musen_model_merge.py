"""Models merged as cmusen merges them (ConsoleSimulator::SetupModelManager: the file's
models, then the job's added; a model already active takes the job's parameters on top of
the file's).  Every active model acts, so two of one kind -- MUSEN's Example 3: the file's
Kelvin bond and the script's Elastic bond, both listed in cmusen's log -- are refused, never
silently reduced to one."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

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


def test_example_3_is_refused_naming_both_bond_models(tmp_path):
    script = _staged(tmp_path)
    with pytest.raises(InputError) as err:
        _model(script)
    assert err.value.path == str(script) and err.value.line == 9
    assert err.value.message.startswith(
        "ModelSBElastic (line 9) and ModelSBKelvin (stored in CompressionTest.mdem) are both "
        "SB models: cmusen runs every selected model")


def test_example_3_through_the_cli_exits_2_and_writes_nothing(tmp_path):
    script = _staged(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", script.name],
                          cwd=script.parent, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert f"{script.name}:9: ModelSBElastic (line 9) and ModelSBKelvin" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in script.parent.iterdir()) == [script.name]


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


def test_two_bond_models_in_one_script_are_refused(tmp_path):
    shutil.copy(TEXT_SCENE, tmp_path)
    script = tmp_path / "job.txt"
    script.write_text(f"SOURCE_FILE {TEXT_SCENE.name}\nRESULT_FILE ./r.txt\n"
                      "MODEL_PP ModelPPHertzMindlin\nMODEL_SB ModelSBElastic\n"
                      "MODEL_SB ModelSBKelvin\nEND_TIME 1e-7\n")
    with pytest.raises(InputError) as err:
        _model(script)
    assert err.value.line == 5
    assert err.value.message.startswith("ModelSBKelvin (line 5) and ModelSBElastic (line 4) are "
                                        "both SB models")
    assert "remove one of the two MODEL_ lines" in err.value.message
