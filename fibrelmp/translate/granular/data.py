"""The data file of a granular job: spheres and wall particles (atom style bpm/sphere), their
velocities, and the solid bonds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.lammps_text import comment_text
from fibrelmp.textio import atomic_write
from fibrelmp.translate.granular.bonds import GEOMETRY_SECTION
from fibrelmp.translate.lammps_format import data_rows, float_text


def write_data(model, path: Path, rows, type_of_mat, smat, crad, lo, hi, ntypes,
               tx, ttype, tv, tids, tile_radius, tile_mass, bond_rows, btype, nbtypes,
               geometry=None) -> None:
    """``geometry`` (bonds.BondGeometry, or None): the per-atom bond geometry sections
    BondGeometry1..K that ``read_data … fix fl_bgeomk NULL BondGeometryk`` hands to fix
    property/atom (one line per atom, in the Atoms section's order)."""
    sp = model.spheres
    n = len(rows) + len(tx)
    parts = [f"LAMMPS data file written by fibrelmp from {comment_text(model.source.name)}\n\n",
             f"{n} atoms\n{ntypes} atom types\n"]
    if len(bond_rows):
        parts.append(f"{len(bond_rows)} bonds\n{nbtypes} bond types\n")
    parts.append("\n")
    for a, name in enumerate("xyz"):
        parts.append(f"{float_text(lo[a])} {float_text(hi[a])} {name}lo {name}hi\n")
    r = crad[rows]
    # LAMMPS sets rmass = 4/3 pi r^3 density (also in 2D): density chosen to give the mass
    dens = sp.mass[rows] / (4.0 * math.pi / 3.0 * r * r * r)
    ids = rows + 1
    lut = np.zeros(max(type_of_mat, default=0) + 1, np.int64)
    for mat, t in type_of_mat.items():
        lut[mat] = t
    types = lut[smat]
    x = sp.position[rows]
    if len(tx):
        ids = np.r_[ids, tids]
        types = np.r_[types, ttype]
        diam = np.r_[2.0 * r, np.full(len(tx), 2.0 * tile_radius)]
        dens = np.r_[dens, np.full(len(tx), tile_mass / (4.0 * math.pi / 3.0 * tile_radius ** 3))]
        x = np.vstack([x, tx])
    else:
        diam = 2.0 * r
    parts.append("\nAtoms # bpm/sphere\n\n")
    parts.append(data_rows("%d 0 %d %.17g %.17g %.17g %.17g %.17g\n",
                        [ids, types, diam, dens, x[:, 0], x[:, 1], x[:, 2]]))
    v = sp.velocity[rows]
    w = sp.omega[rows]
    if len(tx):
        v = np.vstack([v, tv])
        w = np.vstack([w, np.zeros_like(tv)])
    parts.append("\nVelocities\n\n")
    parts.append(data_rows("%d %.17g %.17g %.17g %.17g %.17g %.17g\n",
                        [ids, v[:, 0], v[:, 1], v[:, 2], w[:, 0], w[:, 1], w[:, 2]]))
    if len(bond_rows):
        b = model.bonds.pair[bond_rows].astype(np.int64) + 1
        parts.append("\nBonds\n\n")
        parts.append(data_rows("%d %d %d %d\n", [np.arange(1, len(b) + 1), btype + 1, b[:, 0], b[:, 1]]))
        if geometry is not None:
            for k in range(geometry.slots):
                cols = [ids, geometry.partners[:, k]] + [geometry.values[:, k, c] for c in range(geometry.width)]
                parts.append(f"\n{GEOMETRY_SECTION}{k + 1}\n\n")
                parts.append(data_rows("%d %d" + " %.17g" * geometry.width + "\n", cols))
    atomic_write(path, "".join(parts))
