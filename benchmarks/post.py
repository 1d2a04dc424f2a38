"""fibrelmp post (LAMMPS dump -> FibreNet xyz) vs MDAnalysis merely reading the same dump.

Generates a 256,000-atom x 10-frame text dump (id type x y z vx vy vz fx fy fz in LAMMPS's
default %g format, ~220 MB) in a temporary folder, then times, in the same process:

* fibrelmp: ``post_command(dump, "xyz", ...)`` -- reading, parsing, sorting and writing
  ``_coord/_vel/_force.xyz`` (everything ``fibrelmp post --to xyz`` does but start-up);
* MDAnalysis: ``Universe(dump, format="LAMMPSDUMP")`` (reads frame 0 for the topology and
  indexes the frames) plus iterating over every frame (its DumpReader parses each frame;
  nothing is written).

Passes are interleaved after one untimed warm-up conversion (page cache, imports); the best of
each side counts.  Also printed: fibrelmp's reader alone (``iter_frames``: read + parse, one
``np.loadtxt`` per frame), the floor of any conversion built on it.

Run from the repository root:  python benchmarks/post.py   (~1 min)
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def generate(path: Path, atoms: int, frames: int, seed: int = 1) -> None:
    """A dump like LAMMPS's ``dump custom`` default (ints %d, floats %g), sorted by id."""
    from fibrelmp.textio import format_rows

    rng = np.random.default_rng(seed)
    ids = np.arange(1, atoms + 1)
    types = rng.integers(1, 4, atoms)
    x = rng.random((atoms, 3)) * 100.0
    v = rng.normal(size=(atoms, 3))
    with open(path, "w") as fh:
        for k in range(frames):
            f = rng.normal(size=(atoms, 3)) * 10.0
            fh.write(f"ITEM: TIMESTEP\n{k * 1000}\nITEM: NUMBER OF ATOMS\n{atoms}\n"
                     "ITEM: BOX BOUNDS pp pp pp\n0 100\n0 100\n0 100\n"
                     "ITEM: ATOMS id type x y z vx vy vz fx fy fz\n")
            cols = [ids, types] + [a[:, c] for a in (x, v, f) for c in range(3)]
            fh.write(format_rows("%d %d" + " %g" * 9 + "\n", cols))
            x = np.mod(x + 0.05 * v, 100.0)


def run_fibrelmp(dump: Path, out: Path) -> float:
    from fibrelmp.post.convert import post_command

    if out.exists():
        shutil.rmtree(out)
    out.mkdir()
    t = time.perf_counter()
    post_command(dump, "xyz", out / "net", False, None, None, None, None, None, False, None, lambda s: None)
    return time.perf_counter() - t


def run_reader(dump: Path) -> float:
    """fibrelmp's reader alone (read + parse every frame), to show where the time goes."""
    from fibrelmp.post.lammps_dump.reader import iter_frames

    t = time.perf_counter()
    for _ in iter_frames(dump):
        pass
    return time.perf_counter() - t


def run_mdanalysis(dump: Path, frames: int) -> float:
    import MDAnalysis as mda

    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        u = mda.Universe(str(dump), format="LAMMPSDUMP")
        n = sum(1 for _ in u.trajectory)
    elapsed = time.perf_counter() - t
    assert n == frames
    return elapsed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--atoms", type=int, default=256_000)
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=2, help="interleaved passes; the best of each side counts")
    ap.add_argument("--profile", action="store_true", help="cProfile one fibrelmp conversion")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="fibrelmp_bench_post_"))
    try:
        dump = tmp / "dump.lammpstrj"
        t = time.perf_counter()
        generate(dump, args.atoms, args.frames)
        print(f"dump: {args.atoms} atoms x {args.frames} frames, {dump.stat().st_size / 1e6:.0f} MB "
              f"(generated in {time.perf_counter() - t:.1f} s)")
        run_fibrelmp(dump, tmp / "warm")                     # page cache, imports
        mine, theirs, reader = [], [], []
        for k in range(args.repeat):
            mine.append(run_fibrelmp(dump, tmp / "out"))
            theirs.append(run_mdanalysis(dump, args.frames))
            reader.append(run_reader(dump))
            print(f"pass {k + 1}: fibrelmp post --to xyz {mine[-1]:.2f} s (its reader alone {reader[-1]:.2f} s), "
                  f"MDAnalysis DumpReader {theirs[-1]:.2f} s")
        out_mb = sum(p.stat().st_size for p in (tmp / "out").iterdir()) / 1e6
        print(f"fibrelmp wrote {out_mb:.0f} MB of xyz")
        if args.profile:
            import cProfile
            import pstats

            cProfile.runctx("run_fibrelmp(dump, tmp / 'prof')", globals(), locals(), str(tmp / "p"))
            pstats.Stats(str(tmp / "p")).sort_stats("tottime").print_stats(15)
        print(f"MDAnalysis-read / fibrelmp-convert ratio: {min(theirs) / min(mine):.1f}x (goal >= 10x)")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
