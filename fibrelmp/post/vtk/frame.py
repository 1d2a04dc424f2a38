"""One frame as the 3D viewers get it (``ViewerFrame``), and the geometry the writer needs:
positions wrapped into the periodic box, bonds split where they cross a periodic face.

A frame comes from a LAMMPS dump frame (``from_dump``: ``post --to vtk``, FibreNet runs) or
from a run's own frames (``fibrelmp.post.vtk.run_output``).  Point arrays carry the names OVITO
gives its standard particle properties (``Radius``, ``Velocity``, ``Force``, ``Orientation``,
...), so OVITO maps them on import and ParaView shows the same names.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fibrelmp.post.lammps_dump.reader import Frame

# viewer array -> dump columns (quaternions in OVITO's (X, Y, Z, W) order, LAMMPS's is w i j k)
VECTORS = {"Velocity": ("vx", "vy", "vz"), "Force": ("fx", "fy", "fz"),
           "Angular Velocity": ("omegax", "omegay", "omegaz"),
           "Angular Momentum": ("angmomx", "angmomy", "angmomz"), "Torque": ("tqx", "tqy", "tqz"),
           "Orientation": ("quati", "quatj", "quatk", "quatw")}
SCALARS = {"Radius": "radius", "Mass": "mass",
           "temperature": "d_musen_temperature"}     # fibrelmp's MUSEN heat models (K)
# columns that are not per-atom data for a viewer (positions, images, the integer fields)
SKIP = {"x", "y", "z", "xs", "ys", "zs", "xu", "yu", "zu", "xsu", "ysu", "zsu", "ix", "iy", "iz",
        "id", "type"}


@dataclass
class ViewerFrame:
    """A frame's particles (rows in any order), their bonds (atom-id pairs) and the box."""

    step: int
    time: float
    ids: np.ndarray                    # (n,) int64
    positions: np.ndarray              # (n,3)
    origin: np.ndarray                 # (3,) box corner
    cell: np.ndarray                   # (3,3) edge vectors as columns
    periodic: np.ndarray               # (3,) bool
    point_data: dict[str, np.ndarray] = field(default_factory=dict)   # (n,) or (n,k)
    bonds: np.ndarray | None = None    # (m,2) atom ids
    bond_data: dict[str, np.ndarray] = field(default_factory=dict)    # (m,) or (m,k)
    walls: np.ndarray | None = None    # (k,3,3) wall triangles' vertices (MUSEN geometries)
    wall_data: dict[str, np.ndarray] = field(default_factory=dict)    # (k,) or (k,j)


def box_of(lo, hi, periodic, tilt=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin, cell, periodic) of a box given by its corners (and LAMMPS tilt factors)."""
    lx, ly, lz = np.asarray(hi, float) - np.asarray(lo, float)
    xy, xz, yz = tilt if tilt is not None else (0.0, 0.0, 0.0)
    cell = np.array([[lx, xy, xz], [0.0, ly, yz], [0.0, 0.0, lz]])
    return np.asarray(lo, float), cell, np.asarray(periodic, bool)


def wrap(x: np.ndarray, origin: np.ndarray, cell: np.ndarray, periodic: np.ndarray) -> np.ndarray:
    """Positions moved into the box on periodic axes by whole box vectors (atoms inside keep
    their coordinates bit for bit; LAMMPS lets atoms stray out until it re-neighbours)."""
    if not periodic.any() or len(x) == 0:
        return x
    s = np.linalg.solve(cell, (x - origin).T).T
    shift = np.where(periodic, np.floor(s), 0.0)
    if not shift.any():
        return x
    return x - shift @ cell.T


def from_dump(frame: Frame, bonds: np.ndarray | None = None, time: float | None = None) -> ViewerFrame:
    """The viewer frame of a dump frame: id, type, the ``VECTORS``/``SCALARS`` it has under
    their viewer names, every other numeric column as a scalar under its own name; ``bonds``
    (atom-id pairs, e.g. from ``--data``); ``time``: default the frame's, else its step."""
    origin, cell, periodic = box_of(frame.lo, frame.hi, frame.periodic, frame.tilt)
    x = frame.wrapped()
    ids = np.asarray(frame.column("id")).astype(np.int64)
    data: dict[str, np.ndarray] = {}
    if "type" in frame.columns and np.asarray(frame.columns["type"]).dtype.kind in "fiu":
        data["type"] = np.asarray(frame.columns["type"]).astype(np.int32)
    used = set(SKIP)
    for name, col in SCALARS.items():
        if frame.has(col):
            data[name] = np.asarray(frame.columns[col], np.float64)
            used.add(col)
    for name, cols in VECTORS.items():
        if frame.has(*cols):
            data[name] = frame.vector(*cols)
            used.update(cols)
    for name, col in frame.columns.items():
        if name not in used and np.asarray(col).dtype.kind in "fiu":
            data[name] = np.asarray(col, np.float64)
    if time is None:
        time = float(frame.step) if frame.time is None else frame.time
    return ViewerFrame(frame.step, time, ids, wrap(x, origin, cell, periodic), origin, cell,
                       periodic, data, bonds)


def bond_rows(ids: np.ndarray, bonds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2) point rows of the bonds whose atoms are both in the frame, and those bonds'
    indices into ``bonds``."""
    if bonds is None or len(bonds) == 0 or len(ids) == 0:
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    order = np.argsort(ids, kind="stable")
    sorted_ids = ids[order]
    k = np.minimum(np.searchsorted(sorted_ids, bonds), len(ids) - 1)
    found = np.all(sorted_ids[k] == bonds, axis=1)
    return order[k[found]], np.flatnonzero(found)


@dataclass
class Segments:
    """Bond pieces to draw: a bond inside the box is one piece; one that crosses periodic
    faces is cut there into pieces that each end on the face (its minimum image)."""

    start: np.ndarray        # (p,3)
    end: np.ndarray          # (p,3)
    bond: np.ndarray         # (p,) index of the bond each piece belongs to


def bond_segments(xa: np.ndarray, xb: np.ndarray, origin: np.ndarray, cell: np.ndarray,
                  periodic: np.ndarray) -> Segments:
    """The pieces of the bonds ``xa[i]``-``xb[i]`` (wrapped positions).  Along the minimum
    image vector d, the bond crosses a periodic face where a fractional coordinate passes
    0 or 1; between crossings each piece is moved back into the box by whole box vectors.
    Ends at the atoms are the atoms' positions; ends on a face lie exactly on it."""
    m = len(xa)
    if m == 0:
        return Segments(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, np.int64))
    sa = np.linalg.solve(cell, (xa - origin).T).T
    sb = np.linalg.solve(cell, (xb - origin).T).T
    image = np.where(periodic, np.round(sb - sa), 0.0)       # b's image nearest to a
    ds = sb - image - sa
    with np.errstate(divide="ignore", invalid="ignore"):
        face = np.where(ds > 0, 1.0, 0.0)
        t_cross = (face - sa) / ds                             # where each axis meets its face
    crosses = periodic & (ds != 0) & (t_cross > 0) & (t_cross < 1)
    t_cross = np.where(crosses, t_cross, np.nan)
    bounds = np.sort(np.column_stack([np.zeros(m), t_cross, np.ones(m)]), axis=1)   # nan last
    t0, t1 = bounds[:, :-1], bounds[:, 1:]
    bond, piece = np.nonzero(np.isfinite(t1))
    t0, t1 = t0[bond, piece], t1[bond, piece]
    s0 = sa[bond] + t0[:, None] * ds[bond]
    s1 = sa[bond] + t1[:, None] * ds[bond]
    shift = np.where(periodic, np.floor(0.5 * (s0 + s1)), 0.0)  # the piece's way into the box
    s0 -= shift
    s1 -= shift
    tc = t_cross[bond]
    s0 = np.where(t0[:, None] == tc, np.round(s0), s0)          # on the face it crosses
    s1 = np.where(t1[:, None] == tc, np.round(s1), s1)
    start = origin + s0 @ cell.T
    end = origin + s1 @ cell.T
    at_a, at_b = t0 == 0, t1 == 1
    start[at_a] = xa[bond[at_a]] - shift[at_a] @ cell.T         # the atoms themselves
    end[at_b] = xb[bond[at_b]] - (image[bond[at_b]] + shift[at_b]) @ cell.T
    return Segments(start, end, bond)
