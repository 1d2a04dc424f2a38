"""MIXTURE_PROPERTY lines read as cmusen's ScriptAnalyzer reads them (six values); MUSEN's
Example 5 as shipped (five values a line) stops cmusen, and stops fibrelmp at the first such
line, naming the cause."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.script_parse import read_script

from .conftest import REPO

CASE = REPO / "tests" / "data" / "real-outputs" / "musen" / "example5_mixture"
SCRIPT = CASE / "Example 5 - Packing generation new PSD.txt"
SCENE = REPO / "tests" / "data" / "real-inputs" / "musen" / "PackingGeneration.mdem"


def test_cmusen_itself_stops_on_example_5():
    log = (CASE / "cmusen_example5.log").read_text()
    assert "The total fraction of material (Mixture0) is not equal to 1 (0.000000)" in log


def _with_simulator_component(tmp_path):
    """Example 5 with `COMPONENT SIMULATOR` on line 3 (same line numbers): until the package
    generator is merged, its component line is refused before line 13 is read; the
    MIXTURE_PROPERTY check does not depend on the component."""
    lines = SCRIPT.read_text().splitlines(keepends=True)
    assert lines[2].split() == ["COMPONENT", "PACKAGE_GENERATOR"]
    lines[2] = "COMPONENT            SIMULATOR\n"
    script = tmp_path / SCRIPT.name
    script.write_text("".join(lines))
    return script


def test_example_5_stops_at_its_first_short_mixture_line(tmp_path):
    script = _with_simulator_component(tmp_path)
    with pytest.raises(InputError) as err:
        read_script(script)
    assert err.value.path == str(script) and err.value.line == 13
    assert err.value.message == ("MIXTURE_PROPERTY: needs 6 values: MIXTURE FRACTION COMPOUND_KEY "
                                 "DIAMETER CONTACT_DIAMETER FRACTION, got 5 (cmusen reads a "
                                 "missing value as 0)")


def test_six_values_are_read_in_cmusens_order(tmp_path):
    script = tmp_path / "job.txt"
    script.write_text("COMPONENT SIMULATOR\n"
                      "MIXTURE_PROPERTY 1 2 CG9ZE5YQBM 1.8e-3 1.7e-3 0.3\n")
    (job,) = read_script(script)
    assert job.mixture_properties == [(1, 2, "CG9ZE5YQBM", 1.8e-3, 1.7e-3, 0.3, 2)]


@pytest.mark.parametrize("line, words", [
    ("0 1 KEY 1e-3 1e-3 1", "the mixture and fraction numbers count from 1"),
    ("1 1.5 KEY 1e-3 1e-3 1", "the mixture and fraction numbers count from 1"),
    ("1 1 KEY 1e-3 x 1", "expected a number, got 'x'"),
    ("1 1 KEY 1e-3 1e-3 1 7", "got 7"),
])
def test_bad_mixture_lines_are_refused(tmp_path, line, words):
    script = tmp_path / "job.txt"
    script.write_text(f"COMPONENT SIMULATOR\nMIXTURE_PROPERTY {line}\n")
    with pytest.raises(InputError) as err:
        read_script(script)
    assert err.value.line == 2 and words in err.value.message


def test_example_5_through_the_cli_exits_2_and_writes_nothing(tmp_path):
    (tmp_path / "InitScenes").mkdir()   # MUSEN's example layout
    (tmp_path / "Scripts").mkdir()
    shutil.copy(SCENE, tmp_path / "InitScenes")
    script = tmp_path / "Scripts" / SCRIPT.name
    shutil.copy(_with_simulator_component(tmp_path), script)
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", SCRIPT.name],
                          cwd=script.parent, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert f"{SCRIPT.name}:13: MIXTURE_PROPERTY: needs 6 values" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in script.parent.iterdir()) == [SCRIPT.name]
