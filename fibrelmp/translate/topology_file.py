"""FibreNet jobs' binary topology file (``topology.bin``), read by the plugin command
``fibrenet/read_data`` instead of ``read_data data.lammps``.

``read_data`` parses every line on every MPI rank and reads bonds and angles twice (a first
pass counts them per atom): 13.5 s of a 63 s run of 2.6M beads on 2 ranks.  The same box,
masses, atoms, bonds and angles as fixed-size binary records are read once, on rank 0, and
broadcast (docs/performance.md).  ``data.lammps`` is still written: it is what ``fibrelmp post
--data`` and people read.

Layout (little-endian; fibrelmp/lammps_styles/src/fibrenet_read_data.h reads it):

    char[8] "FLMPTOP1"
    int64   natoms nbonds nangles ntypes nbondtypes nangletypes has_velocities
            bond_per_atom angle_per_atom bond_per_atom_off angle_per_atom_off
    double  xlo xhi ylo yhi zlo zhi
    double  mass[ntypes]
    natoms  x {int64 id molecule type; double x y z; (has_velocities) double vx vy vz}
    nbonds  x {int64 type atom1 atom2}
    nangles x {int64 type atom1 atom2 atom3}

Ids are 1..natoms in order; a bond is stored with its first atom and an angle with its middle
atom (newton_bond on; with it off, with every atom of it), so bond_per_atom / angle_per_atom
(_off) are the most any atom stores.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from fibrelmp.textio import atomic_write

MAGIC = b"FLMPTOP1"


def _most(ids: np.ndarray) -> int:
    """The most times any id occurs."""
    return int(np.bincount(ids).max()) if len(ids) else 0


def topology_bytes(box: Sequence[tuple[float, float]], masses: Sequence[float], molecules: np.ndarray,
                   types: np.ndarray, x: np.ndarray, v: np.ndarray | None, bonds: np.ndarray,
                   bond_types: np.ndarray, nbond_types: int, angles: np.ndarray,
                   angle_types: np.ndarray, nangle_types: int) -> list:
    """The file's bytes, as parts to write in turn.  ``types``, ``bond_types``, ``angle_types`` are 1-based LAMMPS types;
    ``bonds`` (nb, 2) and ``angles`` (na, 3) hold 1-based atom ids; ``v`` None: all at rest."""
    n = len(types)
    fields = [("id", "<i8"), ("molecule", "<i8"), ("type", "<i8"), ("x", "<f8", 3)]
    if v is not None:
        fields.append(("v", "<f8", 3))
    atoms = np.empty(n, np.dtype(fields))
    atoms["id"] = np.arange(1, n + 1)
    atoms["molecule"] = molecules
    atoms["type"] = types
    atoms["x"] = x
    if v is not None:
        atoms["v"] = v
    bond_rows = np.column_stack([bond_types, bonds]).astype("<i8") if len(bonds) else np.zeros((0, 3), "<i8")
    angle_rows = np.column_stack([angle_types, angles]).astype("<i8") if len(angles) else np.zeros((0, 4), "<i8")
    head = np.array([n, len(bond_rows), len(angle_rows), len(masses), nbond_types, nangle_types,
                     int(v is not None), _most(bond_rows[:, 1]), _most(angle_rows[:, 2]),
                     _most(bond_rows[:, 1:].ravel()), _most(angle_rows[:, 1:].ravel())], "<i8")
    bounds = np.array([b for pair in box for b in pair], "<f8")
    return [MAGIC, head.tobytes(), bounds.tobytes(), np.asarray(masses, "<f8").tobytes(),
            atoms.view(np.uint8), bond_rows.view(np.uint8), angle_rows.view(np.uint8)]


def write_topology_file(path: Path, *args, **kwargs) -> None:
    """``topology_bytes(*args, **kwargs)`` written atomically to ``path`` (part by part)."""
    atomic_write(path, topology_bytes(*args, **kwargs))
