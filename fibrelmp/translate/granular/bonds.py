"""Solid bonds of a granular job: the bonds alive at the start between simulated spheres, and
their LAMMPS bond types (bpm/rotational coefficients, one per material and binned diameter
and initial length)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import comment_text
from fibrelmp.translate.granular.schedule import RunTime

BOND_BIN_RTOL = 1e-3        # bond types: diameter and L0 binned to 0.1 % (log bins)
BIG = 1e300                 # "never breaks"


@dataclass
class SimulatedBonds:
    rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))    # bonds simulated
    types: list[dict] = field(default_factory=list)      # coefficients of each bond type
    type: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))    # type of each (0-based)
    max_length: float = 0.0          # longest bond (communication cutoff)


def select_bonds(model: GranularModel, run: RunTime, spheres, periodic: np.ndarray,
                 warnings: list[tuple[str, str]]) -> SimulatedBonds:
    """Bonds alive at the start whose spheres are both simulated (``spheres``), typed."""
    bonds = model.bonds
    out = SimulatedBonds()
    if bonds is None or not bonds.count:
        return out
    eps, t_start, keep, x = 0.5 * run.dt, run.t_start, spheres.keep, spheres.x
    pair = bonds.pair.astype(np.int64)
    alive = ((bonds.active_start <= t_start + eps) & (bonds.active_end > t_start + eps)
             & keep[pair[:, 0]] & keep[pair[:, 1]])
    out.rows = bond_rows = np.flatnonzero(alive)
    if np.isfinite(bonds.active_end[bond_rows]).any():
        warnings.append(("bond activity end", "finite bond activity ends in the future are "
                         "ignored: bonds live until they break or a sphere is removed"))
    if len(bond_rows):
        d = bonds.diameter[bond_rows].astype(float)
        L0 = bonds.length0[bond_rows].astype(float)
        if (d <= 0).any() or (L0 <= 0).any():
            raise InputError(model.source, None, "solid bonds need diameter > 0 and initial length > 0")
        bm = bonds.material[bond_rows].astype(np.int64)
        key = np.stack([bm, _tol_bins(d, BOND_BIN_RTOL), _tol_bins(L0, BOND_BIN_RTOL)], 1)
        ukeys, btype = np.unique(key, axis=0, return_inverse=True)
        out.type = btype = btype.reshape(-1)
        for t in range(len(ukeys)):
            sel = btype == t
            out.types.append(_bond_coeffs(model, int(ukeys[t, 0]), float(d[sel].mean()),
                                          float(L0[sel].mean()), int(sel.sum())))
        dist = np.linalg.norm(x[pair[bond_rows, 0]] - x[pair[bond_rows, 1]], axis=1)
        pre = np.abs(dist - L0) > 1e-3 * L0
        if pre.any() and not periodic.any():
            warnings.append(("bond prestress", f"{int(pre.sum())} bond(s) whose sphere distance "
                             "differs from the stored initial length by > 0.1 %: LAMMPS bonds "
                             "start unstressed at the current distance"))
        out.max_length = float(max(L0.max(), dist.max() if not periodic.any() else L0.max()))
    return out


def _tol_bins(values: np.ndarray, rtol: float) -> np.ndarray:
    """Integer bin per value: logarithmic bins of relative width rtol (values > 0)."""
    return np.rint(np.log(values) / math.log1p(rtol)).astype(np.int64)


def _bond_coeffs(model: GranularModel, mat: int, d: float, L0: float, count: int) -> dict:
    m = model.materials[mat]
    E, G = m.youngs, m.shear_modulus
    if not (E > 0 and math.isfinite(E) and G > 0 and math.isfinite(G)):
        raise InputError(model.source, None, f"material '{m.name}' of solid bonds needs Young's "
                         "modulus > 0 and a Poisson ratio in (-1, 0.5]")
    A = math.pi * d * d / 4.0
    I = math.pi * d ** 4 / 64.0
    breakage = int(model.plan.bond_breakage) != 0
    sn = m.normal_strength if breakage and math.isfinite(m.normal_strength) and m.normal_strength > 0 else None
    ts = m.shear_strength if breakage and math.isfinite(m.shear_strength) and m.shear_strength > 0 else None
    return dict(
        kr=E * A / L0, ks=G * A / L0, kt=2.0 * G * I / L0, kb=E * I / L0,
        frc=sn * A if sn else BIG, fsc=ts * A if ts else BIG,
        tbc=sn * math.pi * d ** 3 / 32.0 if sn else BIG,
        ttc=ts * math.pi * d ** 3 / 16.0 if ts else BIG,
        comment=f"{comment_text(m.name)} d={d:.6g} L0={L0:.6g} ({count} bonds)")

