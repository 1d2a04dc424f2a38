"""Plate metrics of the oblique scenario (shared/real-outputs/musen/scenarios/oblique_two_materials):
spheres 0-9 on the aluminium plate (z = 0), compared with the real cmusen result.

    python tests/scenarios/oblique_metrics.py RESULT [--reference CMUSEN_RESULT]

The README's definitions: at t = 1 ms the rebound of spheres 0-7, v_n = vz, v_t = vx (sphere 7:
(vx, vy)) and the spin w_y (sphere 7: the whole vector); at t = 40 ms the sliding-then-rolling
spheres 8 and 9: x, vx and w_y.  Tolerances: v_n 1e-3 m/s, v_t 5e-3 m/s, w 20 rad/s; rolling
spheres 10 um, 1e-3 m/s, 1 rad/s.
"""

from __future__ import annotations

import argparse
import gzip
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[2]))

from fibrelmp.translate.musen.text import read_time_points  # noqa: E402

NAMES = ["G20", "G45", "G70", "S20", "S45", "S70", "Gspin0", "S30spin"]
TOL = {"v_n": 1e-3, "v_t": 5e-3, "w": 20.0, "x": 1e-5, "v": 1e-3, "w_roll": 1.0}


def _plain(path: Path, tmp: Path) -> Path:
    if path.suffix != ".gz":
        return path
    out = tmp / path.stem
    with gzip.open(path, "rb") as src, open(out, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return out


def _at(tp, t: float) -> int:
    k = int(np.argmin(np.abs(tp.times - t)))
    if abs(tp.times[k] - t) > 1e-9:
        raise ValueError(f"no saved time at {t}")
    return k


def oblique_metrics(result: str | Path) -> list[tuple[str, str, np.ndarray]]:
    """(sphere, metric kind, value) rows."""
    with tempfile.TemporaryDirectory() as tmp:
        tp = read_time_points(_plain(Path(result), Path(tmp)), types=(1,), tags=(12, 15, 16))
    col = {int(i): k for k, i in enumerate(tp.ids)}
    k1, k40 = _at(tp, 1e-3), _at(tp, 0.04)
    x, v, w = tp.fields[12], tp.fields[15], tp.fields[16]
    rows = []
    for sid, name in enumerate(NAMES):
        c = col[sid]
        rows.append((name, "v_n", np.array([v[k1, c, 2]])))
        rows.append((name, "v_t", v[k1, c, :2] if sid == 7 else np.array([v[k1, c, 0]])))
        rows.append((name, "w", w[k1, c] if sid == 7 else np.array([w[k1, c, 1]])))
    for sid, name in ((8, "G-roll"), (9, "S-roll")):
        c = col[sid]
        rows.append((name, "x", np.array([x[k40, c, 0]])))
        rows.append((name, "v", np.array([v[k40, c, 0]])))
        rows.append((name, "w_roll", np.array([w[k40, c, 1]])))
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("result")
    p.add_argument("--reference", default=None)
    a = p.parse_args(argv)
    shared = HERE.parents[3] / "shared" / "real-outputs" / "musen" / "scenarios" / "oblique_two_materials"
    ref = oblique_metrics(a.reference or shared / "cmusen_oblique_result_prec17.txt.gz")
    mine = oblique_metrics(a.result)
    ok_all = 0
    print("# sphere\tmetric\tthis\tcmusen\tdifference\twithin tolerance")
    for (name, kind, mv), (_, _, rv) in zip(mine, ref):
        d = float(np.abs(mv - rv).max())
        ok = d <= TOL[kind]
        ok_all += ok
        fmt = lambda a: ", ".join(f"{x:.6g}" for x in a)   # noqa: E731
        print(f"{name}\t{kind}\t{fmt(mv)}\t{fmt(rv)}\t{d:.3g}\t{'yes' if ok else 'NO'} (<= {TOL[kind]:g})")
    print(f"# {ok_all}/{len(mine)} within tolerance")
    return 0


if __name__ == "__main__":
    sys.exit(main())
