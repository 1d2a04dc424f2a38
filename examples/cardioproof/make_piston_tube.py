#!/usr/bin/env python3
"""Write the piston-tube case: an openCARP surface mesh (tube wall, piston, outlet), the
piston's motion as a ``.dynpt`` and the case file.

The tube (radius R, length L along z) is closed at z = 0 by a piston disc and at z = L by the
outlet disc (the opening, region tag 3).  The piston starts at rest, accelerates uniformly for
``ramp`` seconds and then moves at ``speed`` into the tube; the outlet pressure rises
linearly from 0 to ``pressure`` over the run.  Steady outflow = piston area x speed.

    python examples/cardioproof/make_piston_tube.py --out examples/cardioproof
    fibrelmp run examples/cardioproof/piston_tube.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

UM = 1e-6          # openCARP coordinates are µm


def disc(z: float, radius: float, segments: int, start: int) -> tuple[np.ndarray, np.ndarray]:
    """A fan of triangles: centre node, then the ring; node numbers from ``start``."""
    a = 2 * math.pi * np.arange(segments) / segments
    pts = np.vstack([[0.0, 0.0, z], np.column_stack([radius * np.cos(a), radius * np.sin(a), np.full(segments, z)])])
    k = np.arange(segments)
    tri = np.column_stack([np.zeros(segments, int), 1 + k, 1 + (k + 1) % segments]) + start
    return pts, tri


def tube(radius: float, length: float, segments: int, rings: int, start: int) -> tuple[np.ndarray, np.ndarray]:
    a = 2 * math.pi * np.arange(segments) / segments
    z = np.linspace(0.0, length, rings)
    pts = np.array([[radius * math.cos(t), radius * math.sin(t), zz] for zz in z for t in a])
    quads = []
    for r in range(rings - 1):
        for k in range(segments):
            i, j = r * segments + k, r * segments + (k + 1) % segments
            quads.append([i, j, j + segments, i + segments])
    return pts, np.array(quads) + start


def piston_position(t: np.ndarray, speed: float, ramp: float) -> np.ndarray:
    return np.where(t < ramp, speed * t * t / (2 * ramp), speed * (t - ramp / 2))


def build(radius: float, length: float, segments: int, speed: float, ramp: float, end: float,
          frame_interval: float, outlet_speed: float = 0.0):
    rings = max(2, int(round(length / (2 * math.pi * radius / segments))) + 1)
    t_pts, t_quads = tube(radius, length, segments, rings, 0)
    p_pts, p_tri = disc(0.0, radius, segments, len(t_pts))
    o_pts, o_tri = disc(length, radius, segments, len(t_pts) + len(p_pts))
    points = np.vstack([t_pts, p_pts, o_pts])
    piston = np.arange(len(t_pts), len(t_pts) + len(p_pts))
    times = np.arange(int(round(end / frame_interval)) + 1) * frame_interval
    frames = np.repeat(points[None], len(times), axis=0)
    frames[:, piston, 2] += piston_position(times, speed, ramp)[:, None]
    if outlet_speed:
        # the outlet disc and the tube's last ring move out along z (the last quads stretch)
        end_nodes = np.r_[np.arange((rings - 1) * segments, rings * segments),
                          np.arange(len(t_pts) + len(p_pts), len(points))]
        frames[:, end_nodes, 2] += outlet_speed * times[:, None]
    return points, t_quads, p_tri, o_tri, frames


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("."))
    ap.add_argument("--radius", type=float, default=1.0e-3)
    ap.add_argument("--length", type=float, default=2.0e-3)
    ap.add_argument("--segments", type=int, default=24)
    ap.add_argument("--speed", type=float, default=0.1, help="piston speed (m/s)")
    ap.add_argument("--ramp", type=float, default=4.0e-3, help="acceleration time (s)")
    ap.add_argument("--end", type=float, default=10.0e-3, help="end time (s)")
    ap.add_argument("--frame-interval", type=float, default=0.5e-3)
    ap.add_argument("--spacing", type=float, default=1.25e-4)
    ap.add_argument("--sound-speed", type=float, default=5.0, help="c0 (m/s): 50 x the piston speed")
    ap.add_argument("--pressure", type=float, default=10.0, help="outlet pressure at the end (Pa)")
    ap.add_argument("--outlet-speed", type=float, default=0.0, help="the outlet moves out at this speed (m/s)")
    ap.add_argument("--save-interval", type=float, default=1.0e-3, help="VTK frames every (s)")
    ap.add_argument("--name", default="piston_tube")
    args = ap.parse_args(argv)

    from fibrelmp.mesh.model import CellBlock, Mesh
    from fibrelmp.mesh.opencarp.dynpt import DynptWriter
    from fibrelmp.mesh.opencarp.mesh import OpenCarpMeshWriter

    points, quads, piston, outlet, frames = build(args.radius, args.length, args.segments, args.speed,
                                                  args.ramp, args.end, args.frame_interval, args.outlet_speed)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    mesh = Mesh(points / UM, [CellBlock("quad", quads, np.full(len(quads), 1)),
                              CellBlock("triangle", piston, np.full(len(piston), 2)),
                              CellBlock("triangle", outlet, np.full(len(outlet), 3))], unit=UM)
    with OpenCarpMeshWriter(out / f"{args.name}.pts") as w:
        w.add(mesh)
    with DynptWriter(out / f"{args.name}.dynpt", inc_t=args.frame_interval * 1e3, unit_t="ms") as w:
        for f in frames:
            w.add(f / UM)
    case = {
        "mesh": {"file": f"{args.name}.pts"},
        "motion": {"file": f"{args.name}.dynpt", "frame_interval": args.frame_interval},
        "fluid": {"spacing": args.spacing, "density": 1000.0, "artificial_viscosity": 0.1, "sound_speed": args.sound_speed},
        "openings": [{"name": "outlet", "tags": [3], "pressure": [[0.0, 0.0], [args.end, args.pressure]]}],
        "run": {"end_time": args.end},
        "output": {"interval": args.save_interval, "series_interval": args.save_interval / 10},
    }
    # the first key "cardioproof" on the first line: how fibrelmp tells a case from DEMDF JSON
    body = ",\n".join(f" {json.dumps(k)}: {json.dumps(v)}" for k, v in case.items())
    (out / f"{args.name}.json").write_text('{"cardioproof": 1,\n' + body + "\n}\n")
    print(f"wrote {out / args.name}.pts/.elem, .dynpt ({len(frames)} frames), .json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
