#!/usr/bin/env python3
"""Draw a frame of a CardioProof run: the fluid in a slice through the mesh (|y| < one spacing)
coloured by its velocity along the tube, the mesh cut by the plane y = 0 (walls solid, openings
dashed), and each opening's outflow over time from its CSV series.

    fibrelmp run examples/cardioproof/piston_tube.json
    python examples/cardioproof/picture.py examples/cardioproof/piston_tube.pvd --frame 7 \\
        --expected 3.1058e-7 -o docs/img/cardioproof_piston_tube.png
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def cut(triangles: np.ndarray) -> np.ndarray:
    """(m, 2, 3) segments where triangles (k, 3, 3) cross the plane y = 0."""
    out = []
    for t in triangles:
        y = t[:, 1]
        pts = []
        for i in range(3):
            a, b = t[i], t[(i + 1) % 3]
            if (a[1] < 0) != (b[1] < 0):
                s = a[1] / (a[1] - b[1])
                pts.append(a + s * (b - a))
        if len(pts) == 2 and np.ptp(y) > 0:
            out.append(pts)
    return np.array(out).reshape(-1, 2, 3)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("pvd", type=Path, help="the run's <name>.pvd")
    ap.add_argument("--frame", type=int, default=-1)
    ap.add_argument("-o", "--out", type=Path, default=None)
    ap.add_argument("--expected", type=float, default=None, help="a reference outflow (m^3/s) to draw")
    args = ap.parse_args(argv)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fibrelmp.post.vtk.reader import read_piece, read_pvd

    entries = read_pvd(args.pvd)
    time, path = entries[args.frame]
    base = args.pvd.with_suffix("")
    fluid = read_piece(path)
    walls = read_piece(path.with_name(path.stem + "_walls.vtp"))
    x = fluid.points
    v = fluid.point_data["Velocity"]
    # the two lattice layers nearest y = 0 (spacing from the fluid's volume per particle)
    spacing = (np.prod(np.ptp(x, axis=0)) / max(len(x), 1)) ** (1 / 3)
    slab = np.abs(x[:, 1]) <= 0.75 * spacing
    tri = walls.points.reshape(-1, 3, 3)
    opening = walls.cell_data["opening"]

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.6), gridspec_kw={"width_ratios": [1, 1.25]})
    mm = 1e3
    sc = ax.scatter(x[slab, 2] * mm, x[slab, 0] * mm, c=v[slab, 2], s=9, cmap="viridis", vmin=0)
    for k, style in ((-1, "-"), *((o, "--") for o in sorted(set(opening.tolist()) - {-1}))):
        for seg in cut(tri[opening == k]):
            ax.plot(seg[:, 2] * mm, seg[:, 0] * mm, style, color="k" if k < 0 else "tab:red", lw=1.4)
    ax.set_aspect("equal")
    ax.set_xlabel("z (mm)")
    ax.set_ylabel("x (mm)")
    ax.set_title(f"t = {time * 1e3:.2f} ms: fluid slice |y| small, wall (solid), outlet (dashed)", fontsize=9)
    fig.colorbar(sc, ax=ax, label="v_z (m/s)", shrink=0.8)

    for csv in sorted(base.parent.glob(base.name + "_*.csv")):
        d = np.genfromtxt(csv, delimiter=",", names=True)
        name = csv.stem[len(base.name) + 1:]
        bx.plot(d["time_s"] * 1e3, d["flux_velocity_m3_s"] * 1e9, lw=0.8, label=f"{name}: A x mean normal velocity")
        crossing = np.nan_to_num(d["flux_crossing_m3_s"])
        width = 10
        kernel = np.ones(width)
        smooth = np.convolve(crossing, kernel, mode="same") / np.convolve(np.ones_like(crossing), kernel, mode="same")
        bx.plot(d["time_s"] * 1e3, smooth * 1e9, lw=1.2, label=f"{name}: particles crossing (smoothed)")
    if args.expected is not None:
        bx.axhline(args.expected * 1e9, color="k", ls="--", lw=0.8, label="piston area x speed")
    bx.axvline(time * 1e3, color="0.6", lw=0.8)
    bx.set_xlabel("t (ms)")
    bx.set_ylabel("outflow (mm^3/s)")
    bx.legend(fontsize=8, loc="lower right")
    bx.set_title("outflow per opening", fontsize=9)
    fig.tight_layout()
    out = args.out or base.with_name(base.name + "_picture.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
