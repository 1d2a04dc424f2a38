#!/usr/bin/env python3
"""Per-step cost of fibrelmp's ``pair_style musen/hm`` against the stock ``pair_style granular``
line it replaces (hertz/material + mindlin + rolling sds + coeff_restitution), on a packing.

    python benchmarks/pair_musen_hm.py [--n 5000] [--steps 2000] [--repeat 3]

The packing: n glass spheres (R 0.9-1 mm, random) on a compressed simple cubic lattice in a
periodic box (every sphere touches its 6 neighbours: a settled bed's ~6 persistent
contacts), random velocities and spins, both styles with MUSEN's glass-glass coefficients of
the oblique scenario.  Each style runs with the ``newton`` fibrelmp writes for it (musen/hm:
off; granular: on).  Serial, in-process.  Printed: microseconds per step (total and the Pair
part of LAMMPS's timer) and the ratio musen/hm / granular (best of --repeat).
"""

from __future__ import annotations

import argparse
import math
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fibrelmp import lammps_styles  # noqa: E402
from fibrelmp._lammps import new_lammps  # noqa: E402

E_GLASS, NU_GLASS, RHO = 5e10, 0.22, 2500.0


def musen_coeffs() -> tuple[float, float]:
    g = E_GLASS / (2 * (1 + NU_GLASS))
    e_star = 1.0 / (2 * (1 - NU_GLASS ** 2) / E_GLASS)
    g_star = 1.0 / (2 * (2 - NU_GLASS) / g)
    return e_star, g_star


def stock_args(dt: float, m_min: float) -> str:
    """What fibrelmp's contacts.law_args writes for this law (same back-solve, same spring)."""
    from fibrelmp.granmodel import ContactLaw
    from fibrelmp.translate.granular.contacts import law_args, rolling_spring

    e_star, g_star = musen_coeffs()
    k, g = rolling_spring(m_min, dt)
    law = ContactLaw(e_star, g_star, 0.9, 0.45, 0.05)
    return law_args(law, 2 * law.rolling_friction, k, g)


def run(style: str, n: int, steps: int, plugin: Path | None) -> tuple[float, float, float]:
    side = max(2, round(n ** (1 / 3)))
    spacing = 1.9e-3
    L = side * spacing
    rng = np.random.default_rng(7)
    dt = 5e-8
    screen = Path(tempfile.mkdtemp()) / "screen.txt"
    lmp = new_lammps(["-log", "none", "-screen", str(screen), "-nocite"])
    try:
        cmds = ([f"plugin load {plugin}"] if style == "musen/hm" else []) + [
            "units si", "atom_style sphere", "boundary p p p",
            f"newton {'off' if style == 'musen/hm' else 'on'}", "comm_modify vel yes",
            f"region box block 0 {L!r} 0 {L!r} 0 {L!r}", "create_box 1 box",
            f"lattice sc {spacing!r}", "create_atoms 1 box",
            "set type 1 density 2500"]
        for c in cmds:
            lmp.command(c)
        nlocal = lmp.extract_global("nlocal")
        radius = lmp.numpy.extract_atom("radius")
        radius[:nlocal] = rng.uniform(0.96e-3, 1.0e-3, nlocal)
        rmass = lmp.numpy.extract_atom("rmass")
        rmass[:nlocal] = RHO * 4.0 / 3.0 * math.pi * radius[:nlocal] ** 3
        v = lmp.numpy.extract_atom("v")
        v[:nlocal] = rng.normal(0, 0.05, (nlocal, 3))
        w = lmp.numpy.extract_atom("omega")
        w[:nlocal] = rng.normal(0, 50.0, (nlocal, 3))
        if style == "musen/hm":
            e_star, g_star = musen_coeffs()
            lmp.commands_list(["pair_style musen/hm",
                               f"pair_coeff * * {e_star!r} {g_star!r} 0.9 0.45 0.05"])
        else:
            lmp.commands_list(["pair_style granular",
                               f"pair_coeff * * {stock_args(dt, float(rmass[:nlocal].min()))}"])
        lmp.commands_list(["neighbor 0.0005 bin", "neigh_modify every 1 delay 0 check yes",
                           f"timestep {dt!r}", "fix 1 all nve/sphere", "run 0 post no"])
        t0 = time.perf_counter()
        lmp.command(f"run {steps} pre no post yes")
        total = time.perf_counter() - t0
        contacts = _contacts(lmp, nlocal)
    finally:
        lmp.close()
    # LAMMPS's timing breakdown of the run: "Pair    | min | avg | max | %varavg | %total"
    rows = [ln for ln in screen.read_text().splitlines() if ln.startswith("Pair ")]
    pair = float(rows[-1].split("|")[2]) if rows else float("nan")
    shutil.rmtree(screen.parent, ignore_errors=True)
    return total / steps * 1e6, pair / steps * 1e6, contacts


def _contacts(lmp, nlocal) -> float:
    x = lmp.numpy.extract_atom("x")[:nlocal]
    r = lmp.numpy.extract_atom("radius")[:nlocal]
    box = lmp.extract_box()
    L = np.array(box[1]) - np.array(box[0])
    n = 0
    for i in range(min(nlocal, 500)):
        d = x - x[i]
        d -= L * np.round(d / L)
        dist = np.linalg.norm(d, axis=1)
        n += int(((dist < r + r[i]) & (dist > 0)).sum())
    return n / min(nlocal, 500)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    found = lammps_styles.plugin()
    if not found.available:
        print(f"the plugin is unavailable: {found.how}")
        return 1
    best, best_pair = {}, {}
    for _ in range(args.repeat):
        for style in ("granular", "musen/hm"):
            us, pair_us, contacts = run(style, args.n, args.steps, found.path)
            best[style] = min(best.get(style, math.inf), us)
            best_pair[style] = min(best_pair.get(style, math.inf), pair_us)
            print(f"{style:>9}: {us:8.1f} us/step, Pair {pair_us:8.1f} us/step "
                  f"({contacts:.2f} contacts per sphere)")
    ratio = best["musen/hm"] / best["granular"]
    print(f"Pair part: musen/hm / granular = {best_pair['musen/hm'] / best_pair['granular']:.3f}")
    print(f"per-step cost musen/hm / granular: {ratio:.3f} "
          f"({best['musen/hm']:.1f} / {best['granular']:.1f} us, {args.n} spheres, best of {args.repeat})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
