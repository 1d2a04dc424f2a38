"""`fibrelmp post` keeps memory bounded by a frame (issue 28, goal 1): its peak resident memory,
measured in a child process with getrusage, must not grow with the number of frames in the dump."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.textio import format_rows

ATOMS = 10_000   # 0.78 MB a frame


def _write_dump(path: Path, frames: int) -> int:
    """A ``dump custom`` style text dump; returns the bytes of one frame."""
    rng = np.random.default_rng(3)
    ids = np.arange(1, ATOMS + 1)
    types = rng.integers(1, 4, ATOMS)
    with open(path, "w") as fh:
        for k in range(frames):
            a = rng.random((ATOMS, 9)) * 100.0
            fh.write(f"ITEM: TIMESTEP\n{k * 100}\nITEM: NUMBER OF ATOMS\n{ATOMS}\n"
                     "ITEM: BOX BOUNDS pp pp pp\n0 100\n0 100\n0 100\n"
                     "ITEM: ATOMS id type x y z vx vy vz fx fy fz\n")
            fh.write(format_rows("%d %d" + " %g" * 9 + "\n", [ids, types] + [a[:, c] for c in range(9)]))
    return path.stat().st_size // frames


_CHILD = """
import resource, sys
from fibrelmp.cli import main
try:
    sys.argv = ["fibrelmp", "-q", "post", sys.argv[1], "--to", "xyz", "-o", sys.argv[2]]
    main()
except SystemExit as exc:
    assert not exc.code, exc.code
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def _peak_rss_kb(dump: Path, out: Path, env: dict) -> int:
    # a fresh interpreter per run: its high-water mark is its own, not the test runner's
    done = subprocess.run([sys.executable, "-c", _CHILD, str(dump), str(out)], env=env,
                          capture_output=True, text=True, check=True)
    return int(done.stdout.split()[-1])


@pytest.mark.parametrize("no_c", ["", "1"], ids=["compiled", "numpy"])
def test_post_peak_memory_does_not_grow_with_frames(tmp_path: Path, no_c: str) -> None:
    env = dict(os.environ, FIBRELMP_NO_C=no_c)
    few, many = tmp_path / "few.dump", tmp_path / "many.dump"
    frame_bytes = _write_dump(few, 64)
    _write_dump(many, 128)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    rss_few = _peak_rss_kb(few, tmp_path / "a" / "net", env)
    rss_many = _peak_rss_kb(many, tmp_path / "b" / "net", env)
    # both dumps (50 and 100 MB) are past the reader's fixed cost (16 MB reads, a buffer of up
    # to two); 64 more frames would add ~50 MB of text (more as parsed arrays) if any were
    # kept; measured growth is < 1 frame, allowed four for allocator noise
    growth = (rss_many - rss_few) * 1024
    assert growth < 4 * frame_bytes, (rss_few, rss_many, frame_bytes)
    xyz = (tmp_path / "b").glob("*coord*")
    assert sum(1 for _ in xyz) >= 1
