"""fibrelmp post (LAMMPS dump -> FibreNet xyz) against OVITO and MDAnalysis reading the same dump,
and against the I/O limit (issue 28, goal 1).

Generates a 256,000-atom x 10-frame text dump (id type x y z vx vy vz fx fy fz in LAMMPS's
default %g format, ~220 MB) in a temporary folder, then runs, each as a whole command in its
own subprocess (start-up and imports included; wall time and peak resident memory):

* fibrelmp: ``fibrelmp -q post DUMP --to xyz -o OUT`` -- reading, parsing, sorting and writing
  ``_coord/_vel/_force.xyz``; and, one line each, the other targets (``--targets``);
* OVITO (its Python module, C++ readers): ``import_file(DUMP)`` + every frame's positions
  (``pipeline.compute(frame).particles.positions``), nothing written; needs ``--ovito-python``
  (a Python with ``pip install ovito``; env FIBRELMP_OVITO_PYTHON), else "not given";
* MDAnalysis: ``Universe(DUMP, format="LAMMPSDUMP")`` + iterating every frame, nothing written;
* the I/O limit: reading the dump (16 MB blocks, as ``cat dump > /dev/null``) + writing as many
  bytes as fibrelmp writes, with nothing computed.

``--repeat`` interleaved rounds after one untimed warm-up of each (page cache); medians count.
Printed: seconds, MB/s of dump read, peak RSS, ratios OVITO / fibrelmp and MDAnalysis / fibrelmp
(goals >= 1 and >= 20) and fibrelmp / I/O limit, and the load average before and after.

Run from the repository root:  python benchmarks/post.py [--ovito-python /venv/bin/python]  (~2 min)
"""

from __future__ import annotations

import argparse
import datetime
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import timed as run_timed  # noqa: E402


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


def timed(cmd: list[str], env: dict | None = None) -> tuple[float, float]:
    """(wall seconds, peak resident MB) of one command."""
    seconds, peak = run_timed(cmd, env=env)
    return seconds, peak / 2**20


def fibrelmp_cmd(dump: Path, out: Path, target: str = "xyz") -> list[str]:
    if out.exists():
        shutil.rmtree(out)
    out.mkdir()
    return [sys.executable, "-m", "fibrelmp.cli", "-q", "post", str(dump), "--to", target, "-o", str(out / "net")]


def ovito_missing(python: str | None) -> str | None:
    """Why OVITO cannot be timed (None if it can)."""
    if not python:
        return "not given (--ovito-python)"
    done = subprocess.run([python, "-c", "import ovito"], capture_output=True, text=True)
    if done.returncode:
        return f"not installed in {python}: {done.stderr.strip().splitlines()[-1:]}"
    return None


OVITO = """
import sys
from ovito.io import import_file
pipeline = import_file(sys.argv[1])
n = pipeline.source.num_frames
total = 0.0
for frame in range(n):
    total += float(pipeline.compute(frame).particles.positions[0, 0])
assert n == int(sys.argv[2]), n
"""

MDA = """
import sys, warnings
import MDAnalysis as mda
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    u = mda.Universe(sys.argv[1], format="LAMMPSDUMP")
    n = sum(1 for _ in u.trajectory)
assert n == int(sys.argv[2]), n
"""

IO_LIMIT = """
import sys
with open(sys.argv[1], "rb", buffering=0) as src:
    while src.read(1 << 24):
        pass
left, block = int(sys.argv[3]), bytes(1 << 24)
with open(sys.argv[2], "wb", buffering=0) as dst:
    while left > 0:
        left -= dst.write(block[:min(left, len(block))])
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--atoms", type=int, default=256_000)
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=3, help="interleaved rounds; medians count")
    ap.add_argument("--ovito-python", default=os.environ.get("FIBRELMP_OVITO_PYTHON"),
                    help="a Python with the ovito module (env FIBRELMP_OVITO_PYTHON)")
    ap.add_argument("--targets", default="xyz,res,vtk",
                    help="fibrelmp post targets to time, one line each (xyz is the one compared; mdem, musen, "
                         "demdf and mercury need radius/mass columns this dump lacks)")
    ap.add_argument("--quick", action="store_true", help="20,000 atoms x 3 frames, 1 round: checks the script")
    args = ap.parse_args()
    if args.quick:
        args.atoms, args.frames, args.repeat = 20_000, 3, 1
    if args.quick:
        args.targets = "xyz"
    print(f"post: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    tmp = Path(tempfile.mkdtemp(prefix="fibrelmp_bench_post_"))
    try:
        dump = tmp / "dump.lammpstrj"
        t = time.perf_counter()
        # in a child: this process stays small, so its children's peak RSS is their own (a
        # forked child's high-water mark starts at its parent's)
        subprocess.run([sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); import post; "
                        "post.generate(post.Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]))",
                        str(Path(__file__).parent), str(dump), str(args.atoms), str(args.frames)], check=True)
        size = dump.stat().st_size / 1e6
        print(f"dump: {args.atoms} atoms x {args.frames} frames, {size:.0f} MB "
              f"(generated in {time.perf_counter() - t:.1f} s)")
        timed(fibrelmp_cmd(dump, tmp / "out"))               # page cache, first imports
        written = sum(p.stat().st_size for p in (tmp / "out").iterdir())
        sides = {"fibrelmp post --to xyz": lambda: fibrelmp_cmd(dump, tmp / "out")}
        for target in [t for t in args.targets.split(",") if t and t != "xyz"]:
            sides[f"fibrelmp post --to {target}"] = (lambda t=target: fibrelmp_cmd(dump, tmp / f"out_{t}", t))
            timed(sides[f"fibrelmp post --to {target}"]())   # untimed warm-up, as for xyz
        sides |= {"MDAnalysis read": lambda: [sys.executable, "-c", MDA, str(dump), str(args.frames)],
                 "I/O limit (read + write)": lambda: [sys.executable, "-c", IO_LIMIT, str(dump),
                                                      str(tmp / "io.out"), str(written)]}
        missing = ovito_missing(args.ovito_python)
        if not missing:
            sides["OVITO read"] = lambda: [args.ovito_python, "-c", OVITO, str(dump), str(args.frames)]
            timed(sides["OVITO read"]())                      # its first start compiles .pyc files
        results: dict[str, list[tuple[float, float]]] = {k: [] for k in sides}
        names = list(sides)
        for k in range(args.repeat):
            for name in names[k % len(names):] + names[:k % len(names)]:
                results[name].append(timed(sides[name]()))
            print(f"round {k + 1}: " + ", ".join(f"{n} {results[n][-1][0]:.2f} s" for n in names))
        med = {n: (statistics.median(t for t, _ in r), max(m for _, m in r)) for n, r in results.items()}
        print(f"\n| side | s (median of {args.repeat}) | dump MB/s | peak RSS MB |")
        print("|---|---|---|---|")
        for n in names:
            print(f"| {n} | {med[n][0]:.2f} | {size / med[n][0]:.0f} | {med[n][1]:.0f} |")
        if missing:
            print(f"| OVITO read | {missing} | | |")
        mine = med["fibrelmp post --to xyz"][0]
        print(f"\nfibrelmp wrote {written / 1e6:.0f} MB of xyz")
        if not missing:
            print(f"OVITO / fibrelmp: {med['OVITO read'][0] / mine:.2f}x (goal >= 1)")
        print(f"MDAnalysis / fibrelmp: {med['MDAnalysis read'][0] / mine:.1f}x (goal >= 20)")
        print(f"fibrelmp / I/O limit: {mine / med['I/O limit (read + write)'][0]:.2f}x")
        print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
