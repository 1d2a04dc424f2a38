"""Bad FibreNet input: one `path:line: message`, exit code 2, no traceback, no output file."""

import subprocess
import sys
from pathlib import Path

import pytest

from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.errors import InputError

MODEL = """BEAD\tA\t1\t0\t0.3\t1.0\t1.0\t1.0\t1.0\t0\t0\t0\t0\t0\t0\t1.0\t1.0\t1.0
BEAD\tA\t1\t0\t0.3\t1.0\t1.5\t1.0\t1.0\t0\t0\t0\t0\t0\t0\t1.5\t1.0\t1.0
BEAD\tB\t2\t0\t0.3\t1.0\t1.2\t1.5\t1.0\t0\t0\t0\t0\t0\t0\t1.2\t1.5\t1.0
SPRING\tHR\t0\t0\t1\t0.5\t100
"""
INPUT = """model_file model.txt
output_file out
type A
type B
pair hs A A 100
pair hs B B 100
pair hs A B 100
box_size 5 5 5
box_type finite
box_wall_rep 100
box_unit_cell 1.0
cutoff 1.0
step 0.001
lambda 0.5
run 20
output_freq 10
output_data all
output_type all
"""


def write_case(folder: Path, model: str = MODEL, inp: str = INPUT) -> Path:
    (folder / "model.txt").write_text(model)
    (folder / "input.txt").write_text(inp)
    return folder / "input.txt"


CASES = {
    "unknown keyword": (MODEL, INPUT + "dampnig 0.1\n", "input.txt:19", "unknown keyword 'dampnig'"),
    "wrong token count": (MODEL, INPUT.replace("box_size 5 5 5", "box_size 5 5"), "input.txt:8",
                          "'box_size' takes 3 value(s)"),
    "not a number": (MODEL, INPUT.replace("step 0.001", "step fast"), "input.txt:13", "expected a number"),
    "bead outside box": (MODEL.replace("\t1.2\t1.5\t1.0\t0", "\t7.2\t1.5\t1.0\t0"), INPUT, "model.txt:3",
                         "outside the box"),
    "undefined type pair": (MODEL, INPUT.replace("pair hs A B 100\n", ""), "input.txt",
                            "no 'pair' line for types A B"),
    "bond to missing bead": (MODEL.replace("SPRING\tHR\t0\t0\t1", "SPRING\tHR\t0\t0\t7"), INPUT, "model.txt:4",
                             "refers to bead 7"),
    "bead token count": (MODEL.replace("\t1.0\t1.0\t1.0\n", "\t1.0\t1.0\n", 1), INPUT, "model.txt:1",
                         "needs 18 tokens"),
    "undefined bead type": (MODEL.replace("BEAD\tB", "BEAD\tC"), INPUT, "model.txt:3", "bead type 'C'"),
    "missing model": (MODEL, INPUT.replace("model.txt", "nope.txt"), "input.txt:1", "model file 'nope.txt' not found"),
    "missing box_wall_rep": (MODEL, INPUT.replace("box_wall_rep 100\n", ""), "input.txt",
                             "'box_wall_rep' is missing"),
    "negative step": (MODEL, INPUT.replace("step 0.001", "step -0.001"), "input.txt:13", "must be > 0"),
    "nan radius": (MODEL.replace("\t0.3\t1.0\t1.2", "\tnan\t1.0\t1.2"), INPUT, "model.txt:3", "finite"),
    "self bond": (MODEL.replace("SPRING\tHR\t0\t0\t1", "SPRING\tHR\t0\t1\t1"), INPUT, "model.txt:4", "itself"),
    "lambda missing": (MODEL, INPUT.replace("lambda 0.5\n", ""), "input.txt", "'lambda' is missing"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_reader_reports_location(name, tmp_path):
    model, inp, where, what = CASES[name]
    path = write_case(tmp_path, model, inp)
    with pytest.raises(InputError) as info:
        read_fibrenet(path)
    message = str(info.value)
    assert where in message and what in message, message


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fibrelmp.cli", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def test_cli_bad_input_exit_2_no_traceback_no_outputs(tmp_path):
    path = write_case(tmp_path, inp=INPUT + "dampnig 0.1\n")
    proc = _cli("run", str(path), cwd=tmp_path)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert proc.stderr.strip().splitlines()[-1].startswith("error: ")
    assert "input.txt:19: unknown keyword 'dampnig' (did you mean 'damping'?)" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["input.txt", "model.txt"]


def test_cli_missing_file_and_directory(tmp_path):
    for target in (tmp_path / "nothing.txt", tmp_path):
        proc = _cli("check", str(target), cwd=tmp_path)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_cli_run_check_translate(tmp_path):
    path = write_case(tmp_path)
    check = _cli("check", str(path), cwd=tmp_path)
    assert check.returncode == 0, check.stderr
    assert "beads        3" in check.stdout and "springs      1" in check.stdout
    job = _cli("translate", str(path), "-o", str(tmp_path / "job"), cwd=tmp_path)
    assert job.returncode == 0 and (tmp_path / "job" / "in.lammps").exists()
    run = _cli("--quiet", "run", str(path), cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    for suffix in ("_coord.xyz", "_vel.xyz", "_force.xyz", "_restart.res"):
        assert (tmp_path / f"out{suffix}").exists()


def test_cli_lammps_failure_exit_1(tmp_path):
    # an absurd contact stiffness blows the system up: LAMMPS stops with "Lost atoms"
    inp = INPUT.replace("box_type finite", "box_type pbc").replace("pair hs A B 100", "pair hs A B 1e300")
    path = write_case(tmp_path, MODEL, inp)
    proc = _cli("run", str(path), cwd=tmp_path)
    assert proc.returncode == 1
    assert "Traceback" not in proc.stderr
    assert "in.lammps" in proc.stderr and "Lost atoms" in proc.stderr
    assert not any(p.suffix in (".xyz", ".res") for p in tmp_path.iterdir())


def test_version():
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "--version"], capture_output=True, text=True)
    assert proc.returncode == 0 and "fibrelmp" in proc.stdout and "LAMMPS 2025" in proc.stdout


def test_cli_run_with_relative_paths(tmp_path):
    """Outputs land next to a relative input path even though LAMMPS runs in the work folder."""
    (tmp_path / "case").mkdir()
    write_case(tmp_path / "case")
    proc = _cli("--quiet", "run", "case/input.txt", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "case" / "out_coord.xyz").exists()
    assert (tmp_path / "case" / "out_work" / "in.lammps").exists()
