#!/usr/bin/env python3
"""Per-step cost of MUSEN's solid bonds: fibrelmp's ``bond_style musen/elastic`` versus the
stock ``bond_style bpm/rotational`` that stands in without the plugin.

Translates MUSEN's agglomerate-impact scenario (tests/data/real-outputs/musen/scenarios/
agglomerate_impact: 5,696 spheres, 18,802 bonds, a plate) twice, with fibrelmp's styles and
with ``--stock-styles``, into a temporary folder, keeps each ``in.lammps`` up to its first
``run 0`` (the set-up: data file, styles, walls, fixes), and times ``run N`` from the start
(the agglomerate falls onto the plate and hits it at step ~400, so the second half of a
1,000-step run has contacts and a few breaks) in a fresh process each, alternating.  The
bpm/rotational script is the plugin job's with only its bonds replaced by the stock job's
(newton_bond off, data file, bond types and coefficients), so the two differ in the bonds
alone.

Printed, best of ``--repeat`` passes: LAMMPS's loop time per step and the ``Bond`` row of its
timing breakdown per step, for each style, and their ratios.

    python benchmarks/bond_styles.py [--steps 1000] [--repeat 2]
"""

from __future__ import annotations

import argparse
import gzip
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
SCENARIO = HERE.parent / "tests" / "data" / "real-outputs" / "musen" / "scenarios" / "agglomerate_impact"

RUNNER = """
import sys
from fibrelmp._lammps import new_lammps
lmp = new_lammps(["-log", "log.bench", "-screen", "none", "-nocite"])
lmp.file("bench.lammps")
lmp.close()
"""


def translate(folder: Path, stock: bool) -> Path:
    folder.mkdir(parents=True)
    with gzip.open(SCENARIO / "agglo_impact_scene.txt.gz", "rb") as src:
        (folder / "agglo_impact_scene.txt").write_bytes(src.read())
    shutil.copy(SCENARIO / "job_agglo.txt", folder)
    cmd = [sys.executable, "-m", "fibrelmp.cli", "-q", "translate", "job_agglo.txt", "-o", "job"]
    if stock:
        cmd.append("--stock-styles")
    subprocess.run(cmd, cwd=folder, check=True, capture_output=True)
    return folder / "job"


def setup_lines(job: Path) -> list[str]:
    """``in.lammps`` up to its first run, without dumps and local computes."""
    lines = (job / "in.lammps").read_text().splitlines()
    first_run = next(i for i, ln in enumerate(lines) if ln.startswith("run"))
    return [ln for ln in lines[:first_run]
            if not ln.startswith(("dump", "dump_modify"))
            and not (ln.startswith("compute") and "/local" in ln)]


def bench_scripts(plugin_job: Path, stock_job: Path, steps: int) -> None:
    """The plugin job as rendered, and the same job with the stock job's bonds (newton_bond
    off, its data file and bond types, bpm/rotational): everything else identical."""
    tail = ["run 0 post no", f"run {steps} pre no"]
    plugin = setup_lines(plugin_job)
    (plugin_job / "bench.lammps").write_text("\n".join(plugin + tail) + "\n")
    stock_bonds = [ln for ln in setup_lines(stock_job) if ln.startswith(("bond_style", "bond_coeff"))]
    out, placed = [], False
    for ln in plugin:
        if ln.startswith("newton"):
            out.append("newton          on off")
        elif "property/atom" in ln and "fl_bgeom" in ln:
            continue
        elif ln.startswith("read_data"):
            out.append(f"read_data       {stock_job / 'data.lammps'}")
        elif ln.startswith(("bond_style", "bond_coeff")):
            if not placed:
                out += stock_bonds
                placed = True
        else:
            out.append(ln)
    (stock_job / "bench.lammps").write_text("\n".join(out + tail) + "\n")


def timed(job: Path) -> tuple[float, float, int]:
    """(loop seconds, bond seconds, steps) of the timed run, from LAMMPS's log."""
    subprocess.run([sys.executable, "-c", RUNNER], cwd=job, check=True)
    log = (job / "log.bench").read_text()
    loops = re.findall(r"Loop time of (\S+) on \d+ procs for (\d+) steps", log)
    bonds = re.findall(r"^Bond\s+\|\s+\S+\s+\|\s+(\S+)", log, re.M)
    loop, steps = loops[-1]
    return float(loop), float(bonds[-1]), int(steps)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    from fibrelmp import lammps_styles

    found = lammps_styles.plugin()
    if not found.available:
        sys.exit(f"fibrelmp's LAMMPS styles are unavailable: {found.how}")
    with tempfile.TemporaryDirectory(prefix="fibrelmp-bench-bonds-") as tmp:
        jobs = {"musen/elastic": translate(Path(tmp) / "plugin", False),
                "bpm/rotational": translate(Path(tmp) / "stock", True)}
        bench_scripts(jobs["musen/elastic"], jobs["bpm/rotational"], args.steps)
        best = {name: None for name in jobs}
        for _ in range(args.repeat):
            for name, job in jobs.items():
                loop, bond, steps = timed(job)
                if best[name] is None or loop < best[name][0]:
                    best[name] = (loop, bond, steps)
        print(f"agglomerate (5,696 spheres, 18,802 bonds), {args.steps} steps from t = 0, "
              f"best of {args.repeat}:")
        for name, (loop, bond, steps) in best.items():
            print(f"  {name:15s} loop {1e3 * loop / steps:7.3f} ms/step   bonds {1e3 * bond / steps:7.3f} ms/step")
        (lp, bp, _), (ls, bs, _) = best["musen/elastic"], best["bpm/rotational"]
        print(f"musen/elastic / bpm/rotational: loop {lp / ls:.3f}, bonds {bp / bs:.3f}")


if __name__ == "__main__":
    main()
