"""One CLI: usage lines and option lists in the usual form (no ``{input}``, ``<path>`` or
``<list[str]>``), tab completion of ``--to`` values, ``--frames`` out of range says how many
frames there are, ``--precision`` refused (exit 2, nothing written) where it means nothing."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from fibrelmp import python_api
from fibrelmp.cli import app
from fibrelmp.registry import DOCUMENT, TARGET, names

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
COMMANDS = sorted(typer.main.get_command(app).commands)


def invoke(*args, **kwargs):
    return CliRunner().invoke(app, [str(a) for a in args], prog_name="fibrelmp", **kwargs)


@pytest.fixture(scope="module")
def head_on(tmp_path_factory):
    """The DEMDF head-on example run once: its work dump has 9 frames."""
    folder = tmp_path_factory.mktemp("head_on")
    python_api.run(EXAMPLES / "demdf" / "head_on.json", folder)
    return folder / "head_on_work" / "frames.dump"


# -- help -----------------------------------------------------------------------------------------
def test_the_command_list_has_plot_and_snapshot():
    assert {"run", "check", "translate", "post", "convert", "plot", "snapshot"} <= set(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_usage_names_arguments_plainly(command):
    result = invoke(command, "--help", terminal_width=100)
    assert result.exit_code == 0
    usage = result.stdout.splitlines()[0]
    assert re.fullmatch(rf"Usage: fibrelmp {command} \[OPTIONS\]( [A-Z]+)+", usage), usage
    # no typer/click type placeholders anywhere: <path>, <str>, <list[str]>, {input}
    placeholders = re.findall(r"<[a-z][\w\[\],]*>|\{[a-z_]+\}", result.stdout)
    assert not placeholders, (placeholders, result.stdout)
    argument = usage.split()[-1]
    assert re.search(rf"(?m)^  {argument}  ", result.stdout), result.stdout   # Arguments: NAME  help


def test_post_options_show_what_they_take():
    text = invoke("post", "--help", terminal_width=100).stdout
    for option in ("--to NAME", "--types TYPES", "--gravity GX GY GZ", "--frames SPEC", "--data FILE",
                   "--precision DIGITS"):
        assert option in text, option
    missing = invoke("post")
    assert missing.exit_code == 2 and "Missing argument 'DUMP'" in missing.output


# -- completion -----------------------------------------------------------------------------------
def complete(line: str, shell: str = "bash") -> list[str]:
    words = line.split(" ")
    env = {"_FIBRELMP_COMPLETE": f"complete_{shell}", "COMP_WORDS": line,
           "COMP_CWORD": str(len(words) - 1), "_TYPER_COMPLETE_ARGS": line}
    result = invoke(env=env)
    assert result.exit_code == 0, result.output
    return result.stdout.split()


def test_to_values_complete():
    assert complete("fibrelmp post frames.dump --to ") == names(TARGET)
    assert complete("fibrelmp post frames.dump --to m") == [n for n in names(TARGET) if n.startswith("m")]
    assert complete("fibrelmp convert scene.txt --to ") == names(DOCUMENT)
    assert complete("fibrelmp plot run_work --source ") == ["auto", "log", "result"]
    zsh = " ".join(complete("fibrelmp post frames.dump --to v", "zsh"))
    assert '"vtk"' in zsh and "mercury" not in zsh


# -- --frames -------------------------------------------------------------------------------------
@pytest.mark.parametrize("spec, says", [
    ("9", "frame 9 does not exist: the LAMMPS dump has 9 frames (indices 0..8, or -9..-1 from the end)"),
    ("-10", "frame -10 does not exist: the LAMMPS dump has 9 frames"),
    ("0,20", "frame 20 does not exist: the LAMMPS dump has 9 frames"),
    ("20:", "selects no frame: the LAMMPS dump has 9 frames"),
])
def test_frames_out_of_range_says_how_many_frames_exist(head_on, tmp_path, spec, says):
    result = invoke("post", head_on, "--to", "xyz", "-o", tmp_path / "x", "--frames", spec)
    assert result.exit_code == 2, result.output
    assert says in result.stderr and str(head_on) in result.stderr
    assert not list(tmp_path.iterdir())          # nothing written


def test_frames_in_range_still_convert(head_on, tmp_path):
    from fibrelmp.translate.fibrenet.writer import read_xyz

    assert invoke("post", head_on, "--to", "xyz", "-o", tmp_path / "x", "--frames", "-2:,0").exit_code == 0
    assert len(read_xyz(tmp_path / "x_coord.xyz")) == 3


# -- --precision ----------------------------------------------------------------------------------
SCENE = EXAMPLES / "musen" / "SingelParticle_text.txt"


@pytest.mark.parametrize("args, says", [
    ([EXAMPLES / "fibre_network" / "input.txt"], "FibreNet's results have FibreNet's own digits"),
    ([EXAMPLES / "demdf" / "head_on.json"], "DEMDF snapshots keep every number exactly"),
    ([EXAMPLES / "musen" / "single_particle_job.txt"], "TEXT_EXPORT_PRECISION"),
    ([SCENE, "--end-time", "1e-3", "-o", "{tmp}/r.mdem"], "is a .mdem file"),
    ([EXAMPLES / "musen" / "SingelParticle.mdem", "-o", "{tmp}/r.mdem"], "is a .mdem file"),
])
def test_run_refuses_precision_where_results_take_none(tmp_path, args, says):
    args = [str(a).replace("{tmp}", str(tmp_path)) for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "out")]
    result = invoke("run", *args, "--precision", "9")
    assert result.exit_code == 2, result.output
    assert "--precision has no meaning here" in result.stderr and says in result.stderr
    assert not list(tmp_path.iterdir())          # nothing written, no folder made


def test_precision_out_of_range(tmp_path):
    result = invoke("run", SCENE, "--end-time", "1e-3", "-o", tmp_path / "r.txt", "--precision", "0")
    assert result.exit_code == 2 and "--precision must be 1..17, got 0" in result.stderr
    assert not list(tmp_path.iterdir())


def test_convert_refuses_precision_for_a_binary_output(tmp_path):
    result = invoke("convert", SCENE, "-o", tmp_path / "s.mdem", "--precision", "17")
    assert result.exit_code == 2 and "--precision has no meaning for a MUSEN .mdem" in result.stderr
    assert not list(tmp_path.iterdir())
    assert invoke("convert", SCENE, "-o", tmp_path / "s.mdem").exit_code == 0
    assert invoke("convert", tmp_path / "s.mdem", "-o", tmp_path / "s.txt", "--precision", "17").exit_code == 0


def test_readme_convert_row_runs_as_written(tmp_path):
    """Issue 24: README's ``convert`` row gave ``--precision`` to a ``.mdem`` output, which is
    refused; every command of the row (optional parts included) now runs as written."""
    row = next(line for line in (REPO / "README.md").read_text().splitlines()
               if line.startswith("| `fibrelmp convert scene.mdem"))
    commands = re.findall(r"`((?:fibrelmp )?convert [^`]+)`", row.split(" | ")[0])
    assert len(commands) == 2, row
    (tmp_path / "scene.txt").write_bytes(SCENE.read_bytes())
    (tmp_path / "scene.mdem").write_bytes((EXAMPLES / "musen" / "SingelParticle.mdem").read_bytes())
    for command in commands:
        words = command.replace("[", "").replace("]", "").split()
        words = [str(tmp_path / w) if w.startswith("scene.") else w for w in words[words.index("convert"):]]
        result = invoke(*words, "--force")
        assert result.exit_code == 0, (command, result.output)


def significant_digits(token: str) -> int:
    """Digits of a %g number: its mantissa without sign, point, leading and trailing zeros."""
    mantissa = re.split("[eE]", token.lstrip("+-"))[0].replace(".", "")
    return len(mantissa.strip("0"))


def test_post_precision_only_for_targets_that_write_digits(head_on, tmp_path):
    refused = invoke("post", head_on, "--to", "xyz", "-o", tmp_path / "x", "--precision", "9")
    assert refused.exit_code == 2 and "only --to musen writes numbers" in refused.stderr
    assert not list(tmp_path.iterdir())
    for digits in (None, 9):
        out = tmp_path / f"r{digits}.txt"
        extra = [] if digits is None else ["--precision", str(digits)]
        data = ["--data", head_on.with_name("data.lammps")]            # the spheres' radii
        done = invoke("post", head_on, "--to", "musen", "-o", out, *data, *extra)
        assert done.exit_code == 0, done.output
        numbers = [w for line in out.read_text().splitlines() if line.startswith("0 ")
                   for w in line.split() if re.fullmatch(r"[-+]?[\d.]+(e[-+]?\d+)?", w)]
        assert max(map(significant_digits, numbers)) == (6 if digits is None else 9)
