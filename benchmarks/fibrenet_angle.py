#!/usr/bin/env python3
"""FibreNet angle cost: fibrelmp's ``angle_style fibrenet`` versus ``harmonic`` and ``lepton``.

Random networks from examples/generate_network.py (``--beads``, default 5000 and 50000) in two
shapes: ``bent`` (the generator's 0.05 rad per triple) and ``straight`` (1e-5 rad per triple,
like relaxed FibreGen fibres with theta0 = pi, where the exact route matters).  Each network is
translated by fibrelmp (plugin), and the job's set-up (data file, bonds, pairs, fixes) is run
for ``--steps`` steps with four angle styles on the same data:

  fibrenet  fibrelmp's style (exact, also near straight)
  harmonic  angle_style harmonic, K = c1, theta0 in degrees (LAMMPS's cheapest angle; clamps
            sin(theta) at 0.001, so it is only a cost reference here)
  lepton    today's stock route: angle_style lepton + fibrelmp's clamp-cancelling expression
  zero      angle_style zero: the same run without angle forces

The wheel's ``lmp`` runs each job; the times are LAMMPS's own "Loop time" and its "Bond" section
(bonds + angles), so start-up and reading are excluded.  Angle cost = Bond(style) - Bond(zero),
per angle and step.  The variants are interleaved (rotating order) ``--repeat`` times; medians.

Goal: fibrenet / harmonic angle cost <= 1.0.

    python benchmarks/fibrenet_angle.py [--beads 5000 50000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import load_generator  # noqa: E402

STYLES = ("fibrenet", "harmonic", "lepton", "zero")
SHAPES = {"bent": 0.05, "straight": 1e-5}


def steps_for(beads: int) -> int:
    return max(200, int(2e7 / beads))          # ~0.5-1 s of LAMMPS per run


def prepare(folder: Path, beads: int, bend: float, steps: int) -> tuple[Path, int]:
    """Generate + translate one network; write in.<style> for every style; (folder, angles)."""
    from fibrelmp import lammps_styles
    from fibrelmp.translate.fibrenet.reader import read
    from fibrelmp.translate.lammps_job import angle_expression, write_job

    gen = load_generator()
    net = gen.generate(gen.parse_args(["--beads", str(beads), "--seed", "1", "--out", str(folder),
                                       "--bend", str(bend), "--run", str(steps),
                                       "--output-freq", str(steps)]))
    if not lammps_styles.plugin().available:
        sys.exit(f"fibrelmp's plugin is unavailable ({lammps_styles.plugin().how}): nothing to compare")
    job = write_job(read(folder / "input.txt"), folder / "job")
    lines = job.script.read_text().splitlines()
    end = next(i for i, ln in enumerate(lines) if ln.startswith("variable"))
    head = lines[:end]
    coeffs = [ln.split()[1:] for ln in head if ln.startswith("angle_coeff")]
    body = [ln for ln in head if not ln.startswith(("angle_style", "angle_coeff"))]
    at = next(i for i, ln in enumerate(body) if ln.startswith("special_bonds"))
    for style in STYLES:
        if style == "fibrenet":
            block = ["angle_style fibrenet"] + [f"angle_coeff {n} {c} {t0}" for n, c, t0 in coeffs]
        elif style == "harmonic":
            block = ["angle_style harmonic"] + [f"angle_coeff {n} {c} {math.degrees(float(t0))!r}"
                                                for n, c, t0 in coeffs]
        elif style == "lepton":
            block = ["angle_style lepton no_offset"] + [
                f'angle_coeff {n} {math.degrees(float(t0))!r} "{angle_expression(float(c), float(t0))}"'
                for n, c, t0 in coeffs]
        else:
            block = ["angle_style zero", "angle_coeff *"]
        script = body[:at] + block + body[at:] + [f"run {steps}"]
        (job.folder / f"in.{style}").write_text("\n".join(script) + "\n")
    return job.folder, len(net["angles"])


def run_once(folder: Path, style: str) -> tuple[float, float]:
    """(loop seconds, Bond-section seconds) of one run."""
    from fibrelmp._lammps import lmp_executable_env
    import lammps

    lmp = Path(lammps.__file__).parent / "lmp"
    log = folder / f"log.{style}"
    proc = subprocess.run([str(lmp), "-in", f"in.{style}", "-log", log.name, "-screen", "none",
                           "-nocite"], capture_output=True, text=True, cwd=folder,
                          env=dict(lmp_executable_env(), OMP_NUM_THREADS="1"))
    if proc.returncode != 0:
        sys.exit(f"lmp failed ({folder}, {style}):\n{(proc.stderr + proc.stdout)[-2000:]}")
    text = log.read_text()
    loop = float(re.search(r"Loop time of ([0-9.eE+-]+)", text).group(1))
    bond = float(re.search(r"^Bond\s*\|\s*\S+\s*\|\s*([0-9.eE+-]+)", text, re.M).group(1))
    return loop, bond


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--beads", type=int, nargs="+", default=[5000, 50000])
    ap.add_argument("--shapes", nargs="+", choices=list(SHAPES), default=list(SHAPES))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", type=int, default=None, help="default: 2e7 / beads (>= 200)")
    args = ap.parse_args()
    print(f"load before: {os.getloadavg()}  cores: {os.cpu_count()}  {time.strftime('%Y-%m-%d %H:%M')}")
    ratios = []
    with tempfile.TemporaryDirectory(prefix="fibrelmp-bench-") as tmp:
        for beads in args.beads:
            for shape in args.shapes:
                steps = args.steps or steps_for(beads)
                folder, nangles = prepare(Path(tmp) / f"{shape}{beads}", beads, SHAPES[shape], steps)
                times: dict[str, list[tuple[float, float]]] = {s: [] for s in STYLES}
                for r in range(args.repeat):
                    k = r % len(STYLES)
                    for style in STYLES[k:] + STYLES[:k]:
                        times[style].append(run_once(folder, style))
                loop = {s: statistics.median(t[0] for t in v) for s, v in times.items()}
                bond = {s: statistics.median(t[1] for t in v) for s, v in times.items()}
                angle = {s: bond[s] - bond["zero"] for s in STYLES}
                print(f"\n{shape} network, {beads} beads, {nangles} angles, {steps} steps "
                      f"(medians of {args.repeat})")
                for s in STYLES:
                    per = angle[s] / steps / max(nangles, 1) * 1e9
                    print(f"  {s:9s} loop {loop[s]:7.3f} s  bonds+angles {bond[s]:7.3f} s  "
                          f"angles {angle[s]:7.3f} s = {per:6.1f} ns/angle-step" if s != "zero" else
                          f"  {s:9s} loop {loop[s]:7.3f} s  bonds+angles {bond[s]:7.3f} s")
                r_angle = angle["fibrenet"] / angle["harmonic"]
                ratios.append(r_angle)
                print(f"  fibrenet/harmonic angle cost {r_angle:.3f}, loop {loop['fibrenet'] / loop['harmonic']:.3f}; "
                      f"lepton/fibrenet angle cost {angle['lepton'] / angle['fibrenet']:.2f}, "
                      f"loop {loop['lepton'] / loop['fibrenet']:.3f}")
    print(f"\nload after:  {os.getloadavg()}")
    worst = max(ratios)
    print(f"fibrenet/harmonic angle cost ratio (worst case): {worst:.3f} "
          f"({'OK' if worst <= 1.0 else 'ABOVE GOAL 1.0'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
