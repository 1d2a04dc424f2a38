"""Make the stored references of MUSEN's Examples 1, 2, 3, 7 from cmusen's 17-digit text exports
(README.md says how those were made).  Usage:
    python make_reference.py OUT.txt.gz EXPORT_prec17.txt [forces [STRIDE]]

Writes, for every saved time point after t = 0: a sample of the spheres (ids that are multiples
of 8 or STRIDE, and every sphere touching the moving upper plate at t = 0) as
``S time id x y z vx vy vz wx wy wz``, every wall as ``W time id`` and its 9 vertex coordinates,
the number of solid bonds broken by the last time point as ``# broken_bonds N``, and with
``forces`` the sampled spheres' saved forces as ``F time id fx fy fz``; 17 significant digits."""

from __future__ import annotations

import gzip
import sys

import numpy as np

from fibrelmp.translate.musen.scene import read
from fibrelmp.translate.musen.text import read_time_points

SPHERE, WALL = 1, 14
PLATE_TOP_CONTACTS = (1913,)    # row of the sphere touching UpperWall at t = 0 (docs/musen.md)


def sampled_rows(ids: np.ndarray, types: np.ndarray, stride: int = 8) -> np.ndarray:
    spheres = types == SPHERE
    rows = set(np.flatnonzero(spheres & (ids % stride == 0)).tolist()) | set(PLATE_TOP_CONTACTS)
    return np.array(sorted(rows), np.int64)


def main(out: str, export: str, forces: bool = False, stride: int = 8) -> None:
    tp = read_time_points(export, tags=(12, 15, 16, 20, 44))
    rows = sampled_rows(tp.ids, tp.types, stride)
    walls = np.flatnonzero(tp.types == WALL)
    model = read(export)
    # the scene's bonds carry activity ends from an earlier run, far in the future: not breaks
    broken = int(np.count_nonzero(model.bonds.active_end <= tp.times[-1])) if model.bonds.count else 0
    with gzip.open(out, "wt") as f:
        f.write(f"# cmusen 1.74.2 export {export.split('/')[-1]}: sampled spheres and walls\n")
        f.write(f"# broken_bonds {broken}\n")
        for k in range(1, len(tp.times)):
            t = repr(float(tp.times[k]))
            for r in rows:
                vals = np.concatenate([tp.fields[12][k][r], tp.fields[15][k][r], tp.fields[16][k][r]])
                f.write(f"S {t} {int(tp.ids[r])} " + " ".join(f"{v:.17g}" for v in vals) + "\n")
            if forces:
                for r in rows:
                    f.write(f"F {t} {int(tp.ids[r])} " + " ".join(f"{v:.17g}" for v in tp.fields[20][k][r]) + "\n")
            for r in walls:
                f.write(f"W {t} {int(tp.ids[r])} " + " ".join(f"{v:.17g}" for v in tp.fields[44][k][r]) + "\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], len(sys.argv) > 3 and sys.argv[3] == "forces",
         int(sys.argv[4]) if len(sys.argv) > 4 else 8)
