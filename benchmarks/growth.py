#!/usr/bin/env python3
"""Cost per particle as inputs grow (issue 28, goal 3): FibreNet networks of 50k to 2.6M beads
and MUSEN packings of 5k to 500k spheres in a triangulated box.

For each size, in a fresh folder, each command a subprocess of its own (wall time and peak
resident memory of that process, ``os.wait4``):

* ``translate``: ``fibrelmp translate INPUT -o job`` -- s and bytes per particle;
* ``run``: ``fibrelmp -q run INPUT`` for a few steps -- LAMMPS's own loop time (log.lammps
  "Loop time of", summed) per particle-step, and the whole command's peak memory per particle;
* ``post``: ``fibrelmp post`` of the run's work dump (frames.dump) to the input's own format
  (FibreNet ``xyz``, MUSEN ``musen`` text) -- s per particle-frame and bytes per particle.

Inputs: ``examples/generate_network.py`` (as ``vs_real_codes.py`` makes its networks) and
``vs_real_codes.packing_scene`` (beads on a jittered lattice, 7 layers, in an open steel box of 10
triangles; the box widens with the count).  Printed: a table per family, the ratio largest /
smallest size of each per-particle figure (goal: within 1.25), and the load average.

    python benchmarks/growth.py                  # 50k, 260k, 2.6M beads; 5k, 50k, 500k spheres (~15 min)
    python benchmarks/growth.py --quick          # small sizes: checks the script (~10 s)
"""

from __future__ import annotations

import argparse
import datetime
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import timed as run_timed  # noqa: E402
from vs_real_codes import MUSEN_JOB, load_generator, packing_domain, packing_scene  # noqa: E402

CLI = [sys.executable, "-m", "fibrelmp.cli"]


def timed(cmd: list[str], cwd: Path) -> tuple[float, float]:
    """(wall seconds, peak resident bytes) of one fibrelmp command, single-threaded."""
    return run_timed(cmd, cwd=cwd, env=dict(os.environ, OMP_NUM_THREADS="1"))


def loop_seconds(log: Path) -> float:
    return sum(float(m) for m in re.findall(r"^Loop time of ([0-9.eE+-]+)", log.read_text(), re.M))


def fibrenet_input(folder: Path, beads: int, steps: int) -> tuple[str, int]:
    gen = load_generator()
    net = gen.generate(gen.parse_args(["--beads", str(beads), "--seed", "1", "--out", str(folder),
                                       "--run", str(steps), "--output-freq", str(steps)]))
    return "input.txt", int(net["n"])


def musen_input(folder: Path, spheres: int, steps: int) -> tuple[str, int]:
    (folder / "packing_scene.txt").write_text(packing_scene(spheres))
    dt = 1e-6
    (folder / "job.txt").write_text(MUSEN_JOB.format(
        scene="packing_scene.txt", dt=dt, save=steps * dt, end=steps * dt,
        models="MODEL_PW             ModelPWHertzMindlin\n", domain=packing_domain(spheres)))
    return "job.txt", spheres


def measure(root: Path, family: str, size: int, steps: int, keep: Path | None = None) -> dict:
    folder = root / f"{family}-{size}"
    folder.mkdir(parents=True)
    # made in a child: this process stays small, so the children's peak RSS is their own (a
    # forked child's high-water mark starts at its parent's)
    made = subprocess.run([sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); import growth; "
                           f"print(*growth.{family}_input(growth.Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])))",
                           str(HERE), str(folder), str(size), str(steps)],
                          check=True, capture_output=True, text=True).stdout.split()
    name, n = made[-2], int(made[-1])
    t_tr, m_tr = timed(CLI + ["-q", "translate", name, "-o", "job"], folder)
    t_run, m_run = timed(CLI + ["-q", "run", name, "-o", "out", "--work", "work"], folder)
    logs = sorted((folder / "work").rglob("log.lammps"))
    loop = sum(loop_seconds(log) for log in logs)
    dumps = sorted((folder / "work").rglob("frames.dump"))
    dump = dumps[-1]
    frames = sum(1 for line in open(dump, "rb") if line.startswith(b"ITEM: TIMESTEP"))
    target = "xyz" if family == "fibrenet" else "musen"
    t_post, m_post = timed(CLI + ["-q", "post", str(dump), "--to", target, "-o", "post/out"], folder)
    if keep is not None:            # LAMMPS's timing breakdown of the run
        shutil.copy(logs[-1], keep / f"{family}-{n}.log.lammps")
    shutil.rmtree(folder)           # the 2.6M-bead case writes GBs
    return {"family": family, "n": n, "steps": steps, "frames": frames,
            "translate_s": t_tr / n, "translate_B": m_tr / n,
            "run_s": loop / (n * steps), "run_B": m_run / n, "run_wall": t_run,
            "post_s": t_post / (n * frames), "post_B": m_post / n}


def table(rows: list[dict], label: str) -> float:
    print(f"\n{label}")
    print("| particles | translate µs/particle | translate B/particle | run µs/particle-step (LAMMPS loop) "
          "| run B/particle | post µs/particle-frame | post B/particle | run wall s |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['n']:,} | {r['translate_s'] * 1e6:.2f} | {r['translate_B']:.0f} | {r['run_s'] * 1e6:.3f} "
              f"| {r['run_B']:.0f} | {r['post_s'] * 1e6:.3f} | {r['post_B']:.0f} | {r['run_wall']:.1f} |")
    if len(rows) > 1:
        keys = ["translate_s", "translate_B", "run_s", "run_B", "post_s", "post_B"]
        ratios = {k: rows[-1][k] / rows[0][k] for k in keys}
        print("largest / smallest size: " + ", ".join(f"{k} {v:.2f}" for k, v in ratios.items()))
        # the memory each further particle costs (start-up's fixed ~100 MB left out)
        for a, b in zip(rows, rows[1:]):
            more = {k: (b[k] * b["n"] - a[k] * a["n"]) / (b["n"] - a["n"]) for k in ("translate_B", "run_B", "post_B")}
            print(f"bytes per further particle, {a['n']:,} -> {b['n']:,}: "
                  + ", ".join(f"{k[:-2]} {v:.0f}" for k, v in more.items()))
        worst = max(ratios.values())
        print(f"worst growth ratio ({label.split()[0]}): {worst:.2f} (goal <= 1.25)")
        return worst
    return 0.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="small sizes: checks the script")
    ap.add_argument("--only", choices=["fibrenet", "musen"], action="append")
    ap.add_argument("--keep-logs", type=Path, help="copy each run's log.lammps here")
    args = ap.parse_args()
    if args.quick:
        plan = {"fibrenet": [(5000, 50), (20000, 50)], "musen": [(500, 50), (2000, 50)]}
    else:
        plan = {"fibrenet": [(50_000, 200), (260_000, 100), (2_600_000, 20)],
                "musen": [(5_000, 200), (50_000, 200), (500_000, 200)]}
    print(f"growth: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, {os.cpu_count()} cores, "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    root = Path(tempfile.mkdtemp(prefix="fibrelmp_growth_"))
    worst = []
    try:
        for family, sizes in plan.items():
            if args.only and family not in args.only:
                continue
            rows = []
            for size, steps in sizes:
                rows.append(measure(root, family, size, steps, args.keep_logs))
                r = rows[-1]
                print(f"{family} {r['n']:,}: run {r['run_wall']:.1f} s, load {os.getloadavg()[0]:.2f}", flush=True)
            worst.append(table(rows, "FibreNet beads" if family == "fibrenet" else "MUSEN spheres"))
    finally:
        shutil.rmtree(root, ignore_errors=True)
    if worst:
        print(f"worst growth ratio (all families run): {max(worst):.2f} (goal <= 1.25)")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
