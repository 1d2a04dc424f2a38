#!/usr/bin/env python3
"""Generate a random bead-spring fibre network in FibreNet's model + input format.

Fibres are planar arcs of beads spaced ``r0`` apart, with random start points, random
directions and a small random bend per triple (the rest angle is pi, so the fibres relax
towards straight).  Per fibre: tag = fibre index, loc_id 0, HR springs between consecutive
beads and HR angles for consecutive triples.  Fibre ``f`` has type ``F{f % types + 1}``;
radii, masses and stiffnesses can be given per type.  ``pair hs`` is written for every type
pair.  In a periodic box the wrapped position (px py pz) is in [0, L) and the unwrapped one
(ix iy iz) is continuous along each fibre; in a finite box every fibre is moved inside
the box.

Everything is vectorised numpy (positions, topology and text formatting), so a 260,000-bead
network takes a few seconds:

    python examples/generate_network.py --beads 260000 --out /tmp/big
    fibrelmp run /tmp/big/input.txt

The small example in examples/fibre_network/ was made with the command in its README.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

CHUNK = 65536       # rows formatted per % operation (bounds the size of the argument tuple)


def _per_type(values: list[float], ntypes: int) -> np.ndarray:
    """A per-type array from 1..n values, cycled to ``ntypes`` entries."""
    return np.array([values[t % len(values)] for t in range(ntypes)], dtype=float)


def build(beads: int, seed: int, box: float | None, density: float, fibre_min: int,
          fibre_max: int, r0: float, bend: float, ntypes: int, periodic: bool) -> dict:
    """Positions and topology (all numpy arrays) of a random network."""
    rng = np.random.default_rng(seed)
    mean_len = 0.5 * (fibre_min + fibre_max)
    nf = max(1, int(round(beads / mean_len)))
    lens = rng.integers(fibre_min, fibre_max + 1, size=nf)
    n = int(lens.sum())
    L = box if box is not None else (n / density) ** (1.0 / 3.0)

    start = np.r_[0, np.cumsum(lens)[:-1]]               # first bead of each fibre
    fib = np.repeat(np.arange(nf), lens)                 # fibre of each bead
    local = np.arange(n) - start[fib]                    # index of the bead in its fibre

    # orthonormal (d, e) per fibre: d = start direction, e = in-plane bend direction
    d = rng.normal(size=(nf, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    e = rng.normal(size=(nf, 3))
    e -= (e * d).sum(1, keepdims=True) * d
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    b = bend * rng.uniform(0.5, 1.5, size=nf)            # bend per triple (rad)
    phase = -0.5 * b * (lens - 2)                        # centre the arc on direction d

    # segment j (bead j-1 -> j) points along cos(phase + (j-1) b) d + sin(...) e
    ang = (phase[fib] + (local - 1) * b[fib])[:, None]
    seg = r0 * (np.cos(ang) * d[fib] + np.sin(ang) * e[fib])
    seg[local == 0] = 0.0
    cs = np.cumsum(seg, axis=0)
    pos = cs - cs[start][fib]                            # relative to each fibre's first bead

    if periodic:
        origin = rng.uniform(0.0, L, size=(nf, 3))
        unwrapped = np.round(origin[fib] + pos, 6)       # the file keeps 6 decimals
        wrapped = np.mod(unwrapped, L)
        wrapped[wrapped >= L] = 0.0                      # np.mod(-tiny, L) can round to L
    else:
        # random start, then shift each fibre so its bounding box lies inside [m, L - m]
        origin = rng.uniform(0.0, L, size=(nf, 3))
        x = origin[fib] + pos
        lo = np.minimum.reduceat(x, start, axis=0)
        hi = np.maximum.reduceat(x, start, axis=0)
        margin = min(0.5, 0.05 * L)
        shift = np.maximum(0.0, margin - lo) - np.maximum(0.0, hi - (L - margin))
        x = np.clip(np.round(x + shift[fib], 6), 0.0, L)
        wrapped = unwrapped = x

    # springs (i-1, i) and angles (i-2, i-1, i); spring of bead i (local >= 1) is i - 1 - fib
    sb = np.flatnonzero(local >= 1)
    ab = np.flatnonzero(local >= 2)
    return dict(n=n, nf=nf, L=L, fib=fib, types=fib % ntypes, wrapped=wrapped,
                unwrapped=unwrapped, springs=np.column_stack([sb - 1, sb]), spring_fib=fib[sb],
                angles=np.column_stack([ab - 2, ab - 1, ab]), angle_fib=fib[ab],
                angle_springs=np.column_stack([ab - 2 - fib[ab], ab - 1 - fib[ab]]))


def _format(fmt_row: str, columns: list) -> list[str]:
    """Rows formatted with one C-level ``%`` per chunk (no per-row Python code)."""
    n = len(columns[0])
    out = []
    for a in range(0, n, CHUNK):
        z = min(n, a + CHUNK)
        flat = np.empty((z - a, len(columns)), dtype=object)
        for c, col in enumerate(columns):
            flat[:, c] = col[a:z].tolist()
        out.append((fmt_row * (z - a)) % tuple(flat.ravel().tolist()))
    return out


def model_text(net: dict, names: list[str], radius: np.ndarray, mass: np.ndarray, r0: float,
               spring_k: np.ndarray, angle_k: np.ndarray) -> str:
    """FibreNet model file, tab-separated like FibreGen's (velocities and forces are 0)."""
    t = net["types"]
    # per-type text "F1\t" ... and per-type "R\tm" columns, looked up once per bead
    head = np.array([f"{names[k]}" for k in range(len(names))], dtype=object)[t]
    rm = np.array([f"{radius[k]:.6f}\t{mass[k]:.6f}" for k in range(len(names))], dtype=object)[t]
    w, u = net["wrapped"], net["unwrapped"]
    zeros = "\t".join(["0.000000"] * 6)
    parts = _format(f"BEAD\t%s\t%d\t0\t%s\t%.6f\t%.6f\t%.6f\t{zeros}\t%.6f\t%.6f\t%.6f\n",
                    [head, net["fib"], rm, w[:, 0], w[:, 1], w[:, 2], u[:, 0], u[:, 1], u[:, 2]])
    sf = net["spring_fib"]
    rk = np.array([f"{r0:.6f}\t{spring_k[k]:.6f}" for k in range(len(names))], dtype=object)
    s = net["springs"]
    parts += _format("SPRING\tHR\t%d\t%d\t%d\t%s\n", [sf, s[:, 0], s[:, 1], rk[sf % len(names)]])
    af = net["angle_fib"]
    tk = np.array([f"{math.pi!r}\t{angle_k[k]:.6f}" for k in range(len(names))], dtype=object)
    a, asp = net["angles"], net["angle_springs"]
    parts += _format("ANGLE\tHR\t%d\t%d\t%d\t%d\t%d\t%d\t%s\n",
                     [af, a[:, 0], a[:, 1], a[:, 2], asp[:, 0], asp[:, 1], tk[af % len(names)]])
    return "".join(parts)


def input_text(args, net: dict, names: list[str], radius: np.ndarray, hs_k: list[float]) -> str:
    ntypes = len(names)
    lines = ["model_file\tmodel.txt", f"output_file\t{args.output_file}", ""]
    lines += [f"type\t{name}" for name in names]
    k = 0
    for i in range(ntypes):
        for j in range(i, ntypes):
            lines.append(f"pair\ths\t{names[i]}\t{names[j]}\t{hs_k[k % len(hs_k)]:.1f}")
            k += 1
    L = net["L"]
    unit = args.unit_cell
    if unit is None:        # FibreNet lists hs pairs within max(R) + skin (skin = R + 0.5)
        unit = math.ceil(10 * max(args.cutoff, 2 * radius.max() + 0.5)) / 10
    lines += ["", f"box_size\t{L:.6f}\t{L:.6f}\t{L:.6f}", f"box_type\t{args.box_type}",
              f"box_wall_rep\t{args.wall_k:.1f}", f"box_unit_cell\t{unit:g}",
              f"cutoff\t{args.cutoff:g}", "", f"step\t{args.step:g}", f"lambda\t{args.lambda_:g}",
              f"damping\t{args.damping:g}", "", f"run\t{args.run}",
              f"output_freq\t{args.output_freq}", f"output_data\t{args.output_data}",
              "output_type\tall", ""]
    return "\n".join(lines)


def _floats(text: str) -> list[float]:
    return [float(x) for x in text.split(",")]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--beads", type=int, default=2000, help="total number of beads (approximate)")
    ap.add_argument("--out", type=Path, required=True, help="folder for model.txt and input.txt (created)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (same seed + numpy = same files)")
    ap.add_argument("--box", type=float, default=None, help="cubic box edge L; if omitted, L = (beads / density)^(1/3)")
    ap.add_argument("--density", type=float, default=0.2, help="beads per unit volume when --box is not given")
    ap.add_argument("--box-type", choices=("pbc", "finite"), default="pbc")
    ap.add_argument("--wall-k", type=float, default=500.0, help="box_wall_rep (needed even for pbc)")
    ap.add_argument("--fibre-beads", type=str, default="10:20",
                    help="beads per fibre: N or MIN:MAX (uniform random)")
    ap.add_argument("--r0", type=float, default=0.38, help="bead spacing = spring rest length")
    ap.add_argument("--bend", type=float, default=0.05,
                    help="mean initial bend per triple in rad (x0.5..1.5 per fibre); rest angle is pi")
    ap.add_argument("--types", type=int, default=2, help="number of bead types (fibre f gets type f %% types)")
    ap.add_argument("--radius", type=_floats, default=[0.42, 0.28], help="bead radius per type (comma list, cycled)")
    ap.add_argument("--mass", type=_floats, default=[1.0, 0.8], help="bead mass per type (comma list, cycled)")
    ap.add_argument("--spring-k", type=_floats, default=[3500.0, 3000.0], help="HR spring stiffness per type")
    ap.add_argument("--angle-k", type=_floats, default=[25.0, 15.0], help="HR angle stiffness c1 per type")
    ap.add_argument("--hs-k", type=_floats, default=[900.0, 1100.0, 700.0],
                    help="hs stiffness per type pair in order (1,1),(1,2),...,(2,2),... (cycled)")
    ap.add_argument("--cutoff", type=float, default=1.2, help="FibreNet global cutoff")
    ap.add_argument("--unit-cell", type=float, default=None,
                    help="box_unit_cell (default: max(cutoff, 2 max R + 0.5) rounded up)")
    ap.add_argument("--step", type=float, default=0.0005, help="time step")
    ap.add_argument("--lambda", dest="lambda_", type=float, default=0.5, help="FibreNet lambda")
    ap.add_argument("--damping", type=float, default=0.3, help="drag coefficient")
    ap.add_argument("--run", type=int, default=2000, help="production steps")
    ap.add_argument("--output-freq", type=int, default=400, help="steps between output frames")
    ap.add_argument("--output-data", choices=("all", "position", "velocity", "force"), default="all")
    ap.add_argument("--output-file", default="network", help="FibreNet output_file base name")
    args = ap.parse_args(argv)
    lo, _, hi = args.fibre_beads.partition(":")
    args.fibre_min, args.fibre_max = int(lo), int(hi or lo)
    if not 3 <= args.fibre_min <= args.fibre_max:
        ap.error("--fibre-beads: need 3 <= MIN <= MAX")
    if args.output_freq > args.run:
        ap.error("--output-freq must not exceed --run")
    return args


def generate(args: argparse.Namespace) -> dict:
    ntypes = args.types
    names = [f"F{k + 1}" for k in range(ntypes)]
    radius, mass = _per_type(args.radius, ntypes), _per_type(args.mass, ntypes)
    spring_k, angle_k = _per_type(args.spring_k, ntypes), _per_type(args.angle_k, ntypes)
    net = build(args.beads, args.seed, args.box, args.density, args.fibre_min, args.fibre_max,
                args.r0, args.bend, ntypes, args.box_type == "pbc")
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "model.txt").write_text(model_text(net, names, radius, mass, args.r0, spring_k, angle_k))
    (args.out / "input.txt").write_text(input_text(args, net, names, radius, args.hs_k))
    return net


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    net = generate(args)
    print(f"wrote {args.out / 'model.txt'} and {args.out / 'input.txt'}: {net['n']} beads in "
          f"{net['nf']} fibres, {len(net['springs'])} springs, {len(net['angles'])} angles, "
          f"box {net['L']:.4g} ({args.box_type})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
