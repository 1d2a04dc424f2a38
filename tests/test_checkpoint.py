"""Checkpoints: a run killed with SIGTERM stops at a checkpoint; ``--resume`` finishes it with
the same frames as an uninterrupted run (no duplicates, no gaps).

The checkpoint keeps the step's forces and torques besides LAMMPS's restart file (drag and
contact damping were computed with half-step velocities, which write_restart does not keep),
so the resumed run continues as the uninterrupted one did; the %.17g dump differs only by
summation round-off (the neighbour lists are rebuilt).  The tolerances here are the earlier,
looser ones; tests/test_trust_runs.py asserts byte-identical result files.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import numpy as np

from fibrelmp.translate.fibrenet.writer import read_xyz
from fibrelmp.post.lammps_dump.reader import iter_frames

from .conftest import REPO

INPUT = REPO / "examples" / "fibre_network" / "input.txt"
CLI = [sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", str(INPUT)]


def test_sigterm_then_resume_equals_uninterrupted(tmp_path):
    whole = subprocess.run(CLI + ["--out", str(tmp_path / "whole")], capture_output=True, text=True)
    assert whole.returncode == 0, whole.stderr

    out = tmp_path / "cut"
    state = out / "fibre_network_work" / "checkpoint.json"
    proc = subprocess.Popen(CLI + ["--out", str(out), "--checkpoint-every", "200"],
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not state.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert state.exists(), "no checkpoint appeared"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "--resume" in err and "Traceback" not in err
    stopped_at = json.loads(state.read_text())["steps"]
    assert 0 < stopped_at < 2000
    assert not list(out.glob("*.xyz")), "a stopped run must not leave partial outputs"

    again = subprocess.run(CLI + ["--out", str(out), "--resume"], capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert not state.exists(), "a finished run removes its checkpoint"

    full = list(iter_frames(tmp_path / "whole" / "fibre_network_work" / "frames.dump"))
    resumed = list(iter_frames(out / "fibre_network_work" / "frames.dump"))
    assert [f.step for f in resumed] == [f.step for f in full] == list(range(0, 2001, 400))
    for a, b in zip(resumed, full):
        np.testing.assert_array_equal(a.column("id"), b.column("id"))
        assert np.abs(a.vector("x", "y", "z") - b.vector("x", "y", "z")).max() < 1e-6
        assert np.abs(a.vector("v_fn_vx", "v_fn_vy", "v_fn_vz")
                      - b.vector("v_fn_vx", "v_fn_vy", "v_fn_vz")).max() < 1e-4
        if a.step <= stopped_at:          # frames written before the checkpoint are kept as they were
            np.testing.assert_array_equal(a.vector("x", "y", "z"), b.vector("x", "y", "z"))
    for kind in ("coord", "vel", "force"):
        ours = read_xyz(out / f"fibre_network_{kind}.xyz")
        ref = read_xyz(tmp_path / "whole" / f"fibre_network_{kind}.xyz")
        assert [f.step for f in ours] == [f.step for f in ref]
        for a, b in zip(ours, ref):
            assert np.abs(a.values - b.values).max() <= (1.1e-5 if kind != "force" else 1e-3)


def test_resume_without_checkpoint_is_an_input_error(tmp_path):
    done = subprocess.run(CLI + ["--out", str(tmp_path), "--resume"], capture_output=True, text=True)
    assert done.returncode == 2
    assert "no checkpoint to resume from" in done.stderr and "Traceback" not in done.stderr


def test_musen_script_sigterm_then_resume(tmp_path):
    """The same for a cmusen script (agglomerate, 2,000 steps): the resumed result has every
    saved time once and agrees with the uninterrupted one to the 6-digit export (positions),
    within 1e-4 m/s in velocity (the damped contacts restart with full-step velocities)."""
    from fibrelmp.translate.musen.scene import read_time_points

    src = REPO / "examples" / "musen"
    job = (src / "agglomerate_short_job.txt").read_text()
    job = "\n".join("END_TIME             2e-5" if ln.startswith("END_TIME") else
                    "SAVING_STEP          5e-6" if ln.startswith("SAVING_STEP") else ln
                    for ln in job.splitlines()) + "\n"
    runs = {}
    for name in ("whole", "cut"):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "job.txt").write_text(job)
        (folder / "SphericalAgglomerate_text.txt").symlink_to(src / "SphericalAgglomerate_text.txt")
        runs[name] = folder
    cli = [sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", "job.txt"]
    assert subprocess.run(cli, cwd=runs["whole"], capture_output=True).returncode == 0

    state = runs["cut"] / "job_work" / "job2" / "checkpoint.json"
    proc = subprocess.Popen(cli + ["--checkpoint-every", "400"], cwd=runs["cut"],
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not state.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert state.exists(), "no checkpoint appeared"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert not (runs["cut"] / "agglomerate_short_result.txt").exists()
    again = subprocess.run(cli + ["--resume"], cwd=runs["cut"], capture_output=True, text=True)
    assert again.returncode == 0, again.stderr

    a = read_time_points(runs["cut"] / "agglomerate_short_result.txt", tags=(12, 15))
    b = read_time_points(runs["whole"] / "agglomerate_short_result.txt", tags=(12, 15))
    np.testing.assert_array_equal(a.ids, b.ids)
    np.testing.assert_allclose(a.times, b.times, rtol=0, atol=1e-15)
    assert len(a.times) == 5
    assert np.nanmax(np.abs(a.fields[12] - b.fields[12])) <= 1.01e-8
    assert np.nanmax(np.abs(a.fields[15] - b.fields[15])) < 1e-4
