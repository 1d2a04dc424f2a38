"""Outputs are replaced completely or not at all (issue 24): a ``--force`` rerun that fails
at the end leaves the earlier run's whole set of results as it was, and no staging files."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.formatbase import Replacement, place, replacing
from fibrelmp.post.vtk.frame import ViewerFrame
from fibrelmp.post.vtk.writer import VtkWriter

from .conftest import REPO

RUN = dict(step=1e-6, save_step=1e-3, also=["vtk"])


def _contents(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_force_rerun_failing_at_the_end_keeps_the_earlier_results(tmp_path):
    """A MUSEN scene run with --also vtk (res.mdem, res.pvd, frames), then a --force rerun with
    one more frame whose VTK frame path is a directory: the rerun fails when its files are
    renamed into place; the earlier .mdem, .pvd and frames are byte for byte as before."""
    scene = tmp_path / "SingelParticle.mdem"
    shutil.copy(REPO / "examples" / "musen" / "SingelParticle.mdem", scene)
    first = python_api.run(scene, end_time=2e-3, **RUN)
    result = tmp_path / "SingelParticle_result.mdem"
    assert result in first.outputs and tmp_path / "SingelParticle_result.pvd" in first.outputs
    before = _contents(tmp_path)
    # the rerun's first frame beyond the first run's (the first has cmusen's 4: 0, 1e-3, 2e-3
    # and 2.001e-3 s, its summed clock's last step; the rerun goes on to 4e-3 s)
    n = len([p for p in before if re.fullmatch(r"SingelParticle_result_\d{6}\.vtp", p)])
    blocked = f"SingelParticle_result_{n:06d}.vtp"
    (tmp_path / blocked).mkdir()
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", str(scene), "--force",
                           "--also", "vtk", "--end-time", "4e-3", "--step", "1e-6", "--save-step", "1e-3"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode != 0, proc.stderr
    assert blocked in proc.stderr and "Traceback" not in proc.stderr
    assert _contents(tmp_path) == before            # same files, same bytes: nothing replaced
    assert not [p for p in tmp_path.iterdir() if ".tmp" in p.name]   # no staging files left


def _frame(step: int, x: float) -> ViewerFrame:
    return ViewerFrame(step, float(step), np.array([1, 2]), np.full((2, 3), x), np.zeros(3),
                       np.eye(3), np.zeros(3, bool))


def test_a_writer_replaces_its_own_files_all_or_none(tmp_path):
    """Outside a run (post, convert) one writer's files: frame 0 is renamed over the earlier
    frame 0, then frame 1's path is a directory: the earlier frame 0 comes back."""
    base = tmp_path / "out"
    with VtkWriter(base) as writer:
        writer.add(_frame(0, 0.0))
    before = _contents(tmp_path)
    writer = VtkWriter(base)
    writer.add(_frame(0, 1.0))
    writer.add(_frame(1, 2.0))
    writer.prepare()
    order = [final.name for final, _ in writer._pending()]
    assert order.index("out_000000.vtp") < order.index("out_000001.vtp")
    (tmp_path / "out_000001.vtp").mkdir()
    with pytest.raises(InputError, match="out_000001.vtp: cannot write output"):
        writer.close()
    assert _contents(tmp_path) == before
    assert not [p for p in tmp_path.iterdir() if ".tmp" in p.name]


def test_replacing_undoes_every_writer_of_a_failed_run(tmp_path):
    """Two outputs renamed into place in one run, then the run fails: both earlier files
    are back, the new ones gone; on success the earlier files kept aside are removed."""
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old a")
    try:
        with replacing([tmp_path]):
            for final, text in ((a, "new a"), (b, "new b")):
                tmp = final.with_name(f".{final.name}.tmp")
                tmp.write_text(text)
                place(tmp, final)
            assert a.read_text() == "new a" and b.read_text() == "new b"
            raise RuntimeError("the run failed later")
    except RuntimeError:
        pass
    assert a.read_text() == "old a" and not b.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    journal = Replacement()
    tmp = tmp_path / ".a.txt.tmp"
    tmp.write_text("newer")
    journal.place(tmp, a)
    journal.keep()
    assert a.read_text() == "newer" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
