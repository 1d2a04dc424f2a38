"""Metrics of the oblique_two_materials scenario (shared/real-outputs/musen/scenarios/
oblique_two_materials/README.md): fibrelmp's MUSEN text result against the real cmusen's.

    python tests/scenarios/oblique_metrics.py OURS.txt [CMUSEN.txt[.gz]]

prints one line per metric (ours, cmusen's, difference, tolerance) and the verdict; the
default reference is the 17-digit cmusen result in tests/data.  Importable:
``compare(ours_path, ref_path)`` returns the rows, ``metrics(path)`` the values of one file.

The 38 metrics (the README's table), at t = 1 ms unless noted:
* plate impacts, spheres 0-6 (glass/steel at 20, 45, 70 degrees; glass with back-spin):
  v_n = v_z, v_t = v_x, omega_y;  sphere 7 (steel with spin): v_z, (v_x, v_y), omega (vector);
* free-flight pairs 10/11 (glass hit by steel, offset in z) and 12/13 (spinning glass hit by
  glass, offset in y): |v| and omega_y (10, 11) / omega_z (12, 13) of each sphere;
* slide-to-roll spheres 8 (glass) and 9 (steel) at 40 ms: x, |v|, omega_y (only when both
  files reach 40 ms).
Tolerances (README "Tolerances and why"): v_n 1e-3 m/s, v_t 5e-3 m/s, omega 20 rad/s, pair
velocities 0.01 m/s, rolling spheres 10 um, 1e-3 m/s, 1 rad/s.  Vector metrics compare the
norm of the difference.
"""

from __future__ import annotations

import gzip
import shutil
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DEFAULT_REF = (ROOT / "tests" / "data" / "real-outputs" / "musen" / "scenarios" / "oblique_two_materials"
               / "cmusen_oblique_result_prec17.txt.gz")

T_IMPACT = 1e-3
T_ROLL = 0.04
PLATE = {0: "G20", 1: "G45", 2: "G70", 3: "S20", 4: "S45", 5: "S70", 6: "Gspin0"}
PAIRS = {10: ("glass target (10)", 1), 11: ("steel striker (11)", 1),
         12: ("spinning glass (12)", 2), 13: ("glass striker (13)", 2)}
ROLLERS = {8: "glass roller (8)", 9: "steel roller (9)"}
TOL = {"v_n": 1e-3, "v_t": 5e-3, "omega": 20.0, "pair_v": 0.01, "pair_omega": 20.0,
       "roll_x": 10e-6, "roll_v": 1e-3, "roll_omega": 1.0}


@dataclass
class Row:
    name: str
    kind: str           # key of TOL
    ours: np.ndarray
    ref: np.ndarray

    @property
    def diff(self) -> float:
        return float(np.linalg.norm(np.atleast_1d(self.ours) - np.atleast_1d(self.ref)))

    @property
    def tol(self) -> float:
        return TOL[self.kind]

    @property
    def ok(self) -> bool:
        return self.diff <= self.tol

    def line(self) -> str:
        def fmt(a):
            a = np.atleast_1d(a)
            return ("(" + ", ".join(f"{x:.6g}" for x in a) + ")") if len(a) > 1 else f"{a[0]:.6g}"
        return (f"{'ok  ' if self.ok else 'FAIL'} {self.name:<28} {fmt(self.ours):>30} {fmt(self.ref):>30}"
                f"  diff {self.diff:.3g} (tol {self.tol:g})")


def _plain(path: Path, tmp: Path) -> Path:
    if path.suffix != ".gz":
        return path
    out = tmp / path.stem
    with gzip.open(path, "rb") as src, open(out, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return out


def metrics(path: str | Path) -> dict[str, tuple[str, np.ndarray]]:
    """name -> (tolerance kind, value) of one MUSEN text result."""
    sys.path.insert(0, str(ROOT))
    from fibrelmp.translate.musen.text import read_time_points

    with tempfile.TemporaryDirectory() as tmp:
        tp = read_time_points(_plain(Path(path), Path(tmp)), types=(1,), tags=(12, 15, 16))
    ids = list(tp.ids)

    def at(t: float, tag: int, obj: int) -> np.ndarray | None:
        k = int(np.argmin(np.abs(tp.times - t)))
        if abs(tp.times[k] - t) > 1e-9:
            return None
        return tp.fields[tag][k, ids.index(obj)]

    out: dict[str, tuple[str, np.ndarray]] = {}
    for obj, label in PLATE.items():
        v, w = at(T_IMPACT, 15, obj), at(T_IMPACT, 16, obj)
        out[f"{label} v_n"] = ("v_n", v[2])
        out[f"{label} v_t"] = ("v_t", v[0])
        out[f"{label} omega_y"] = ("omega", w[1])
    v, w = at(T_IMPACT, 15, 7), at(T_IMPACT, 16, 7)
    out["S30spin v_n"] = ("v_n", v[2])
    out["S30spin v_t (x, y)"] = ("v_t", v[:2])
    out["S30spin omega"] = ("omega", w)
    for obj, (label, axis) in PAIRS.items():
        v, w = at(T_IMPACT, 15, obj), at(T_IMPACT, 16, obj)
        out[f"{label} |v|"] = ("pair_v", np.linalg.norm(v))
        out[f"{label} omega_{'xyz'[axis]}"] = ("pair_omega", w[axis])
    for obj, label in ROLLERS.items():
        x, v, w = at(T_ROLL, 12, obj), at(T_ROLL, 15, obj), at(T_ROLL, 16, obj)
        if x is None:
            continue
        out[f"{label} x at 40 ms"] = ("roll_x", x[0])
        out[f"{label} |v| at 40 ms"] = ("roll_v", np.linalg.norm(v))
        out[f"{label} omega_y at 40 ms"] = ("roll_omega", w[1])
    return out


def compare(ours: str | Path, ref: str | Path = DEFAULT_REF) -> list[Row]:
    """Every metric both results have, in the README's order."""
    a, b = metrics(ours), metrics(ref)
    return [Row(name, kind, np.asarray(val), np.asarray(b[name][1]))
            for name, (kind, val) in a.items() if name in b]


def sphere_sphere(rows: list[Row]) -> list[Row]:
    """The metrics of the free-flight pairs (10-13): they depend on the particle-particle law only."""
    return [r for r in rows if r.kind.startswith("pair_")]


def main(argv: list[str]) -> int:
    if not argv or len(argv) > 2:
        print(__doc__.split("\n\n")[1])
        return 2
    rows = compare(argv[0], argv[1] if len(argv) > 1 else DEFAULT_REF)
    print(f"     {'metric':<28} {'fibrelmp':>30} {'cmusen':>30}")
    for r in rows:
        print(r.line())
    good = sum(r.ok for r in rows)
    print(f"{'PASS' if good == len(rows) else 'FAIL'}: {good}/{len(rows)} metrics within tolerance")
    return 0 if good == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
