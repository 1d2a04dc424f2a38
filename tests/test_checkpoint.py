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
import pytest

from fibrelmp.translate.fibrenet.writer import read_xyz
from fibrelmp.post.lammps_dump.reader import iter_frames

from .conftest import REPO

EXAMPLE = REPO / "examples" / "fibre_network"
# long enough (~2 s: ~10 us per step) for SIGTERM to arrive between checkpoints
STEPS, FRAME_EVERY, CHECKPOINT_EVERY = 200000, 40000, 20000


def _long_example(folder) -> list[str]:
    """examples/fibre_network with STEPS steps; the CLI command that runs it."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "model.txt").write_bytes((EXAMPLE / "model.txt").read_bytes())
    lines = [ln for ln in (EXAMPLE / "input.txt").read_text().splitlines()
             if not ln.split() or ln.split()[0] not in ("run", "output_freq")]
    (folder / "input.txt").write_text("\n".join(lines + [f"run\t{STEPS}", f"output_freq\t{FRAME_EVERY}"]) + "\n")
    return [sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", str(folder / "input.txt")]


def test_sigterm_then_resume_equals_uninterrupted(tmp_path):
    cli = _long_example(tmp_path / "in")
    whole = subprocess.run(cli + ["--out", str(tmp_path / "whole")], capture_output=True, text=True)
    assert whole.returncode == 0, whole.stderr

    out = tmp_path / "cut"
    state = out / "fibre_network_work" / "checkpoint.json"
    proc = subprocess.Popen(cli + ["--out", str(out), "--checkpoint-every", str(CHECKPOINT_EVERY)],
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
    assert 0 < stopped_at < STEPS
    assert not list(out.glob("*.xyz")), "a stopped run must not leave partial outputs"
    before = {f.step: f for f in iter_frames(out / "fibre_network_work" / "frames.dump")
              if f.step <= stopped_at}

    again = subprocess.run(cli + ["--out", str(out), "--resume"], capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert not state.exists(), "a finished run removes its checkpoint"

    full = list(iter_frames(tmp_path / "whole" / "fibre_network_work" / "frames.dump"))
    resumed = list(iter_frames(out / "fibre_network_work" / "frames.dump"))
    assert [f.step for f in resumed] == [f.step for f in full] == list(range(0, STEPS + 1, FRAME_EVERY))

    def unwrapped(f):     # LAMMPS wraps atoms at re-neighbouring, which a resumed run does at other steps
        return f.vector("x", "y", "z") + f.vector("ix", "iy", "iz") * (f.hi - f.lo)

    for a, b in zip(resumed, full):
        np.testing.assert_array_equal(a.column("id"), b.column("id"))
        assert np.abs(unwrapped(a) - unwrapped(b)).max() < 1e-6
        assert np.abs(a.vector("vx", "vy", "vz")
                      - b.vector("vx", "vy", "vz")).max() < 1e-4
        if a.step <= stopped_at:          # frames written before the checkpoint are kept as they were
            np.testing.assert_array_equal(a.vector("x", "y", "z"), before[a.step].vector("x", "y", "z"))
    for kind in ("coord", "vel", "force"):
        ours = read_xyz(out / f"fibre_network_{kind}.xyz")
        ref = read_xyz(tmp_path / "whole" / f"fibre_network_{kind}.xyz")
        assert [f.step for f in ours] == [f.step for f in ref]
        for a, b in zip(ours, ref):
            assert np.abs(a.values - b.values).max() <= (1.1e-5 if kind != "force" else 1e-3)


def test_resume_without_checkpoint_is_an_input_error(tmp_path):
    cli = _long_example(tmp_path / "in")
    done = subprocess.run(cli + ["--out", str(tmp_path), "--resume"], capture_output=True, text=True)
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


# A sphere hitting MUSEN's Plate (0.05 m/s) while the plate turns about z (7 rad/s): a frame every
# 5 steps of the 50-step contact (damping, friction) with a rotating wall.
ROTATING_PLATE_JOB = """\
JOB
SOURCE_FILE          scene.txt
RESULT_FILE          init.mdem
COMPONENT            IMPORT_FROM_TEXT
JOB
SOURCE_FILE          init.mdem
RESULT_FILE          result.mdem
COMPONENT            SIMULATOR
SIMULATOR_TYPE       CPU
MODEL_PP             ModelPPHertzMindlin
MODEL_PW             ModelPWHertzMindlin
SIMULATION_STEP      1e-7
SAVING_STEP          5e-7
END_TIME             5e-6
EXT_ACCEL            0 0 -9.81
GEOMETRY_MOTION_TIME Plate 0 1 0 0 0 0 0 7 0 0 0
JOB
SOURCE_FILE          result.mdem
RESULT_FILE          ./result.txt
COMPONENT            EXPORT_TO_TEXT
TEXT_EXPORT_PRECISION 17
"""

# Runs the CLI once per argument list in one process (one interpreter start-up) and prints
# their exit codes; a run given a K stops (as on SIGTERM) when its K-th run command asks
# whether to stop, deterministically.
_RUNS = """\
import json, signal, sys
from fibrelmp import checkpoint
from fibrelmp.cli import main
asked = checkpoint.Checkpointing.stop_requested
codes = []
for args, k in {runs!r}:
    calls = [0]
    def stop_requested(self, size, calls=calls, k=k):
        calls[0] += 1
        return signal.SIGTERM if calls[0] == k else asked(self, size)
    checkpoint.Checkpointing.stop_requested = stop_requested
    sys.argv = ["fibrelmp"] + args
    try:
        main()
        codes.append(0)
    except SystemExit as exc:
        codes.append(exc.code or 0)
print(json.dumps(codes))
"""


def _rotating_plate(folder):
    folder.mkdir(parents=True)
    scene = (REPO / "examples" / "musen" / "SingelParticle_text.txt").read_text()
    scene = scene.replace("12 0 0 0.005 15 0 0 -0.5", "12 0.002 0.001 -0.0005 15 0 0 -0.05")
    (folder / "scene.txt").write_text(scene)
    (folder / "job.txt").write_text(ROTATING_PLATE_JOB)
    return folder / "job.txt"


def _result_files(out):
    named = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    forces = out / "job_work" / "job2" / "wall_forces.dump"      # fix musen/wall/mesh only
    if forces.exists():
        named["wall_forces.dump"] = forces.read_bytes()
    return named


@pytest.mark.parametrize("styles", [[], ["--stock-styles"]], ids=["mesh", "stock-region"])
def test_rotating_wall_checkpoints_give_identical_files(tmp_path, styles):
    """Was: a rotating plate's results changed with --checkpoint-every alone (wall forces up to
    2e-5 relative) and with a stop + --resume: a checkpoint was taken right after a run, and
    its "run 0" recomputed the wall forces (fix musen/wall/mesh's triangle forces, fix
    wall/gran/region's contact forces) with full-step velocities before the frame wrote them.
    Now a checkpoint is taken after the step's frame, before the next run, and every file (the
    17-digit text export, the .mdem, the triangle forces) is byte for byte the uninterrupted
    run's.  The stopped run checkpoints after every 5-step run up to the 6th: its first frames
    come from a run checkpointed at every frame, the later ones from the resumed run."""
    job = _rotating_plate(tmp_path / "in")
    run = ["--quiet", "run", str(job), *styles, "-o"]
    runs = [(run + [str(tmp_path / "whole")], 0),
            (run + [str(tmp_path / "cut"), "--checkpoint-every", "1"], 6),
            (run + [str(tmp_path / "cut"), "--resume"], 0)]
    done = subprocess.run([sys.executable, "-c", _RUNS.format(runs=runs)], capture_output=True,
                          text=True, timeout=300)
    assert json.loads(done.stdout.splitlines()[-1]) == [0, 128 + signal.SIGTERM, 0], done.stderr
    reference = _result_files(tmp_path / "whole")
    walls = [ln for ln in reference["result.txt"].decode().splitlines()
             if ln.split()[:1] == ["0"] and int(ln.split()[1]) < 12]        # the plate's triangles
    forces = np.array([[abs(float(part.split()[2])) for part in ln.split(" 20 ")[1:]] for ln in walls])
    # 12 saved times: cmusen's clock reaches END_TIME one step late and saves there too
    assert forces.shape == (12, 12) and (forces.sum(0) > 0).sum() >= 8, "no lasting wall contact"
    assert _result_files(tmp_path / "cut") == reference
