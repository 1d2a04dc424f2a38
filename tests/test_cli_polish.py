"""CLI polish: help with examples, versions (fibrelmp, LAMMPS, MPI), --quiet/--verbose, grouped
and coloured warnings, ``check`` listing every error, units and time-step sanity checks."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fibrelmp import sanity, units
from fibrelmp.model import spring_period
from fibrelmp.cli import app
from fibrelmp.translate.demdf import contact as demdf_contact
from fibrelmp.translate.fibrenet import reader as fibrenet

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO / "tests" / "bad_inputs"


def invoke(*args: str, color: bool = False):
    return CliRunner().invoke(app, list(args), color=color)


# ------------------------------------------------------------------ help, version, completion
@pytest.mark.parametrize("command", ["check", "translate", "run", "post"])
def test_every_command_help_has_examples(command):
    result = invoke(command, "--help")
    assert result.exit_code == 0
    assert "Examples:" in result.stdout
    examples = result.stdout.split("Examples:", 1)[1]
    assert len(re.findall(rf"fibrelmp {command}\b", examples)) >= 2, result.stdout


def test_main_help_gives_examples_exit_codes_and_completion():
    result = invoke("--help")
    assert result.exit_code == 0
    for text in ("Examples:", "Exit codes: 0 success, 1 the run failed", "2 bad input",
                 "--install-completion", "--quiet", "--verbose", "--version"):
        assert text in result.stdout, text


def test_version_names_fibrelmp_lammps_and_the_mpi_library():
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "--version"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("fibrelmp ")
    assert re.match(r"LAMMPS \d{8} \(MPI support: True\)", lines[1]), lines
    # the wheel's MPICH, read with MPI_Get_library_version
    assert re.match(r"MPI MPICH Version: +\d+\.\d+.* \(MPI standard \d+\.\d+\)", lines[2]), lines


# ------------------------------------------------------------------ warnings, --quiet, --verbose
README_INPUT = REPO / "examples" / "fibrenet_readme" / "input.txt"


def test_warnings_grouped_by_kind_with_counts_and_colour():
    result = invoke("check", str(README_INPUT), color=True)
    assert result.exit_code == 0
    plain = re.sub(r"\x1b\[[0-9;]*m", "", result.stderr)
    assert "warning [skin radius] (3): " in plain
    assert "warning [st force jump] (6): " in plain
    assert plain.count("warning [skin radius]") == 1          # one line per kind
    assert "\x1b[33m" in result.stderr                        # yellow
    assert "warnings     10" in result.stdout


def test_verbose_lists_every_warning_and_quiet_keeps_warnings():
    verbose = invoke("--verbose", "check", str(README_INPUT))
    assert verbose.exit_code == 0
    assert len([ln for ln in verbose.stderr.splitlines() if ln.startswith("  ")]) == 2 + 5
    quiet = invoke("--quiet", "check", str(README_INPUT))
    assert "warning [skin radius] (3)" in quiet.stderr


def test_post_reports_warnings_like_the_other_commands(tmp_path):
    dump = CORPUS / "dump" / "good.dump"
    loud = invoke("post", str(dump), "--to", "xyz", "-o", str(tmp_path / "a"))
    assert loud.exit_code == 0, loud.stderr
    assert "warning [no time step]: " in loud.stderr and "wrote " in loud.stdout
    quiet = invoke("--quiet", "post", str(dump), "--to", "xyz", "-o", str(tmp_path / "b"))
    assert quiet.exit_code == 0
    assert "warning [no time step]: " in quiet.stderr       # warnings survive --quiet
    assert "wrote " not in quiet.stdout + quiet.stderr


# ------------------------------------------------------------------ check lists every error
def _errors(result) -> list[str]:
    return [ln[len("error: "):] for ln in result.stderr.splitlines() if ln.startswith("error: ")]


def test_check_lists_every_error_of_a_fibrenet_input_and_model(tmp_path):
    shutil.copy(CORPUS / "fibrenet" / "model.txt", tmp_path / "model.txt")
    model = (tmp_path / "model.txt").read_text().splitlines()
    model[0] = model[0].replace("\t0.3\t", "\t-0.3\t", 1)           # negative radius
    model[2] = model[2].replace("BEAD\tB", "BEAD\tQ")                 # undefined type
    model[4] = model[4].replace("SPRING\tHR\t0\t1\t2", "SPRING\tHR\t0\t1\t9")
    (tmp_path / "model.txt").write_text("\n".join(model) + "\n")
    text = (CORPUS / "fibrenet" / "good.txt").read_text()
    text = text.replace("step 0.001", "step fast").replace("lambda 0.5", "lambda nan")
    (tmp_path / "input.txt").write_text(text + "dampnig 0.2\n")
    result = invoke("check", str(tmp_path / "input.txt"))
    assert result.exit_code == 2
    names = [e.replace(str(tmp_path) + "/", "") for e in _errors(result)]
    assert names == [                                     # by file, then line
        "input.txt:13: step: expected a number, got 'fast'",
        "input.txt:14: lambda: value must be finite, got 'nan'",
        "input.txt:19: unknown keyword 'dampnig' (did you mean 'damping'?)",
        "model.txt:1: BEAD radius must be >= 0, got -0.3",
        "model.txt:3: bead type 'Q' is not defined by a 'type' line (defined: A, B)",
        "model.txt:5: SPRING refers to bead 9, but the model has beads 0..2",
    ]
    assert result.stderr.rstrip().endswith("6 errors")
    assert "Traceback" not in result.stderr
    # run still stops at the first error
    run = invoke("run", str(tmp_path / "input.txt"))
    assert run.exit_code == 2 and len(_errors(run)) == 1
    assert _errors(run)[0].endswith("input.txt:19: unknown keyword 'dampnig' (did you mean 'damping'?)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["input.txt", "model.txt"]


def test_check_lists_every_error_of_a_musen_scene(tmp_path):
    lines = (CORPUS / "musen" / "good.txt").read_text().splitlines()
    lines[1] = lines[1].replace("0.001 0.001", "-0.001 0.001")      # sphere 1: radius
    lines[2] = lines[2].replace("12 0 0 0.012", "12 0 nan 0.012")   # sphere 2: nan
    lines[10] = "32 GLASS Glass 0 2500 7 5e10 10 0.7"               # Poisson ratio
    lines.append("99 1 2")                                           # unknown tag
    (tmp_path / "scene.txt").write_text("\n".join(lines) + "\n")
    result = invoke("check", str(tmp_path / "scene.txt"))
    assert result.exit_code == 2
    got = [re.sub(r"^.*?scene\.txt", "scene.txt", e) for e in _errors(result)]
    assert got == ["scene.txt:2: sphere 1: radius must be positive",
                   "scene.txt:3: time-point value 5 is nan (values must be finite)",
                   "scene.txt:11: material GLASS (Glass): Poisson ratio outside [0, 0.5]",
                   "scene.txt:15: unknown tag `99` outside an object line"], result.stderr


def test_check_lists_every_error_of_a_cmusen_script(tmp_path):
    shutil.copy(CORPUS / "musen_script" / "scene.txt", tmp_path / "scene.txt")
    text = (CORPUS / "musen_script" / "good.txt").read_text()
    text = text.replace("SIMULATION_STEP      1e-7", "SIMULATION_STEP      -1e-7")
    text = text.replace("ModelPWHertzMindlin", "ModelPWHertzMindln")
    (tmp_path / "job.txt").write_text(text + "VERLET_COEFF 2\n")
    result = invoke("check", str(tmp_path / "job.txt"))
    assert result.exit_code == 2
    got = [re.sub(r"^.*?job\.txt", "job.txt", e) for e in _errors(result)]
    assert got == ["job.txt:6: unknown MUSEN model 'ModelPWHertzMindln'; did you mean "
                   "ModelPWHertzMindlin?",
                   "job.txt:8: SIMULATION_STEP: expected a positive finite number, got '-1e-7'",
                   "job.txt:12: unknown cmusen keyword 'VERLET_COEFF'; did you mean VERLET_COEF?"],\
        result.stderr


def test_check_stops_listing_at_the_limit(tmp_path):
    shutil.copy(CORPUS / "fibrenet" / "model.txt", tmp_path / "model.txt")
    text = (CORPUS / "fibrenet" / "good.txt").read_text()
    (tmp_path / "input.txt").write_text(text + "".join(f"typo{k} 1\n" for k in range(80)))
    result = invoke("check", str(tmp_path / "input.txt"))
    assert result.exit_code == 2
    assert len(_errors(result)) == 50
    assert "50 errors (the limit: fix these and check again)" in result.stderr


# ------------------------------------------------------------------ units and sanity checks
def test_check_prints_units_and_spring_period(tmp_path):
    result = invoke("check", str(CORPUS / "fibrenet" / "good.txt"))
    assert result.exit_code == 0
    assert "units        lj (length sigma" in result.stdout and "LAMMPS 'units lj'" in result.stdout
    # springs k = 100 between unit masses: omega^2 = k (1/m1 + 1/m2) = 200
    period = 2 * np.pi / np.sqrt(200)
    assert f"spring period {period:.4g} (shortest, spring 0: beads 0-1) = {period / 0.001:.1f} " \
           "time steps" in result.stdout
    text = (CORPUS / "fibrenet" / "good.txt").read_text().replace("step 0.001", "step 0.05")
    shutil.copy(CORPUS / "fibrenet" / "model.txt", tmp_path / "model.txt")
    (tmp_path / "input.txt").write_text(text)
    coarse = invoke("check", str(tmp_path / "input.txt"))
    assert coarse.exit_code == 0
    assert "warning [time step]: the time step 0.05 exceeds 1/10 of the shortest spring period" \
        in coarse.stderr


def test_check_prints_units_and_hertz_contact_time():
    scene = invoke("check", str(REPO / "examples" / "musen" / "SingelParticle_text.txt"))
    assert scene.exit_code == 0
    assert "units        si (length m, mass kg, time s, force N; LAMMPS 'units si')" in scene.stdout
    # the sphere-on-plate impact at the fastest approach (tests/test_contact_time.py)
    assert re.search(r"contact time 3.33e-06 \(Hertz, Steel-Glass.*\) = 3.3 time steps", scene.stdout)
    assert "warning [time step]: the time step 1e-06 exceeds 1/10 of the Hertz contact time" \
        in scene.stderr
    doc = invoke("check", str(CORPUS / "demdf" / "good.json"))
    assert doc.exit_code == 0
    assert "units        dimensionless" in doc.stdout and "contact time" in doc.stdout


def test_spring_period_treats_mass_zero_as_immovable(tmp_path):
    model = fibrenet.read(CORPUS / "fibrenet" / "good.txt")
    model.particles.masses[:] = [0.0, 2.0, 0.0]       # bead 1 between two fixed beads
    period, row = spring_period(model)
    assert period == pytest.approx(2 * np.pi * np.sqrt(2.0 / 100))
    model.particles.masses[:] = 0.0
    assert spring_period(model) is None


def test_one_hertz_formula():
    # demdf's stiffness choice and check's contact time are the same physics
    m, r, e, v = 0.5, 0.25, 2e6, 3.0
    delta = (15 * m * v ** 2 / (16 * e * np.sqrt(r))) ** 0.4
    assert sanity.hertz_contact_time(m, r, e, v) == pytest.approx(2.943 * delta / v, rel=1e-12)
    assert demdf_contact.contact_time is sanity.hertz_contact_time
    e_needed = demdf_contact.modulus_for_overlap(m, r, v, 0.01)
    assert sanity.hertz_peak_overlap(m, r, e_needed, v) == pytest.approx(0.01, rel=1e-12)


def test_units_module():
    assert units.for_format("fibrenet") is units.LJ
    assert units.for_format("musen") is units.for_format("musen-script") is units.SI
    assert units.for_format("demdf") is units.DIMENSIONLESS
    assert units.system("si") is units.SI
    with pytest.raises(ValueError):
        units.system("furlong")
    assert units.convert(2.0, "length", "metal", "si") == pytest.approx(2e-10)
    assert units.convert(1.0, "energy", "real", "metal") == pytest.approx(0.0433641, rel=1e-5)
    assert units.convert(1.0, "velocity", "metal", "real") == pytest.approx(1e-3)
    np.testing.assert_allclose(units.convert(np.ones(2), "force", "cgs", "si"), [1e-5, 1e-5])
    with pytest.raises(ValueError):
        units.convert(1.0, "length", "lj", "si")
    assert units.mismatch_note("si", units.SI, "MUSEN") is None
    assert "1e-06 m" in units.mismatch_note("micro", units.SI, "MUSEN")


def test_templates_run_each_format_in_the_units_module_style():
    """The job templates still spell their ``units`` line out; they must agree with units.py
    (the translators own the templates)."""
    templates = REPO / "fibrelmp" / "templates"
    bead = (templates / "bead_spring.lammps.j2").read_text()
    assert re.search(rf"^units\s+{units.LJ.lammps}\s*$", bead, re.M)
    granular = templates / "granular.lammps.j2"
    if granular.exists():
        text = granular.read_text()
        assert units.SI.lammps == units.DIMENSIONLESS.lammps
        assert re.search(rf"^units\s+({units.SI.lammps}|{{{{.*}}}})\s*$", text, re.M)


def test_readers_take_their_unit_system_from_units():
    assert fibrenet.read(CORPUS / "fibrenet" / "good.txt").units == units.LJ.name
    from fibrelmp.translate.demdf import reader as demdf
    from fibrelmp.translate.musen import scene as musen

    assert musen.read(CORPUS / "musen" / "good.txt").units == units.SI.name
    assert demdf.read(CORPUS / "demdf" / "good.json").units == units.DIMENSIONLESS.name


def test_readme_documents_exit_codes_completion_and_troubleshooting():
    text = (REPO / "README.md").read_text()
    assert "## Troubleshooting" in text and "## Exit codes" in text
    exits = text.split("## Exit codes", 1)[1].split("\n## ", 1)[0]
    for code in ("| 0 |", "| 1 |", "| 2 |", "| 130 |"):
        assert code in exits, code
    assert "--install-completion" in text
