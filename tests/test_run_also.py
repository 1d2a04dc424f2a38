"""``fibrelmp run --also NAME``: the formats written from a run's own frames come from the
registry (its ALSO role, ``fibrelmp.also``), not from the input hooks or the CLI.

- ``--also vtk`` writes the same files, byte for byte, as the deprecated ``--vtk`` (which the
  CLI rewrites into ``--also vtk`` with a one-line note on stderr);
- an unknown ``--also`` name is exit 2 with the choices, nothing written;
- a format registered with an ALSO hook (a toy one here) is written by any granular run, and
  its bare ``--NAME`` works as the alias, without touching any hook or the CLI.
"""

from __future__ import annotations

import filecmp
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fibrelmp import python_api, registry
from fibrelmp.cli import app
from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.also import RunOutput, chosen
from fibrelmp.registry import ALSO, Format

REPO = Path(__file__).resolve().parents[1]
HEAD_ON = REPO / "examples" / "demdf" / "head_on.json"       # 2 spheres, 9 snapshots


def results(folder: Path) -> list[str]:
    """The files a run wrote in ``folder`` (its work folder aside)."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*")
                  if p.is_file() and "_work" not in p.relative_to(folder).parts[0])


def run_cli(args: list[str]):
    return CliRunner().invoke(app, ["run", *map(str, args)])


def test_also_vtk_writes_the_files_the_deprecated_flag_wrote(tmp_path):
    new, old = tmp_path / "new", tmp_path / "old"
    for folder in (new, old):
        folder.mkdir()
        shutil.copy(HEAD_ON, folder)
    by_option = run_cli([new / "head_on.json", "--also", "vtk"])
    by_flag = run_cli([old / "head_on.json", "--vtk"])
    assert by_option.exit_code == 0, by_option.output
    assert by_flag.exit_code == 0, by_flag.output
    files = results(new)
    assert files == results(old)
    assert "head_on.pvd" in files and len([f for f in files if f.endswith(".vtp")]) == 9
    match, mismatch, errors = filecmp.cmpfiles(new, old, files, shallow=False)
    assert (mismatch, errors) == ([], [])
    # the alias says so, once, on stderr; the option says nothing of the kind
    notes = [line for line in by_flag.stderr.splitlines() if "deprecated" in line]
    assert notes == ["note: --vtk is deprecated, use --also vtk"]
    assert "deprecated" not in by_option.stderr and "deprecated" not in by_flag.stdout


@pytest.mark.parametrize("also", [["x"], ["vtk,x"], ["vtk", "--also", "x"]])
def test_unknown_also_is_exit_2_with_the_choices_and_nothing_written(tmp_path, also):
    shutil.copy(HEAD_ON, tmp_path)
    res = run_cli([tmp_path / "head_on.json", "--also", *also])
    assert res.exit_code == 2
    assert "--also 'x': unknown format (choose from " + ", ".join(registry.names(ALSO)) + ")" \
        in res.stderr
    assert "Traceback" not in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["head_on.json"]


def test_also_names_repeated_comma_separated_or_capitalised_count_once():
    assert chosen(["vtk,VTK", " vtk ", ""]) == ("vtk",)
    assert chosen([]) == ()
    with pytest.raises(InputError, match=r"--also 'xyz': unknown format"):
        chosen(["xyz"])         # a format, but not one written from a run's frames


# -- a format registered with an ALSO hook needs nothing else --------------------------------
class TimesWriter(Writer):
    """``<base>.times``: one ``time count`` line per frame."""

    def outputs(self) -> list[Path]:
        return [self.target.with_name(self.target.name + ".times")]

    def write(self, frame) -> None:
        self.put(self.outputs()[0], f"{frame.time!r} {len(frame.position)}\n".encode())


class TimesOutput(RunOutput):
    def declare(self, outputs, base: Path) -> None:
        outputs.files.append(base.with_name(base.name + ".times"))

    def granular_writer(self, model, base: Path) -> Writer:
        return TimesWriter(base)

    def fibrenet_writer(self, model, base: Path) -> Writer:
        raise NotImplementedError       # this toy writes granular frames only


@pytest.fixture
def times_format():
    registry.register_format(Format("times", "frame times (a toy)", "any",
                                    {ALSO: f"{__name__}:TimesOutput"}))
    yield
    registry.unregister_format("times")


@pytest.mark.parametrize("flag", [["--also", "vtk,times"], ["--times", "--vtk"]])
def test_a_registered_run_output_is_written_without_any_hook_change(tmp_path, times_format, flag):
    shutil.copy(HEAD_ON, tmp_path)
    res = run_cli([tmp_path / "head_on.json", *flag])
    assert res.exit_code == 0, res.output
    spec = json.loads(HEAD_ON.read_text())
    period = spec["output"]["snapshot"]["savePeriodInTime"]
    rows = np.loadtxt(tmp_path / "head_on.times", ndmin=2)
    np.testing.assert_allclose(rows[:, 0], [k * period for k in range(9)], rtol=1e-12, atol=1e-15)
    assert (rows[:, 1] == 2).all()
    assert (tmp_path / "head_on.pvd").is_file()
    assert ("note: --times is deprecated" in res.stderr) == (flag[0] == "--times")


def test_an_input_that_cannot_write_a_run_output_refuses_it_before_anything(tmp_path, times_format):
    """A CardioProof run's frames are its own VTK results; another --also format is an input
    error (it used to be ignored), found before the case is read."""
    case = tmp_path / "case.json"
    case.write_text('{"cardioproof": 1}')
    with pytest.raises(InputError, match=r"--also times: a CardioProof run writes its frames only"):
        python_api.run(case, also=["times"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.json"]


def test_python_api_viewer_files_is_a_deprecated_also(tmp_path):
    """``run(viewer_files=True)`` (before ``also``) still writes the files, with a warning."""
    shutil.copy(HEAD_ON, tmp_path)
    with pytest.warns(DeprecationWarning, match=r"run\(viewer_files=True\) is deprecated: use also=\[.vtk.\]"):
        done = python_api.run(tmp_path / "head_on.json", viewer_files=True)
    assert tmp_path / "head_on.pvd" in done.outputs and (tmp_path / "head_on_000008.vtp").is_file()


def test_also_choices_complete_and_help_come_from_the_registry(times_format):
    line = "fibrelmp run scene.txt --also "
    env = {"_FIBRELMP_COMPLETE": "complete_bash", "COMP_WORDS": line,
           "COMP_CWORD": str(len(line.split(" ")) - 1), "_TYPER_COMPLETE_ARGS": line}
    done = CliRunner().invoke(app, [], prog_name="fibrelmp", env=env)
    assert done.exit_code == 0 and done.stdout.split() == registry.names(ALSO)
    assert "times" in registry.names(ALSO)          # registered after the CLI was imported
    helped = CliRunner().invoke(app, ["run", "--help"], terminal_width=400)
    assert all(f"{f.name}: {f.title}" in " ".join(helped.stdout.split())
               for f in registry.formats(ALSO) if f.name != "times")
