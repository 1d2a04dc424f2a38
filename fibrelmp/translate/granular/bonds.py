"""Solid bonds of a granular job: the bonds alive at the start between simulated spheres, and
their LAMMPS bond types.

With fibrelmp's LAMMPS styles (``exact``): ``bond_style musen/elastic``, MUSEN's elastic or
Kelvin bond and its breakage criteria; one bond type per bond material (E, G, strengths,
viscosity) and each bond's own diameter, initial length and initial tangential overlap in
per-atom arrays (``fix property/atom``, set from the atomfile ``bond_geometry.txt`` beside the
data file) on the atom that stores it, the bond's first (MUSEN "left") sphere.

Without them: stock ``bond_style bpm/rotational`` coefficients, one type per material and
binned diameter and initial length, an approximation of MUSEN's law that says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import comment_text
from fibrelmp.translate.granular.schedule import RunTime

BOND_BIN_RTOL = 1e-3        # stock bond types: diameter and L0 binned to 0.1 % (log bins)
BIG = 1e300                 # "never breaks"
GEOMETRY_NAME = "bond_geometry.txt"  # per-atom bond geometry (LAMMPS atomfile blocks)
GEOMETRY_FIX = "fl_bgeom"           # their fix property/atom IDs fl_bgeom1..K
PARTNERS, VALUES = "fl_bp", "fl_bv"  # their per-atom values i_fl_bpk, d2_fl_bvk


@dataclass
class BondGeometry:
    """Per-atom slots for ``musen/elastic geometry``: for each LAMMPS atom (row of the data
    file's atoms, in order) the partner ids of up to K bonds it stores (0: none) and, for
    each, d, L0 [and the initial tangential overlap, 3].  One ``fix property/atom`` per slot
    (the slots were data-file sections once, whose lines read_data cuts at 256 characters)."""
    partners: np.ndarray             # (natoms, K) int
    values: np.ndarray               # (natoms, K, width)
    width: int                       # 2 (d L0) or 5 (d L0 overlap)

    @property
    def slots(self) -> int:
        return self.partners.shape[1]


@dataclass
class SimulatedBonds:
    rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))    # bonds simulated
    types: list[dict] = field(default_factory=list)      # coefficients of each bond type
    type: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))    # type of each (0-based)
    max_length: float = 0.0          # longest bond (communication cutoff)
    exact: bool = False              # musen/elastic (types: per material) or bpm/rotational
    # musen/elastic: LAMMPS bond type (1-based) of each bond material, the generated
    # agglomerates' included
    type_of_material: dict[int, int] = field(default_factory=dict)


def select_bonds(model: GranularModel, run: RunTime, spheres, periodic: np.ndarray,
                 warnings: list[tuple[str, str]], exact: bool = False) -> SimulatedBonds:
    """Bonds alive at the start whose spheres are both simulated (``spheres``), typed:
    ``exact`` for ``musen/elastic`` (fibrelmp's styles), else for stock ``bpm/rotational``."""
    from fibrelmp.translate.granular.inlets import inlet_bond_materials

    bonds = model.bonds
    out = SimulatedBonds(exact=exact)
    generated = inlet_bond_materials(model)       # the bonds of generated agglomerates
    if generated and not exact:
        raise InputError(model.source, None, "generated agglomerates' solid bonds need fibrelmp's "
                         "LAMMPS styles (bond_style musen/elastic, fix musen/inlet)")
    if generated:          # bond types of the generated bonds' materials (none alive yet)
        out.type_of_material = {m: t + 1 for t, m in enumerate(generated)}
        out.types = [_musen_coeffs(model, m, 0) for m in generated]
    if bonds is None or not bonds.count:
        return out
    eps, t_start, keep, x = 0.5 * run.dt, run.t_start, spheres.keep, spheres.x
    pair = bonds.pair.astype(np.int64)
    keep_all = np.r_[keep, np.zeros(max(0, int(pair.max(initial=-1)) + 1 - len(keep)), bool)]
    alive = ((bonds.active_start <= t_start + eps) & (bonds.active_end > t_start + eps)
             & keep_all[pair[:, 0]] & keep_all[pair[:, 1]])
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
        dist = np.linalg.norm(x[pair[bond_rows, 0]] - x[pair[bond_rows, 1]], axis=1)
        _refuse_coincident(model, bond_rows, dist)
        out.max_length = float(max(L0.max(), dist.max() if not periodic.any() else L0.max()))
        if exact:
            mats = np.union1d(np.unique(bm), np.array(generated, np.int64))
            btype = np.searchsorted(mats, bm)
            out.type = btype.reshape(-1)
            out.types = [_musen_coeffs(model, int(m), int((bm == m).sum())) for m in mats]
            out.type_of_material = {int(m): t + 1 for t, m in enumerate(mats)}
            return out
        if model.plan.bond_law.form != "elastic" or model.plan.then_bond_laws:
            form = "kelvin" if model.plan.bond_laws_use("kelvin") else "several-model"
            raise InputError(model.source, None, f"MUSEN's {form} solid bond "
                             "needs fibrelmp's LAMMPS styles (bond_style musen/elastic), which "
                             "are not used here; stock LAMMPS has no equivalent")
        breaking = ("LAMMPS bpm/rotational breaks on the sum of four load ratios, not MUSEN's "
                    "two criteria (normal stress or tangential stress); "
                    if int(model.plan.bond_breakage) else "")
        warnings.append(("approximate MUSEN physics", f"solid bonds: {breaking}bond_style "
                         "bpm/rotational bins diameters and initial lengths to 0.1 % and bends "
                         "and twists with the total rotation (Wang 2009), not MUSEN's "
                         "incremental law (docs/granular.md)"))
        key = np.stack([bm, _tol_bins(d, BOND_BIN_RTOL), _tol_bins(L0, BOND_BIN_RTOL)], 1)
        ukeys, btype = np.unique(key, axis=0, return_inverse=True)
        out.type = btype = btype.reshape(-1)
        for t in range(len(ukeys)):
            sel = btype == t
            out.types.append(_bond_coeffs(model, int(ukeys[t, 0]), float(d[sel].mean()),
                                          float(L0[sel].mean()), int(sel.sum())))
        pre = np.abs(dist - L0) > 1e-3 * L0
        if pre.any() and not periodic.any():
            warnings.append(("bond prestress", f"{int(pre.sum())} bond(s) whose sphere distance "
                             "differs from the stored initial length by > 0.1 %: LAMMPS bonds "
                             "start unstressed at the current distance"))
    return out


def check_bond_directions(model: GranularModel) -> None:
    """Refuse a bond alive at the start between two spheres at one position (before anything
    is locked or written; ``select_bonds`` checks the bonds it simulates again)."""
    bonds, sp = model.bonds, model.spheres
    if bonds is None or not bonds.count:
        return
    t = model.plan.t_start
    rows = np.flatnonzero((bonds.active_start <= t) & (bonds.active_end > t))
    pair = bonds.pair[rows].astype(np.int64)
    x = np.asarray(sp.position, float)
    _refuse_coincident(model, rows, np.linalg.norm(x[pair[:, 0]] - x[pair[:, 1]], axis=1))


def _refuse_coincident(model: GranularModel, bond_rows: np.ndarray, dist: np.ndarray) -> None:
    """A bond between two spheres at one position has no direction: MUSEN's bond law divides
    by the zero length and every value of both spheres and the bond turns to nan (the real
    cmusen 1.74.2 does), so such a scene is refused."""
    same = np.flatnonzero(dist == 0)
    if not len(same):
        return
    b, row = model.bonds, int(bond_rows[same[0]])
    line = int(b.source_line[row]) if b.source_line is not None else None
    left, right = (int(model.spheres.ids[k]) for k in b.pair[row])
    more = f" (and {len(same) - 1} more)" if len(same) > 1 else ""
    raise InputError(model.source, line, f"solid bond {int(b.ids[row])} joins spheres {left} and "
                     f"{right}, which are at the same position{more}: the bond has no direction "
                     "(MUSEN's bond law divides by its zero length and gives nan); move one sphere")


def bond_geometry(model: GranularModel, bonds: SimulatedBonds, atom_rows: np.ndarray,
                  natoms: int, min_slots: int = 1) -> BondGeometry:
    """The per-atom bond geometry of the data file's ``natoms`` atoms; the first
    ``len(atom_rows)`` are the spheres ``atom_rows`` (LAMMPS id = sphere row + 1).  At least
    ``min_slots`` slots (generated agglomerates' bonds on one sphere)."""
    b = model.bonds
    rows = bonds.rows
    if b is None or not len(rows):          # only generated bonds (fix musen/inlet sets them)
        return BondGeometry(np.zeros((natoms, min_slots), np.int64), np.zeros((natoms, min_slots, 2)), 2)
    left = b.pair[rows, 0].astype(np.int64)
    right = b.pair[rows, 1].astype(np.int64)
    where = np.full(int(max(atom_rows.max(initial=-1), left.max(initial=-1))) + 1, -1, np.int64)
    where[atom_rows] = np.arange(len(atom_rows))
    atom = where[left]                                   # data-file atom storing each bond
    order = np.argsort(atom, kind="stable")
    atom_sorted = atom[order]
    first = np.searchsorted(atom_sorted, atom_sorted)    # slot = rank within the atom's bonds
    slot = np.empty(len(rows), np.int64)
    slot[order] = np.arange(len(rows)) - first
    K = max(int(slot.max()) + 1 if len(rows) else 1, min_slots)
    overlap = b.tangential_overlap
    width = 5 if overlap is not None and np.any(overlap[rows]) else 2
    partners = np.zeros((natoms, K), np.int64)
    values = np.zeros((natoms, K, width))
    partners[atom, slot] = right + 1
    values[atom, slot, 0] = b.diameter[rows]
    values[atom, slot, 1] = b.length0[rows]
    if width == 5:
        values[atom, slot, 2:] = overlap[rows]
    return BondGeometry(partners, values, width)


def _musen_coeffs(model: GranularModel, mat: int, count: int) -> dict:
    """bond_coeff of musen/elastic for the bonds of material ``mat``: E G sigma_n tau_s mu
    [yield Y] (SimplifiedScene::AddSolidBond: NormalStiffness = E, TangentialStiffness = G =
    E/(2(1+nu)), strengths, the compound's dynamic viscosity and, for the plastic and creep
    laws, its yield strength)."""
    m = model.materials[mat]
    E, G = m.youngs, m.shear_modulus
    if not (E > 0 and math.isfinite(E) and G > 0 and math.isfinite(G)):
        raise InputError(model.source, None, f"material '{m.name}' of solid bonds needs Young's "
                         "modulus > 0 and a Poisson ratio in (-1, 0.5]")
    mu = 0.0
    if model.plan.bond_laws_use("kelvin"):
        mu = m.props.get(2, float("nan"))
        if not (math.isfinite(mu) and mu >= 0):
            raise InputError(model.source, None, f"material '{m.name}' of solid bonds needs a "
                             "dynamic viscosity >= 0 (property 2), which MUSEN's Kelvin bond uses")

    ys = None
    if model.plan.bond_laws_need_yield():
        ys = m.props.get(15, float("nan"))
        if not (math.isfinite(ys) and ys >= 0):
            raise InputError(model.source, None, f"material '{m.name}' of solid bonds needs a "
                             "yield strength >= 0 (property 15), which MUSEN's plastic and creep "
                             "bonds use")

    def strength(value: float) -> float:
        return value if math.isfinite(value) else BIG
    return dict(E=E, G=G, sn=strength(m.normal_strength), ts=strength(m.shear_strength), mu=mu,
                ys=ys, comment=f"{comment_text(m.name)} ({count} bonds)")


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

