"""``fibrelmp post`` against issue 24's hostile inputs: a gzip line that expands to hundreds
of MB, a gzip dump cut short, inf/nan values, names that need XML escaping, MPI, output
names and ``.pvd`` times.  Hostile files are built here, small; anything bounding memory or
time runs the CLI in a subprocess with RLIMIT_AS and a timeout."""

from __future__ import annotations

import gzip
import os
import resource
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.post.lammps_dump.reader import MAX_LINE
from fibrelmp.translate.fibrenet.writer import read_xyz

from .test_post_robust import ROWS, frame, write
from .test_post_roundtrip import post

CLI = [sys.executable, "-m", "fibrelmp.cli"]


def cli(args: list, cwd: Path, memory_mb: int | None = None, timeout: float = 60.0) -> subprocess.CompletedProcess:
    """The CLI in a subprocess (address space limited to ``memory_mb`` when given)."""
    def limit() -> None:
        if memory_mb is not None:
            resource.setrlimit(resource.RLIMIT_AS, (memory_mb << 20, memory_mb << 20))
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return subprocess.run(CLI + [str(a) for a in args], cwd=cwd, capture_output=True, text=True,
                          preexec_fn=limit, timeout=timeout, env=env)


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# ------------------------------------------------------------- 1. one huge line in a small .gz
LONG_LINE_MB = 600          # what the hostile line expands to
MEMORY_MB = 400             # the CLI's address space: a conversion needs < 150 MB


def long_line_gz(path: Path) -> Path:
    """A 1-atom frame whose atom line is ``LONG_LINE_MB`` MB of digits without a newline:
    gzip members (concatenated, as gzip allows) of 16 MiB each, compressed once (~0.6 MB)."""
    head = frame(0, [(1, 1, 0.5, 0.5, 0.5)]).rsplit("1 1 0.5", 1)[0]
    block = gzip.compress(b"1" * (16 << 20), compresslevel=9)
    with open(path, "wb") as fh:
        fh.write(gzip.compress(head.encode()))
        for _ in range(LONG_LINE_MB // 16):
            fh.write(block)
        fh.write(gzip.compress(b" 1 1 1 1\n"))
    return path


@pytest.mark.parametrize("args", [["--info"], ["--to", "xyz", "-o", "out/net"]])
def test_a_gzip_line_of_hundreds_of_mb_is_refused_within_bounded_memory(tmp_path, args):
    """Was: the whole line read into memory (3 GB resident, exit 1 'out of memory').  Now an
    input error at the line, exit 2, in a process limited to MEMORY_MB of address space."""
    dump = long_line_gz(tmp_path / "long.dump.gz")
    assert dump.stat().st_size < 2 << 20
    proc = cli(["post", dump.name, *args], tmp_path, memory_mb=MEMORY_MB, timeout=60)
    assert proc.returncode == 2, proc.stderr[-2000:]
    line = len(frame(0, ROWS).splitlines()) - len(ROWS) + 1          # the first atom line: 10
    assert proc.stderr.strip().splitlines()[-1] == (
        f"error: long.dump.gz:{line}: line longer than {MAX_LINE >> 20} MiB, the longest a dump "
        "line may be (docs/post.md; not a LAMMPS text dump?)")
    assert "Traceback" not in proc.stderr
    assert listing(tmp_path) == ["long.dump.gz"]        # nothing written, no folder made


def test_a_long_header_line_is_refused_too(tmp_path):
    """A line longer than MAX_LINE where an ITEM line is expected (plain file)."""
    p = write(tmp_path, b"ITEM: TIMESTEP\n" + b"7" * (MAX_LINE + 10) + b"\n")
    from fibrelmp.errors import InputError
    from fibrelmp.post.lammps_dump.reader import iter_frames

    with pytest.raises(InputError, match=r"d\.dump:2: line longer than 1 MiB"):
        list(iter_frames(p))


def test_lines_up_to_the_bound_are_read(tmp_path):
    """An atom line of many columns, just under MAX_LINE, is an ordinary line."""
    from fibrelmp.post.lammps_dump.reader import iter_frames

    ncol = 5 + (MAX_LINE - 1000) // 13          # "1.00000000e0 " is 13 characters
    names = "id type x y z " + " ".join(f"c_{k}" for k in range(ncol - 5))
    row = " ".join(["1", "1", "0.5", "0.5", "0.5"] + ["1.00000000e0"] * (ncol - 5))
    assert MAX_LINE - 2000 < len(row) < MAX_LINE
    p = write(tmp_path, frame(0, [(row,)], cols=names))
    (got,) = list(iter_frames(p))
    assert got.count == 1 and len(got.columns) == ncol and got.columns[f"c_{ncol - 6}"][0] == 1.0


# ------------------------------------------------------------- 5. a gzip dump cut short
@pytest.mark.parametrize("keep", [0.6, 0.95])
def test_a_gzip_dump_cut_short_keeps_its_complete_frames_like_a_plain_one(tmp_path, keep):
    """Was: 'cannot read the dump: Compressed file ended before the end-of-stream marker'
    (exit 2, nothing).  Now the frames before the cut, with a warning, as for a plain dump
    cut at the same place of the text."""
    rng = np.random.default_rng(5)          # random digits: gzip cannot shrink them much
    frames = [frame(s, [(k, 1, *rng.random(3)) for k in range(1, 21)], time=s / 10)
              for s in range(0, 50, 10)]
    packed = gzip.compress("".join(frames).encode())
    cut = packed[:int(keep * len(packed))]
    gz = write(tmp_path, cut, "cut.dump.gz")
    seen = zlib.decompressobj(31).decompress(cut)                  # what the cut file holds
    plain = write(tmp_path, seen, "cut.dump")
    complete = sum(len("".join(frames[:k + 1])) <= len(seen) for k in range(5))
    assert 1 <= complete < 5
    for dump, name in ((gz, "gz"), (plain, "plain")):
        proc = cli(["post", dump.name, "--to", "xyz", "-o", name], tmp_path, timeout=60)
        assert proc.returncode == 0, proc.stderr
        assert "warning [truncated dump]" in proc.stderr
        steps = [f.step for f in read_xyz(tmp_path / f"{name}_coord.xyz")]
        assert steps == list(range(0, 10 * complete, 10)), name
    assert "gzip stream ends early" in cli(["post", gz.name, "--info"], tmp_path).stderr
