"""MUSEN .mdem at scale: 100k spheres x 50 saves written and read, time and peak memory.

Each step runs in its own Python process (so its peak resident memory, ru_maxrss, is its own):

* write: ``MdemResultWriter`` fed 100k-sphere frames (the run pipeline's writer of .mdem results);
* read: every time point decoded into arrays (``MdemFile.time_points``);
* scene: the first time point read into fibrelmp's model (``read_scene``: what ``run`` does);
* baseline: the same frames written by the MUSEN *text* result writer, and that text read back
  by fibrelmp's text reader (``read_time_points``) -- the ratios compare .mdem with text.

Memory must not grow with the number of saves: the write and read steps also run with 10
saves, and the script prints both peaks.

Frames of a long result (issue 28): a .mdem of one sphere and ``--points`` time points (one
block each, as MUSEN saves; written by ``MdemWriter``), then frame 0, the middle frame and the
last one read as ``snapshot`` reads them (``MdemSource``: the scene, the block index, the one
block), each in its own process, against one pass of the full decode (every time point
decoded: what finding a frame cost before, once to count the frames and once more up to it).

    python benchmarks/mdem_io.py                      # 100k spheres x 50 saves, 1e6 points (~6 min)
    python benchmarks/mdem_io.py --spheres 20000 --saves 10 --points 100000
    python benchmarks/mdem_io.py --saves 0 --points 1000000     # the frames only
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STEP = r'''
import json, resource, sys, time
from pathlib import Path
import numpy as np
kind, folder, n, saves = sys.argv[1], Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])

def model():
    from fibrelmp.granmodel import GranularModel, GranularPlan, Material, Spheres
    rng = np.random.default_rng(1)
    mat = Material("GLASS", "glass", density=2500.0, youngs=5e10, poisson=0.22)
    s = Spheres(ids=np.arange(n), material=np.zeros(n, int), radius=np.full(n, 1e-4),
                contact_radius=np.full(n, 1e-4), mass=np.full(n, 1e-8),
                position=rng.random((n, 3)), velocity=rng.normal(size=(n, 3)),
                omega=rng.normal(size=(n, 3)), quaternion=np.tile([1.0, 0, 0, 0], (n, 1)),
                active_start=np.zeros(n), active_end=np.full(n, np.inf))
    return GranularModel(source=folder / "scene.txt", kind="musen", materials=[mat], contacts={},
                         spheres=s, plan=GranularPlan(dt=1e-7, t_start=0.0, t_end=saves * 1e-4))

def frames(m):
    from fibrelmp.granmodel import GranularFrame
    rng = np.random.default_rng(2)
    s = m.spheres
    for k in range(saves):
        yield GranularFrame(time=k * 1e-4, step=k * 1000, sphere_rows=np.arange(n),
                            position=s.position + 1e-6 * k, velocity=s.velocity, omega=s.omega,
                            force=rng.normal(size=(n, 3)), quaternion=s.quaternion)

if kind in ("frame-lazy", "full-decode"):       # imports are not what is measured
    import fibrelmp.translate.musen.mdem.pictures  # noqa: F401
    import fibrelmp.translate.musen.mdem.text_export  # noqa: F401
    import fibrelmp.translate.musen.scene  # noqa: F401

start, cpu = time.perf_counter(), time.process_time()
if kind in ("write-mdem", "write-text"):
    m = model()
    if kind == "write-mdem":
        from fibrelmp.translate.musen.mdem.result import MdemResultWriter as W
        w = W(m, folder / f"r{saves}.mdem")
    else:
        from fibrelmp.translate.musen.writer import MusenResultWriter as W
        w = W(m, folder / f"r{saves}.txt")
    for f in frames(m):
        w.add(f)
    w.close()
elif kind == "read-mdem":
    from fibrelmp.translate.musen.mdem.document import MdemFile
    total = 0.0
    with MdemFile(folder / f"r{saves}.mdem") as mdem:
        for t, values, masks in mdem.time_points():
            total += float(values[:, 0].sum())
elif kind == "read-text":
    from fibrelmp.translate.musen.text import read_time_points
    read_time_points(folder / f"r{saves}.txt")
elif kind == "scene-mdem":
    from fibrelmp.translate.musen.mdem.model import read_scene
    read_scene(folder / f"r{saves}.mdem")
elif kind == "export-mdem":
    from fibrelmp.python_api import convert_file
    convert_file(folder / f"r{saves}.mdem", folder / f"export{saves}.txt", force=True)
elif kind == "write-long":                       # n time points of one sphere (saves: unused)
    from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter
    from fibrelmp.translate.musen.mdem.result import MdemResultWriter
    n_points, n, saves = n, 1, 1
    m = model()
    first = MdemResultWriter(m, folder / "scene.mdem")
    first.add(next(frames(m)))
    first.close()
    with MdemFile(folder / "scene.mdem") as scene:
        storage = scene.scene
        _, values, masks = scene.time_point(0)
    with open(folder / "long.mdem", "w+b") as fh:
        w = MdemWriter(fh)
        for k in range(n_points):
            values[:, 0] = 1e-6 * k
            w.add(1e-4 * k, values, masks)
        w.finish(storage)
elif kind == "frame-lazy":                       # saves: the frame
    from fibrelmp.translate.musen.mdem.pictures import MdemSource
    MdemSource(folder / "long.mdem").frame(saves)
elif kind == "full-decode":
    from fibrelmp.translate.musen.mdem.document import MdemFile
    with MdemFile(folder / "long.mdem") as mdem:
        count = sum(1 for _ in mdem.time_points())
seconds = time.perf_counter() - start
print(json.dumps({"seconds": seconds, "cpu": time.process_time() - cpu,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
'''


def step(kind: str, folder: Path, spheres: int, saves: int, env: dict) -> dict:
    out = subprocess.run([sys.executable, "-c", STEP, kind, str(folder), str(spheres), str(saves)],
                         capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def frames(folder: Path, points: int, env: dict) -> None:
    """Frames 0, middle and last of a result of ``points`` time points: ``snapshot``'s reading
    against one pass of the full decode."""
    wrote = step("write-long", folder, points, 0, env)
    size = (folder / "long.mdem").stat().st_size / 2**20
    print(f"  long result: {points} time points of 1 sphere, {size:.1f} MB, written in "
          f"{wrote['seconds']:.1f} s")
    full = step("full-decode", folder, points, 0, env)
    print(f"  full decode, one pass:  {full['seconds']:7.2f} s (cpu {full['cpu']:6.2f} s), "
          f"peak {full['peak_mb']:6.1f} MB")
    for name, index in (("first", 0), ("middle", points // 2), ("last", points - 1)):
        lazy = step("frame-lazy", folder, points, index, env)
        print(f"  frame {index:8d} ({name:6s}): {lazy['seconds']:7.3f} s (cpu {lazy['cpu']:6.3f} s), "
              f"peak {lazy['peak_mb']:6.1f} MB; full decode pass / this: "
              f"{full['seconds'] / lazy['seconds']:.0f}x (cpu {full['cpu'] / lazy['cpu']:.0f}x)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spheres", type=int, default=100_000)
    parser.add_argument("--saves", type=int, default=50)
    parser.add_argument("--few", type=int, default=10, help="saves of the memory comparison")
    parser.add_argument("--export", action="store_true", help="also convert the .mdem to text")
    parser.add_argument("--points", type=int, default=1_000_000,
                        help="time points of the long result whose frames are read (0: none)")
    args = parser.parse_args()
    env = dict(os.environ)
    print(f"mdem_io: {args.spheres} spheres x {args.saves} saves, {args.points} time points; "
          f"load {os.getloadavg()[0]:.2f}; {time.strftime('%Y-%m-%d %H:%M')}")
    with tempfile.TemporaryDirectory(prefix="mdem-bench-") as tmp:
        folder = Path(tmp)
        if args.points:
            frames(folder, args.points, env)
        if not args.saves:
            return 0
        rows = {}
        for saves in (args.few, args.saves):
            for kind in ("write-mdem", "read-mdem", "write-text", "read-text"):
                rows[kind, saves] = step(kind, folder, args.spheres, saves, env)
        rows["scene-mdem", args.saves] = step("scene-mdem", folder, args.spheres, args.saves, env)
        if args.export:
            rows["export-mdem", args.saves] = step("export-mdem", folder, args.spheres, args.saves, env)
        sizes = {s: (folder / f"r{s}.mdem").stat().st_size / 2**20 for s in (args.few, args.saves)}
        text_mb = (folder / f"r{args.saves}.txt").stat().st_size / 2**20
        for (kind, saves), r in rows.items():
            print(f"  {kind:12s} {saves:4d} saves: {r['seconds']:7.2f} s, peak {r['peak_mb']:7.1f} MB")
        n, s = args.saves, args.spheres
        print(f"  file sizes: .mdem {sizes[args.saves]:.1f} MB ({args.few} saves: {sizes[args.few]:.1f} MB), "
              f"text (6 digits) {text_mb:.1f} MB")
        w, r = rows["write-mdem", n], rows["read-mdem", n]
        print(f"  .mdem write {1e9 * w['seconds'] / (n * s):.0f} ns, read {1e9 * r['seconds'] / (n * s):.0f} ns "
              "per sphere-save")
        for kind in ("write", "read"):
            few, many = rows[f"{kind}-mdem", args.few]["peak_mb"], rows[f"{kind}-mdem", n]["peak_mb"]
            print(f"  {kind} peak memory {args.few} -> {n} saves: {few:.0f} -> {many:.0f} MB "
                  f"(x{many / few:.2f})")
        print(f"mdem/text write time ratio: {w['seconds'] / rows['write-text', n]['seconds']:.3f}")
        print(f"mdem/text read time ratio: {r['seconds'] / rows['read-text', n]['seconds']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
