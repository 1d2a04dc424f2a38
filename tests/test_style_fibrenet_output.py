"""``fix fibrenet/output`` (fibrelmp's plugin) writes FibreNet's files byte for byte as
fibrelmp's Python converter writes them from the same frames.

The reference is always the converter (``translate.fibrenet.target.convert_frames`` /
``translate.fibrenet.target.write_fibrenet``) run on the %.17g dump the job writes next to the fix's
files: the same frames, so any byte that differs is the fix's, whatever the physics styles.
Covered: the five real FibreNet cases (and the restart case's first run), synthetic models
(beads crossing periodic faces between neighbour-list rebuilds, several LAMMPS types per
FibreNet type, output_type and output_data subsets, resets, lambda != 1/2, beads pressed into
walls), edge values of the number formats (ties, -0.0, 1e300, inf, nan), FibreNet's restart
rewrite schedule, two MPI ranks, ``translate`` + ``lmp -in``, checkpoint/resume and write
failures (every rank stops with the message, no half frame is left).
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles
from tests.conftest import styles_or_skip
from tests.test_mpi import MPIEXEC
from fibrelmp._lammps import new_lammps
from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.translate.fibrenet.target import OUTSIDE_KIND, convert_frames, write_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.translate.fibrenet.writer import RESTART_SUFFIX, XYZ_SUFFIX

from . import fibrenet_reference as ref
from .conftest import data_path

BIN = Path(sys.executable).parent
CLI = [sys.executable, "-m", "fibrelmp.cli"]
SUFFIXES = [*XYZ_SUFFIX.values(), RESTART_SUFFIX]
CASES = ["network_pbc_hs", "lambda_07_damped", "st_pairs_network", "lj_two_types_minimize",
         "restart_continue", "restart_continue/first_run"]


@pytest.fixture(scope="module")
def plugin() -> Path:
    return styles_or_skip()


def _env() -> dict[str, str]:
    """Subprocesses import this checkout of fibrelmp, whatever their working folder."""
    root = str(Path(__file__).resolve().parents[1])
    return dict(os.environ, OMP_NUM_THREADS="1",
                PYTHONPATH=os.pathsep.join([root, os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))


def _files(folder: Path, prefix: str) -> dict[str, bytes]:
    return {s: (folder / f"{prefix}{s}").read_bytes() for s in SUFFIXES
            if (folder / f"{prefix}{s}").exists()}


def _converted(input_path: Path, job, out: Path) -> tuple[dict[str, bytes], list]:
    """The converter's files (and its warnings) from the dump ``job`` wrote."""
    model = read_fibrenet(input_path)
    said = len(model.warnings)
    prefix = Path(model.plan.output.basename).name
    out.mkdir(parents=True, exist_ok=True)
    convert_frames(model, job, iter_frames(job.frames), out, prefix)
    return _files(out, prefix), model.warnings[said:]


def _run_and_compare(input_path: Path, tmp_path: Path) -> tuple[dict[str, bytes], list]:
    """fibrelmp run (the fix writes, the pipeline moves) vs the converter on the run's dump."""
    model = read_fibrenet(input_path)
    said = len(model.warnings)
    prefix = Path(model.plan.output.basename).name
    run = run_fibrenet(model, out=tmp_path / "run", progress=False)
    job = run.job
    assert job.native is not None, "the plugin is loaded, so the job writes FibreNet's files"
    script = job.script.read_text()
    # the fix writes the work dump too (frames.dump): no write_dump in the script
    assert "fibrenet/output" in script and script.count("fibrenet/frame") > 0 and "write_dump" not in script
    # the pipeline moved the fix's files into place: none is left behind, no temp file either
    assert not [p.name for p in job.folder.iterdir() if p.suffix in (".xyz", ".res") or ".tmp" in p.name]
    ours = _files(tmp_path / "run", prefix)
    assert [p.name for p in run.outputs] == [f"{prefix}{XYZ_SUFFIX[f]}" for f in model.plan.output.fields] \
        + [f"{prefix}{RESTART_SUFFIX}"]
    theirs, warned = _converted(input_path, job, tmp_path / "converted")
    assert sorted(ours) == sorted(theirs)
    for suffix in ours:
        assert ours[suffix] == theirs[suffix], f"{prefix}{suffix} differs from the converter's"
    assert [w for w in model.warnings[said:] if w[0] == OUTSIDE_KIND] == \
        [w for w in warned if w[0] == OUTSIDE_KIND]
    return ours, model.warnings[said:]


# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("case", CASES)
def test_real_fibrenet_cases_byte_identical(case, tmp_path, plugin):
    folder = data_path("real-outputs", "fibrenet", case)
    ours, _ = _run_and_compare(folder / "input.txt", tmp_path)
    assert len(ours) == 4
    # the same frames as FibreNet's own files (values: tests/test_fibrenet_real_outputs.py)
    base = read_fibrenet(folder / "input.txt").plan.output.basename
    for suffix, text in ours.items():
        real = (folder / f"{base}{suffix}").read_text()
        assert [ln.split("\t")[1] for ln in text.decode().splitlines() if ln.startswith("FRAME")] == \
            [ln.split("\t")[1] for ln in real.splitlines() if ln.startswith("FRAME")]


def _crossing_net() -> ref.Net:
    """Periodic box; beads fast enough to cross faces (image flags change); type P split into
    two LAMMPS types by mass; a spring across the x face."""
    net = ref.Net((6.0, 5.0, 7.0), periodic=True, cutoff=1.0, dt=2e-3, damping=0.1)
    net.type("P", "Q")
    net.pair("hs", "P", "P", 200.0)
    net.pair("hs", "Q", "Q", 200.0)
    net.pair("hs", "P", "Q", 300.0)
    rng = np.random.default_rng(11)
    for k in range(10):
        x = rng.uniform(0.3, [5.7, 4.7, 6.7])
        net.bead("P" if k % 3 else "Q", x, tag=k, R=0.25, m=1.0 + (k % 2),
                 v=rng.normal(0, 8.0, 3), xu=x + [6.0 * (k % 2), -5.0 * (k == 3), 0.0])
    first = net.bead("P", (5.8, 2.5, 3.0), tag=20, R=0.2)
    net.bead("P", (0.2, 2.5, 3.0), tag=20, R=0.2, xu=(6.2, 2.5, 3.0))     # across the x face
    net.spring(first, first + 1, 0.4, 500.0, tag=20)
    net.modif_bead("tag", 4, "velocity", 40.0, -35.0, 12.0)
    return net


def test_periodic_crossings_type_split_and_output_subsets(tmp_path, plugin):
    net = _crossing_net()
    path = net.write(tmp_path / "case", name="cross", run=250, output_freq=100)
    text = path.read_text().replace("output_data\tall", "output_data\tposition\noutput_data\tforce") \
        .replace("output_type\tall", "output_type\tP")
    path.write_text(text)
    model = read_fibrenet(path)
    assert model.plan.output.fields == ("position", "force") and model.plan.output.types is not None
    ours, _ = _run_and_compare(path, tmp_path)
    assert sorted(ours) == ["_coord.xyz", "_force.xyz", "_restart.res"]
    frames = [ln for ln in ours["_coord.xyz"].decode().splitlines() if ln.startswith("FRAME")]
    assert [f.split("\t")[1] for f in frames] == ["0", "100", "200", "250"]
    # image flags changed during the run (beads crossed faces); atoms outside [lo, hi) between
    # rebuilds: test_edge_values_and_wrapping_match_the_converter
    job = tmp_path / "run" / "cross_work" / "frames.dump"
    images = [f.vector("ix", "iy", "iz") for f in iter_frames(job)]
    assert any((img != images[0]).any() for img in images[1:])


def test_resets_lambda_damping_and_beads_in_the_walls(tmp_path, plugin):
    """Relax chunks with velocity resets (state frames), lambda 0.7 with drag and gravity in a
    finite box, a bead pressed into a wall: the wall warning is the converter's too."""
    net = ref.Net((5.0, 4.0, 6.0), wall_k=800.0, cutoff=1.0, dt=1e-3, lam=0.7, damping=1.5,
                  gravity=(0.0, 0.2, -3.0))
    net.type("W", "V")
    net.pair("hs", "W", "W", 100.0)
    net.pair("hs", "V", "V", 100.0)
    net.pair("hs", "W", "V", 150.0)
    beads = [net.bead("W", (1.0 + 0.45 * k, 2.0, 3.0), tag=1, R=0.2) for k in range(5)]
    for a, b in zip(beads, beads[1:]):
        net.spring(a, b, 0.45, 900.0, tag=1)
    for a, b, c in zip(beads, beads[1:], beads[2:]):
        net.angle(a, b, c, 3.0, 20.0)
    net.bead("V", (0.15, 1.0, 1.0), tag=2, R=0.2, m=0.0, v=(0.3, 0.0, 0.0))      # mass 0: moves
    # gravity presses this one into the floor: its centre sinks below z = 0 (k 800, g 3)
    net.bead("V", (4.7, 3.0, 0.003), tag=3, R=0.2, f=(2.0, -1.0, 0.015625))
    net.modif_bead("tag", 3, "velocity", 30.0, 0.0, -4.0)          # erased by the resets
    path = net.write(tmp_path / "case", name="walls", run=300, output_freq=75, minimize_steps=100,
                     minimize_substeps=50, minimize_reset=True)
    _, warnings = _run_and_compare(path, tmp_path)
    assert any(kind == OUTSIDE_KIND for kind, _ in warnings), warnings


# ------------------------------------------------------------------------------------------
# the fix directly: edge values of the formats, wrapping with lo != 0, failures
EDGE_VALUES = ["0.015625", "0.046875", "-0.0", "-1e-9", "1e300", "1e20", "123456.789", "-2.5e-7",
               "0.1", "5e-6", "9.999995", "3e300", "-7e299", "2.5", "-0.000005", "0.000015"]
# the work dump as fibrelmp's script wrote it before the fix wrote it (lammps_job.DUMP_NAMES)
FRAME = ("write_dump all custom frames.dump id type x y z ix iy iz v_fn_vx v_fn_vy v_fn_vz "
         "v_fn_fx v_fn_fy v_fn_fz v_fn_radius v_fn_mass modify sort id format float %.17g time yes "
         "colname v_fn_vx vx colname v_fn_vy vy colname v_fn_vz vz colname v_fn_fx fx colname v_fn_fy fy "
         "colname v_fn_fz fz colname v_fn_radius radius colname v_fn_mass mass")


def _edge_setup(plugin: Path, n: int = 12) -> list[str]:
    """Atoms of 3 types in a box with lo != 0, periodic in x and y, shrink-wrapped in z;
    velocities/forces written are variables of per-atom values chosen to hit every branch of
    %.5f / %g: ties (1/64), -0.0, huge (the printf path), inf, -inf and nan (inf - inf: on
    x86 a NaN with the sign bit set, which printf writes "-nan" and Python "nan")."""
    rng = np.random.default_rng(1)
    cmds = [f"plugin load {plugin}", "units lj", "atom_style atomic", "boundary p p m",
            "region b block -2.5 7.5 0 10 0 10", "create_box 3 b", "mass * 1.0"]
    for i in range(n):
        x = rng.uniform([-2.5, 0, 0.5], [7.5, 10, 9.5])
        cmds.append(f"create_atoms {i % 3 + 1} single {float(x[0])!r} {float(x[1])!r} {float(x[2])!r}")
    cmds += ["create_atoms 2 single 1.0 1.0 9.9",              # leaves FibreNet's [0, 10) in z
             "fix p all property/atom d_a d_b d_c d_e d_f d_g",
             "set atom 2 image 2 -1 0", "set atom 5 image -3 0 0",
             "velocity all set 3.0 -2.0 0.5", "set atom 7 vx 400.0", f"set atom {n + 1} vz 30.0",
             "neigh_modify every 1000 delay 0 check no",       # no re-wrapping by LAMMPS
             "pair_style zero 1.0", "pair_coeff * *", "timestep 0.001", "fix nve all nve",
             "thermo_modify lost ignore", "run 10"]
    for i in range(1, n + 2):
        for k, name in enumerate("abcefg"):
            cmds.append(f"set atom {i} d_{name} {EDGE_VALUES[(i * 6 + k) % len(EDGE_VALUES)]}")
    cmds += ["set atom 1 d_a 0.015625", "set atom 3 d_e 0.046875"]     # exact ties, rows kept
    cmds += ["variable fn_vx atom d_a", "variable fn_vy atom (d_b*1e9)-(d_b*1e9)+d_b",
             "variable fn_vz atom -d_c*1e9", "variable fn_fx atom d_e", "variable fn_fy atom d_f*2",
             "variable fn_fz atom d_g", "variable fn_radius atom 0.25*type+d_b",
             "variable fn_mass atom mass*d_f/7",
             "fix out all fibrenet/output edge dt 0.001 box 10 10 10 names A B C files coord vel "
             "force only 1 3 velocity v_fn_vx v_fn_vy v_fn_vz force v_fn_fx v_fn_fy v_fn_fz restart 20 "
             "dump fix_frames.dump radius v_fn_radius mass v_fn_mass"]
    return cmds


def _lammps(folder: Path):
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    cwd = os.getcwd()
    os.chdir(folder)
    return lmp, cwd


def test_edge_values_and_wrapping_match_the_converter(tmp_path, plugin):
    lmp, cwd = _lammps(tmp_path)
    try:
        for cmd in _edge_setup(plugin) + [FRAME, "fibrenet/frame out", "run 10",
                                          FRAME + " append yes", "fibrenet/frame out"]:
            lmp.command(cmd)
        outside = [lmp.extract_fix("out", 0, 1, k) for k in (0, 1)]
        nonfinite = lmp.extract_fix("out", 0, 1, 2)
    finally:
        lmp.close()
        os.chdir(cwd)
    got: list = []
    write_fibrenet(iter_frames(tmp_path / "frames.dump"), "conv", tmp_path, tuple(XYZ_SUFFIX),
                   {1: "A", 2: "B", 3: "C"}, 0.001, np.full(3, 10.0), {"A", "C"},
                   warn=lambda kind, text: got.append((kind, text)))
    for suffix in SUFFIXES:
        assert (tmp_path / f"edge{suffix}").read_bytes() == (tmp_path / f"conv{suffix}").read_bytes(), suffix
    dump = (tmp_path / "frames.dump").read_text()
    assert "-nan" in dump and "inf" in dump           # the dump had them; the files say "nan"
    # the fix's work dump: write_dump's bytes (header, order, %.17g of every edge value), both frames
    assert (tmp_path / "fix_frames.dump").read_bytes() == (tmp_path / "frames.dump").read_bytes()
    assert dump.count("ITEM: TIME\n") == 2 and "ITEM: BOX BOUNDS pp pp mm" in dump
    text = "".join((tmp_path / f"edge{suffix}").read_text() for suffix in SUFFIXES)
    # f_out[3]: the nan/inf values in the files (the run's scan for their lines depends on it)
    values = [w for line in text.splitlines() if not line.startswith("FRAME")      # xyz rows "name\tx..",
              for w in line.lstrip("\t").split("\t")[1:]]                            # restart rows "\tname\tx.." 
    assert nonfinite == sum(not np.isfinite(float(w)) for w in values) > 0
    assert "\tnan" in text and "-nan" not in text and "inf" in text and "-0.00000" in text
    # x 1e5 = 1562.5 and 4687.5 exactly: printf rounds ties to even
    assert (tmp_path / "edge_vel.xyz").read_text().splitlines()[2].split("\t")[1] == "0.01562"
    assert "\tC\t0.04688\t" in "\t" + (tmp_path / "edge_force.xyz").read_text().replace("\n", "\t")
    assert outside == [10.0, 1.0] and len(got) == 1 and "step 10" in got[0][1]
    frames = list(iter_frames(tmp_path / "frames.dump"))
    x, lo, hi = frames[-1].vector("x", "y", "z"), frames[-1].lo, frames[-1].hi
    assert ((x[:, 0] < lo[0]) | (x[:, 0] >= hi[0])).any(), "no atom outside [lo, hi) in x to wrap"


def test_restart_file_rewritten_where_fibrenet_rewrites_it(tmp_path, plugin):
    """FibreNet (SimulationManager::DumpData) rewrites _restart.res at the first frame whose
    progress fraction, computed in float, exceeds 0.25 (then 0.5, 0.75, one stage per frame),
    and after the last step.  Seen after every frame of the running job."""
    from fibrelmp.runner import run_script
    from fibrelmp.translate.lammps_job import write_job

    def expected(run: int, frames: list[int]) -> list[int | None]:
        stage, last, seen = np.float32(0.25), None, []
        for p in frames:
            if np.float32(p) / np.float32(run) > stage:
                stage += np.float32(0.25)
                last = p
            if p == run:
                last = p
            seen.append(last)
        return seen

    net = ref.Net((5.0, 5.0, 5.0), cutoff=1.0)
    net.type("A")
    net.pair("hs", "A", "A", 100.0)
    net.bead("A", (1.0, 1.0, 1.0), tag=1, R=0.2, v=(0.1, 0.0, 0.0))
    net.bead("A", (3.0, 3.0, 3.0), tag=2, R=0.2)
    for run, every in [(1000, 100), (1000, 600), (700, 300), (8, 1)]:
        path = net.write(tmp_path / f"r{run}_{every}", name="st", run=run, output_freq=every)
        job = write_job(read_fibrenet(path), path.parent / "job")
        res = job.folder / "st_restart.res"
        seen: list[int | None] = []

        def hook(words: list[str]) -> None:
            if words[0] == "fibrenet/frame":
                seen.append(int(res.read_text().splitlines()[1].split("\t")[1]) if res.exists() else None)

        run_script(job.script, job.total_steps, progress=False, on_command=hook)
        frames = list(job.output_steps)
        assert seen == expected(run, frames), (run, every, frames)
        assert seen[-1] == run


def test_failed_write_stops_with_the_message_and_leaves_no_half_frame(tmp_path, plugin):
    lmp, cwd = _lammps(tmp_path)
    try:
        for cmd in _edge_setup(plugin) + [FRAME, "fibrenet/frame out", "run 10"]:
            lmp.command(cmd)
        coord = (tmp_path / "edge_coord.xyz").read_bytes()
        (tmp_path / "edge_vel.xyz").unlink()
        (tmp_path / "edge_vel.xyz").symlink_to("/dev/full")        # every write: ENOSPC
        with pytest.raises(Exception, match=r"cannot write edge_vel\.xyz: No space left on device"):
            lmp.command("fibrenet/frame out")
        # coord was written first, then cut back: no half frame in any file
        assert (tmp_path / "edge_coord.xyz").read_bytes() == coord
    finally:
        lmp.close()
        os.chdir(cwd)


def test_bad_arguments_are_lammps_errors(tmp_path, plugin):
    lmp, cwd = _lammps(tmp_path)
    base = "fix out all fibrenet/output p dt 0.1 box 1 1 1 velocity v_a v_b v_c force v_a v_b v_c restart 5"
    try:
        for cmd in _edge_setup(plugin)[:-1]:
            lmp.command(cmd)
        for bad, message in [(base + " names A B", "keyword names needs 3 value"),
                             (base.replace("box 1 1 1 ", ""), "needs dt, box, names"),
                             (base + " names A B C only 4", "only 4: atom types are 1 to 3"),
                             (base.replace("v_a v_b v_c force", "vx vy vz force") + " names A B C",
                              "three atom-style variables"),
                             (base + " names A B C colour red", "unknown keyword colour"),
                             ("fibrenet/frame p", "not the ID of a fix fibrenet/output")]:
            with pytest.raises(Exception, match=message):
                lmp.command(bad)
        lmp.command(base + " names A B C")
        lmp.command("variable a atom 1")
        lmp.command("variable b equal 2")
        with pytest.raises(Exception, match="variable b is not atom-style"):
            lmp.command("fibrenet/frame out")
    finally:
        lmp.close()
        os.chdir(cwd)


# ------------------------------------------------------------------------------------------
def test_translate_then_lmp_writes_the_files_of_fibrelmp_run(tmp_path, plugin):
    from fibrelmp._lammps import lmp_executable_env
    from fibrelmp.python_api import write_job

    src = data_path("real-outputs", "fibrenet", "lambda_07_damped", "input.txt")
    run = run_fibrenet(read_fibrenet(src), out=tmp_path / "run", progress=False)
    job = write_job(src, tmp_path / "job")
    assert job.text == run.job.text
    lmp = [str(BIN / "lmp")] if (BIN / "lmp").exists() else \
        [sys.executable, "-c", "import sys; from lammps.executable import lmp; sys.argv[0]='lmp'; sys.exit(lmp())"]
    proc = subprocess.run(lmp + ["-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=job.folder, env=lmp_executable_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert _files(job.folder, "lambda_07_damped") == _files(tmp_path / "run", "lambda_07_damped")
    assert len(_files(job.folder, "lambda_07_damped")) == 4


def test_resume_cuts_the_fix_files_back_to_the_checkpoint(tmp_path, plugin, monkeypatch):
    """A run stopped at a checkpoint, whose xyz files then got bytes a killed run would have
    appended after it, resumes to the uninterrupted run's files byte for byte."""
    from fibrelmp.checkpoint import STATE, CheckpointStop, Checkpointing

    src = data_path("real-outputs", "fibrenet", "network_pbc_hs", "input.txt")
    whole = run_fibrenet(read_fibrenet(src), out=tmp_path / "whole", progress=False)
    calls = {"n": 0}

    def stop_on_the_3rd(self, size):
        calls["n"] += 1
        return signal.SIGTERM if calls["n"] == 3 else 0

    monkeypatch.setattr(Checkpointing, "stop_requested", stop_on_the_3rd)
    with pytest.raises(CheckpointStop):
        run_fibrenet(read_fibrenet(src), out=tmp_path / "cut", progress=False, checkpoint_every=100)
    monkeypatch.undo()
    work = tmp_path / "cut" / "network_pbc_hs_work"
    import json

    sizes = json.loads((work / STATE).read_text())["sizes"]
    assert {f"network_pbc_hs{s}" for s in XYZ_SUFFIX.values()} <= set(sizes)
    for s in XYZ_SUFFIX.values():
        with open(work / f"network_pbc_hs{s}", "ab") as fh:
            fh.write(b"119\nFRAME\t999\tleft by a killed run\n")
    assert not list((tmp_path / "cut").glob("*.xyz"))
    run_fibrenet(read_fibrenet(src), out=tmp_path / "cut", progress=False, resume=True)
    ours = _files(tmp_path / "cut", "network_pbc_hs")
    assert len(ours) == 4 and ours == _files(tmp_path / "whole", "network_pbc_hs")
    assert whole.job.native is not None


# ------------------------------------------------------------------------------------------
needs_mpi = pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found (pip install mpich)")


def _case(folder: Path, name: str = "network_pbc_hs") -> Path:
    src = data_path("real-outputs", "fibrenet", name)
    folder.mkdir(parents=True)
    for f in ("input.txt", "model.txt"):
        shutil.copy(src / f, folder)
    return folder / "input.txt"


@needs_mpi
def test_two_ranks_rank0_writes_the_converters_bytes(tmp_path, plugin):
    inp = _case(tmp_path / "case")
    proc = subprocess.run([MPIEXEC, "-n", "2"] + CLI + ["-q", "run", "input.txt"], cwd=inp.parent,
                          env=_env(), capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    from fibrelmp.translate.lammps_job import write_job

    model = read_fibrenet(inp)
    job = write_job(model, tmp_path / "rendered")          # the job's type table and dump name
    job.frames = inp.parent / "network_pbc_hs_work" / "frames.dump"
    theirs, _ = _converted(inp, job, tmp_path / "converted")
    ours = _files(inp.parent, "network_pbc_hs")
    assert len(ours) == 4 and ours == theirs
    work = inp.parent / "network_pbc_hs_work"
    assert not [p.name for p in inp.parent.rglob("*") if ".tmp" in p.name]
    assert not [p.name for p in work.iterdir() if p.suffix in (".xyz", ".res")]     # moved
    # the frames came from both ranks: the script splits the box, and every bead is written
    assert ours["_coord.xyz"].decode().splitlines()[0] == "119"


@needs_mpi
def test_a_failed_write_under_two_ranks_ends_both_with_the_message(tmp_path, plugin):
    inp = _case(tmp_path / "case", "lambda_07_damped")
    blocker = inp.parent / "lambda_07_damped_work" / "lambda_07_damped_restart.res"
    (blocker / "keep").mkdir(parents=True)                  # the restart cannot be renamed there
    proc = subprocess.run([MPIEXEC, "-n", "2"] + CLI + ["-q", "run", "input.txt"], cwd=inp.parent,
                          env=_env(), capture_output=True, text=True, timeout=60)
    assert proc.returncode != 0
    assert "cannot write lambda_07_damped_restart.res" in proc.stderr, proc.stderr
    assert not list(inp.parent.glob("lambda_07_damped_*.xyz")), "no result after a failed run"


@needs_mpi
def test_frames_formatted_in_chunks_by_three_ranks_are_the_serial_bytes(tmp_path, plugin):
    """Chunks of 2 rows: every rank formats chunks of every frame and rank 0 writes them in
    order.  The files equal the serial run's and the dump write_dump's, byte for byte; a
    write failing in the middle of a frame (ENOSPC on the vel file) ends all three ranks with
    the message and cuts every file back to the frame before (rank 0 still takes every chunk)."""
    cmds = _edge_setup(plugin)
    frames = [FRAME, "fibrenet/frame out", "run 10", FRAME + " append yes", "fibrenet/frame out"]
    lmp_exe = [str(BIN / "lmp")] if (BIN / "lmp").exists() else \
        [sys.executable, "-c", "import sys; from lammps.executable import lmp; sys.argv[0]='lmp'; sys.exit(lmp())"]
    from fibrelmp._lammps import lmp_executable_env

    def run(folder: Path, ranks: int, chunk: str, after: list[str] = ()) -> subprocess.CompletedProcess:
        folder.mkdir()
        (folder / "in.edge").write_text("\n".join(cmds[:-1] + [cmds[-1] + chunk] + frames + list(after)) + "\n")
        return subprocess.run([MPIEXEC, "-n", str(ranks)] + lmp_exe + ["-in", "in.edge", "-log", "none", "-nocite"],
                              cwd=folder, env=lmp_executable_env(), capture_output=True, text=True, timeout=120)

    serial = run(tmp_path / "serial", 1, "")
    assert serial.returncode == 0, serial.stdout + serial.stderr
    three = run(tmp_path / "three", 3, " chunk 2")
    assert three.returncode == 0, three.stdout + three.stderr
    names = [f"edge{s}" for s in SUFFIXES] + ["fix_frames.dump"]
    for name in names:
        assert (tmp_path / "three" / name).read_bytes() == (tmp_path / "serial" / name).read_bytes(), name
    assert (tmp_path / "three" / "fix_frames.dump").read_bytes() == (tmp_path / "three" / "frames.dump").read_bytes()

    broken = ["shell rm edge_vel.xyz", "shell ln -s /dev/full edge_vel.xyz", "run 10", "fibrenet/frame out"]
    failed = run(tmp_path / "failed", 3, " chunk 2", broken)
    assert failed.returncode != 0
    assert "cannot write edge_vel.xyz: No space left on device" in failed.stdout + failed.stderr
    for name in ("edge_coord.xyz", "edge_force.xyz", "fix_frames.dump"):
        assert (tmp_path / "failed" / name).read_bytes() == (tmp_path / "three" / name).read_bytes(), name


def test_names_lammps_cannot_take_verbatim_fall_back_to_the_converter(tmp_path, plugin):
    from fibrelmp.translate.lammps_job import NATIVE_KIND, write_job

    net = ref.Net((5.0, 5.0, 5.0), cutoff=1.0)
    net.type("A$1", "B")
    net.pair("hs", "A$1", "A$1", 100.0)
    net.pair("hs", "B", "B", 100.0)
    net.pair("hs", "A$1", "B", 100.0)
    net.bead("A$1", (1.0, 1.0, 1.0), tag=1, R=0.2)
    net.bead("B", (3.0, 3.0, 3.0), tag=2, R=0.2)
    path = net.write(tmp_path / "case", name="odd", run=20, output_freq=10)
    model = read_fibrenet(path)
    job = write_job(model, tmp_path / "job")
    assert job.native is None and "fibrenet/output" not in job.text and "fibrenet/frame" not in job.text
    assert any(kind == NATIVE_KIND and "'A$1'" in text for kind, text in model.warnings)
    run = run_fibrenet(read_fibrenet(path), out=tmp_path / "run", progress=False)
    assert run.job.native is None and len(_files(tmp_path / "run", "odd")) == 4
    assert "A$1\t" in (tmp_path / "run" / "odd_coord.xyz").read_text()
    with lammps_styles.stock():
        stock = write_job(read_fibrenet(path), tmp_path / "stock")
    assert stock.native is None and "plugin" not in stock.text
