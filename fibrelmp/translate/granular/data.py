"""The data file of a granular job: spheres and wall particles (atom style bpm/sphere), their
velocities, and the solid bonds; the per-atom bond geometry of fibrelmp's bond style goes
beside it (``bond_geometry.txt``, LAMMPS atomfile blocks), so the data file stays one every
reader of data files reads."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.lammps_text import comment_text
from fibrelmp.textio import atomic_write
from fibrelmp.translate.granular.bonds import GEOMETRY_NAME, PARTNERS, VALUES
from fibrelmp.translate.lammps_data import DataSection, write_data_file
from fibrelmp.translate.lammps_format import atomfile_blocks


def write_data(model, path: Path, rows, type_of_mat, smat, crad, lo, hi, ntypes,
               tx, ttype, tv, tids, tile_radius, tile_mass, bond_rows, btype, nbtypes,
               geometry=None, generated: tuple[int, int] = (0, 0)) -> None:
    """``geometry`` (bonds.BondGeometry, or None): the per-atom bond geometry, written to
    ``GEOMETRY_NAME`` beside the data file as atomfile blocks: per slot k the partner ids
    (i_fl_bpk), then each column c of d2_fl_bvk[c], in the order the script sets them."""
    sp = model.spheres
    n = len(rows) + len(tx)
    counts = [(n, "atoms"), (ntypes, "atom types")]
    if len(bond_rows):
        counts += [(len(bond_rows), "bonds"), (nbtypes, "bond types")]
    elif generated[0]:
        counts += [(nbtypes, "bond types")]
    if generated[0]:        # room for the bonds of generated agglomerates (fix musen/inlet)
        counts += [(generated[0], "extra bond per atom"), (generated[1], "extra special per atom")]
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
    v = sp.velocity[rows]
    w = sp.omega[rows]
    if len(tx):
        v = np.vstack([v, tv])
        w = np.vstack([w, np.zeros_like(tv)])
    sections = [DataSection("Atoms # bpm/sphere", "%d 0 %d %.17g %.17g %.17g %.17g %.17g\n",
                            [ids, types, diam, dens, x[:, 0], x[:, 1], x[:, 2]]),
                DataSection("Velocities", "%d %.17g %.17g %.17g %.17g %.17g %.17g\n",
                            [ids, v[:, 0], v[:, 1], v[:, 2], w[:, 0], w[:, 1], w[:, 2]])]
    if len(bond_rows):
        b = model.bonds.pair[bond_rows].astype(np.int64) + 1
        sections.append(DataSection("Bonds", "%d %d %d %d\n",
                                    [np.arange(1, len(b) + 1), btype + 1, b[:, 0], b[:, 1]]))
    write_data_file(path, f"LAMMPS data file written by fibrelmp from {comment_text(model.source.name)}",
                    counts, list(zip(lo, hi)), sections)
    if geometry is not None and geometry.slots and len(geometry.partners):
        columns = []
        for k in range(geometry.slots):
            columns.append((f"i_{PARTNERS}{k + 1}", geometry.partners[:, k].astype(np.int64)))
            columns += [(f"d2_{VALUES}{k + 1}[{c + 1}]", geometry.values[:, k, c].astype(np.float64))
                        for c in range(geometry.width)]
        title = ("fibrelmp: each bond's partner id, diameter, initial length [, initial tangential\n"
                 "overlap] on its first sphere, read by in.lammps as 'variable fl_bgeom atomfile':\n"
                 "a block per per-atom array column (a count, then 'atom-id value' lines); atoms not\n"
                 "listed are 0")
        atomic_write(path.with_name(GEOMETRY_NAME), atomfile_blocks(ids, columns, title))
