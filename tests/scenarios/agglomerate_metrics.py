"""Metrics of MUSEN's agglomerate-impact scenario (tests/data/real-outputs/musen/scenarios/
agglomerate_impact/README.md) from MUSEN text results, cmusen's or fibrelmp's:

* broken bonds at t: solid bonds whose activity end (tag 24) is <= t;
* the mass-weighted centre-of-mass v_z of the spheres at t (mass = density of the sphere's
  material (its ``32`` line, property 0) x 4/3 pi R^3);
* fragments at the last time: connected components of the spheres over the bonds still
  active then (largest, single spheres, others of >= 2 spheres).

    python tests/scenarios/agglomerate_metrics.py RESULT.txt[.gz] [OTHER.txt[.gz] ...]

prints one column per file; the first is the reference, later columns get the README's
tolerances checked against it (broken bonds 20 % + 10, COM v_z 0.3 m/s, largest fragment
2 %, single spheres 30 % + 10).  Standard library and numpy only; the parser is written here
from the text format (docs/musen.md), independent of fibrelmp's reader.
"""

from __future__ import annotations

import gzip
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

TIMES_US = (10, 20, 30, 50, 70, 100, 150, 300)
# values per time-dependent tag of MUSEN's text format (2: the time itself)
TD_SIZE = {2: 1, 10: 3, 11: 3, 12: 3, 15: 3, 16: 3, 17: 3, 18: 1, 20: 3, 31: 4, 36: 9, 37: 1,
           42: 3, 43: 1, 44: 9, 45: 3}


@dataclass
class Result:
    bond_pair: np.ndarray        # (m, 2) sphere ids
    bond_end: np.ndarray         # (m,) activity end (inf: never)
    sphere_id: np.ndarray        # (n,)
    sphere_mass: np.ndarray      # (n,)
    times: np.ndarray            # (T,) saved times
    vz: np.ndarray               # (T, n) v_z (nan where not saved)


def _open(path: Path):
    return gzip.open(path, "rt") if path.suffix == ".gz" else open(path)


def read(path: str | Path) -> Result:
    path = Path(path)
    density: dict[str, float] = {}
    spheres: list[tuple[int, float, str, dict[float, float]]] = []
    bonds: list[tuple[int, int, float]] = []
    with _open(path) as fh:
        for line in fh:
            tok = line.split()
            if not tok:
                continue
            if tok[0] == "32":                 # 32 KEY NAME pid value pid value ...
                props = dict(zip(tok[3::2], tok[4::2]))
                if "0" in props:
                    density[tok[1]] = float(props["0"])
                continue
            if tok[0] != "0":
                continue
            otype = int(tok[3])
            if otype not in (1, 9):
                continue
            i = tok.index("23", 5)              # after "0 ID 1 TYPE 5 <geometry>"
            key = tok[i + 1]
            end = float(tok[i + 4]) if tok[i + 2] == "24" else math.inf
            if otype == 9:                     # 5 LEFT RIGHT d L0
                bonds.append((int(tok[5]), int(tok[6]), end))
                continue
            radius = float(tok[5])
            vz: dict[float, float] = {}
            j, t = i + 5 if tok[i + 2] == "24" else i + 2, None
            while j < len(tok):
                tag = int(tok[j])
                if tag == 2:
                    t = float(tok[j + 1])
                elif tag == 15:
                    vz[t] = float(tok[j + 3])
                j += 1 + TD_SIZE[tag]
            spheres.append((int(tok[1]), radius, key, vz))
    times = np.array(sorted({t for *_, vz in spheres for t in vz}))
    index = {t: k for k, t in enumerate(times)}
    vzs = np.full((len(times), len(spheres)), np.nan)
    for s, (*_, vz) in enumerate(spheres):
        for t, value in vz.items():
            vzs[index[t], s] = value
    mass = np.array([density.get(key, 1.0) * 4.0 / 3.0 * math.pi * r ** 3 for _, r, key, _ in spheres])
    b = np.array([(a, c) for a, c, _ in bonds], np.int64).reshape(-1, 2)
    return Result(b, np.array([e for *_, e in bonds]), np.array([s[0] for s in spheres]), mass, times, vzs)


def _at(res: Result, t: float) -> int:
    k = int(np.argmin(np.abs(res.times - t)))
    if abs(res.times[k] - t) > 1e-9:
        raise ValueError(f"no saved time {t:g} (nearest {res.times[k]:g})")
    return k


def broken(res: Result, t: float) -> int:
    return int((res.bond_end <= t + 1e-12).sum())


def com_vz(res: Result, t: float) -> float:
    v = res.vz[_at(res, t)]
    ok = np.isfinite(v)
    return float((res.sphere_mass[ok] * v[ok]).sum() / res.sphere_mass[ok].sum())


def fragments(res: Result, t: float) -> tuple[int, int, int]:
    """(largest fragment, single spheres, other fragments of >= 2) over bonds active at t."""
    ids = res.sphere_id
    where = {int(s): k for k, s in enumerate(ids)}
    parent = np.arange(len(ids))

    def root(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    for (a, b), end in zip(res.bond_pair, res.bond_end):
        if end > t + 1e-12 and int(a) in where and int(b) in where:
            ra, rb = root(where[int(a)]), root(where[int(b)])
            if ra != rb:
                parent[ra] = rb
    sizes = np.bincount([root(k) for k in range(len(ids))])
    sizes = sizes[sizes > 0]
    return int(sizes.max()), int((sizes == 1).sum()), int((sizes >= 2).sum() - 1)


def metrics(res: Result) -> dict[str, float]:
    out: dict[str, float] = {}
    for us in TIMES_US:
        out[f"broken@{us}us"] = broken(res, us * 1e-6)
    for us in TIMES_US:
        out[f"COMvz@{us}us"] = com_vz(res, us * 1e-6)
    last = float(res.times.max())
    big, single, other = fragments(res, min(last, TIMES_US[-1] * 1e-6))
    out["largest_fragment"], out["single_spheres"], out["other_fragments"] = big, single, other
    return out


def within(name: str, ref: float, value: float) -> bool:
    """The README's tolerances."""
    if name.startswith("broken"):
        return abs(value - ref) <= 0.2 * abs(ref) + 10
    if name.startswith("COMvz"):
        return abs(value - ref) <= 0.3
    if name == "largest_fragment":
        return abs(value - ref) <= 0.02 * abs(ref)
    if name == "single_spheres":
        return abs(value - ref) <= 0.3 * abs(ref) + 10
    return True


def main(paths: list[str]) -> int:
    results = [metrics(read(p)) for p in paths]
    names = [Path(p).name for p in paths]
    print("metric\t" + "\t".join(names))
    failed = 0
    for key in results[0]:
        row = [key] + [f"{r[key]:.4g}" if isinstance(r[key], float) else str(r[key]) for r in results]
        marks = ["" if within(key, results[0][key], r[key]) else " *" for r in results[1:]]
        failed += sum(bool(m) for m in marks)
        print("\t".join(row[:2] + [v + m for v, m in zip(row[2:], marks)]))
    if len(paths) > 1:
        print(f"{failed} value(s) outside the README's tolerances (marked *)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]) if len(sys.argv) > 1 else __doc__)
