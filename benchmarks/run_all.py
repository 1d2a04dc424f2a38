#!/usr/bin/env python3
"""Run every benchmark and print one table of ratios.

Each benchmark times fibrelmp against its own baseline in the same run (same machine, same
moment), so the ratios compare across machines far better than the seconds.  They are still
sensitive to other load: the table header records the date, the core count and the load
average before and after.  Run on a quiet machine, from the repository root:

    python benchmarks/run_all.py            # the full sizes (~5 min on 2 free cores)
    python benchmarks/run_all.py --quick    # small sizes, a smoke test (~30 s)
    python benchmarks/run_all.py --only mpi_speedup --only translate

Every script also runs on its own (see benchmarks/README.md); extra options go to all of
them with ``--pass-args``.
"""

from __future__ import annotations

import argparse
import datetime
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass
class Bench:
    name: str
    what: str                 # numerator vs denominator
    pattern: str              # regex for the ratio on the script's output
    goal: str                 # e.g. "<= 1.0"
    quick: list[str]          # arguments for --quick
    needs: str = ""           # an environment variable it needs (skipped without it)

    def ok(self, ratio: float) -> bool:
        op, value = self.goal.split()
        return ratio <= float(value) if op == "<=" else ratio >= float(value)


BENCHES = [
    Bench("translate", "fibrelmp read + translate of a 260k-bead network / LAMMPS read_data of the file",
          r"translate/read_data ratio: ([0-9.]+)", "<= 1.0", ["--beads", "50000", "--repeat", "1"]),
    Bench("run_overhead", "fibrelmp run / the same in.lammps through the bare lammps module (50k beads)",
          r"fibrelmp/bare ratio: ([0-9.]+)", "<= 1.03",
          ["--beads", "10000", "--steps", "500", "--repeat", "1"]),
    Bench("post", "MDAnalysis reading a 256k-atom x 10-frame dump / fibrelmp post --to xyz of it "
          "(OVITO / fibrelmp too when FIBRELMP_OVITO_PYTHON names a Python with ovito)",
          r"MDAnalysis / fibrelmp: ([0-9.]+)x", ">= 20", ["--quick"]),
    Bench("fibrenet_angle", "angle_style fibrenet / harmonic: angle cost per step (5k and 50k beads, bent and straight)",
          r"fibrenet/harmonic angle cost ratio \(worst case\): ([0-9.]+)", "<= 1.0",
          ["--beads", "5000", "--repeat", "1", "--steps", "300"]),
    Bench("mpi_speedup", "serial fibrelmp run / mpiexec -n 2 fibrelmp run (260k beads, 1000 steps)",
          r"\d+-rank speed-up: ([0-9.]+)", ">= 1.7", ["--beads", "20000", "--steps", "200"]),
    Bench("bond_styles", "bond time per step: musen/elastic / bpm/rotational (MUSEN agglomerate, 1000 steps)",
          r"musen/elastic / bpm/rotational: loop [0-9.]+, bonds ([0-9.]+)", "<= 1.0",
          ["--steps", "100", "--repeat", "1"]),
    Bench("musen_styles", "MUSEN agglomerate loop per step: fibrelmp's styles / --stock-styles",
          r"ratio plugin / stock \(per-step cost\): ([0-9.]+)", "<= 1.0",
          ["--steps", "100", "--repeat", "1"]),
    Bench("mdem_io", "reading 100k spheres x 50 saves: MUSEN .mdem / MUSEN text (fibrelmp's readers)",
          r"mdem/text read time ratio: ([0-9.]+)", "<= 1.0",
          ["--spheres", "20000", "--saves", "10", "--few", "5", "--points", "20000"]),
    Bench("growth", "cost per particle, largest / smallest input, worst of FibreNet 50k-2.6M beads and MUSEN 5k-500k spheres",
          r"worst growth ratio \(all families run\): ([0-9.]+)", "<= 1.25", ["--quick"]),
    Bench("musen_models_cost", "per-contact cost of the 33 cmusen models: fibrelmp / cmusen -t=1 (worst model)",
          r"worst fibrelmp / cmusen per-contact ratio: ([0-9.]+)", "<= 1.0", ["--quick"],
          needs="FIBRELMP_CMUSEN"),
    Bench("vs_real_codes", "real FibreNet, 2 PoCL threads / best fibrelmp 1|2 ranks (worst of 5k/50k/260k/2.6M)",
          r"worst FibreNet ratio, real / best fibrelmp: ([0-9.]+)", ">= 3", ["--quick", "--repeat", "1"],
          needs="FIBRELMP_FIBRENET"),
]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes: checks the scripts, not the goals")
    ap.add_argument("--only", action="append", choices=[b.name for b in BENCHES],
                    help="run only this benchmark (repeatable)")
    ap.add_argument("--pass-args", default="", help="extra arguments for every script (one string)")
    ap.add_argument("--log", type=Path, default=None, help="also write every script's output here")
    args = ap.parse_args()

    chosen = [b for b in BENCHES if not args.only or b.name in args.only]
    load0 = os.getloadavg()
    started = datetime.datetime.now().astimezone()
    rows, logs = [], []
    for b in chosen:
        if b.needs and not os.environ.get(b.needs):
            print(f"== {b.name}: skipped ({b.needs} not set)", flush=True)
            rows.append((b, "skipped", 0.0))
            continue
        cmd = [sys.executable, str(HERE / f"{b.name}.py")] + (b.quick if args.quick else []) + args.pass_args.split()
        print(f"== {b.name}: {' '.join(cmd[1:])}", flush=True)
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        output = proc.stdout + proc.stderr
        logs.append(f"== {b.name} (exit {proc.returncode}, {wall:.0f} s)\n{output}")
        last = [ln for ln in output.splitlines() if ln.strip()][-3:]
        print("   " + "\n   ".join(last), flush=True)
        m = re.search(b.pattern, output)
        if proc.returncode != 0 or m is None:
            rows.append((b, None, wall))
        else:
            rows.append((b, float(m.group(1)), wall))
    load1 = os.getloadavg()

    print()
    print(f"fibrelmp benchmarks, {started:%Y-%m-%d %H:%M %Z}, {os.cpu_count()} cores, load average "
          f"{load0[0]:.2f} before / {load1[0]:.2f} after{' (QUICK sizes: goals not meaningful)' if args.quick else ''}")
    head = f"| {'benchmark':<13}| {'ratio (what / baseline, timed in the same run)':<82}| {'value':>6} | {'goal':<8}| {'verdict':<8}| {'wall':>5} |"
    print(head)
    print("|" + "|".join("-" * (len(c)) for c in head.split("|")[1:-1]) + "|")
    failed = 0
    for b, ratio, wall in rows:
        if ratio == "skipped":
            value, verdict = "-", "SKIPPED"
        elif ratio is None:
            value, verdict = "error", "ERROR"
            failed += 1
        else:
            value, verdict = f"{ratio:.3g}", "OK" if b.ok(ratio) else "MISSED"
        print(f"| {b.name:<13}| {b.what:<82}| {value:>6} | {b.goal:<8}| {verdict:<8}| {wall:4.0f}s |")
    if args.log:
        args.log.write_text("\n".join(logs))
        print(f"script outputs: {args.log}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
