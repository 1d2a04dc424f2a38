"""The Python API (docs/python.md): the documented example runs as it stands; the API raises
instead of exiting and gives back the signal handlers it borrowed."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

import numpy as np
import pytest

from .conftest import REPO, copy_example


def test_documented_example_runs(tmp_path):
    text = (REPO / "docs" / "python.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    for folder in ("examples/fibre_network", "examples/demdf"):
        copy_example(folder, tmp_path / folder)
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    out = res.stdout.splitlines()
    assert out[0] == str(["fibre_network_coord.xyz", "fibre_network_vel.xyz",
                          "fibre_network_force.xyz", "fibre_network_restart.res"])
    assert out[1].startswith("2000 ")
    assert out[2].startswith("refused:") and "--force" in out[2]
    assert out[3] == "7 ParaView files" and out[4] == "2 spheres"
    assert out[5] == "input        examples/demdf/head_on.json (demdf)" and out[6] == "in.lammps"


def test_run_returns_frames_raises_and_restores_signals(tmp_path):
    import fibrelmp
    from fibrelmp.translate.fibrenet.writer import read_xyz

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    result = fibrelmp.run(REPO / "examples" / "fibre_network" / "input.txt", out=tmp_path)
    assert {s: signal.getsignal(s) for s in before} == before
    frames = list(result.frames())
    xyz = read_xyz(tmp_path / "fibre_network_coord.xyz")
    assert [f.step for f in frames] == [f.step for f in xyz]
    # the dump holds the unrounded positions the xyz file prints with 5 decimals (wrapped)
    lo, hi = frames[-1].lo, frames[-1].hi
    x = frames[-1].vector("x", "y", "z")
    wrapped = lo + np.mod(x - lo, hi - lo)
    assert np.abs(wrapped - xyz[-1].values).max() <= 5.1e-6
    with pytest.raises(fibrelmp.InputError, match="exists already"):
        fibrelmp.run(REPO / "examples" / "fibre_network" / "input.txt", out=tmp_path)
    with pytest.raises(fibrelmp.InputError, match="not found"):
        fibrelmp.read(tmp_path / "missing.txt")


def test_lazy_import_is_light():
    code = "import sys, fibrelmp; print(any(m in sys.modules for m in ('lammps', 'jinja2', 'MDAnalysis')))"
    env = {k: v for k, v in os.environ.items()}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert res.stdout.strip() == "False", res.stderr
