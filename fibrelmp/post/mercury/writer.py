"""MercuryDPM output files from LAMMPS frames: ``.data`` (XBalls), ``.ene`` and ``.fstat``.

Layouts as MercuryDPM's own writers produce them (shared/research/demdf_mercury.md, B):

* ``.data``: per frame a header ``N time xmin ymin zmin xmax ymax zmax `` (trailing space),
  then 14 columns ``x y z vx vy vz radius alpha beta gamma omegax omegay omegaz info`` (3D)
  or, in 2D, header ``N time xmin ymin xmax ymax `` and 8 columns
  ``x y vx vy radius -angleZ -omegaZ info`` (MercuryDPM negates both z rotation columns: its
  2D files show ``-0 -0`` for particles that never rotate).  Positions at precision 15,
  the rest at precision 10.  ``info`` is the species index (LAMMPS type - 1).
* ``.ene``: one header line of labels right-aligned in 16 characters, then per frame
  ``time gravitEnergy traKineticEnergy rotKineticEnergy elasticEnergy comX comY comZ``,
  each value right-aligned in 16 characters, separated by one space.
* ``.fstat``: per frame ``# time 1`` / ``# xmin ymin zmin xmax ymax zmax`` /
  ``# rmin rmax 0 0 0 0``, then one 16-column line per contact side
  ``time i j cx cy cz delta deltat fn ft nx ny nz tx ty tz``: a particle pair twice
  ((i, j, n, t) and (j, i, -n, -t)), a wall contact once with n and t negated and
  ``j = -(wall) - 1``.

Numbers use C++ iostream default formatting at precision 10, which is printf ``%.10g``
(``0``, ``-0``, ``2.060263205e-05``, ``nan``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.textio import format_rows

ENE_LABELS = ("time", "gravitEnergy", "traKineticEnergy", "rotKineticEnergy", "elasticEnergy",
              "centerOfMassX", "centerOfMassY", "centerOfMassZ")
# MercuryDPM writes setw(16) << "label " for each label but the last, which is "label\n"
ENE_HEADER = "".join(f"{lab} ".rjust(16) for lab in ENE_LABELS[:-1]) + f"{ENE_LABELS[-1]}\n".rjust(16)


def g10(x: float) -> str:
    return "%.10g" % x


def euler(q: np.ndarray) -> np.ndarray:
    """MercuryDPM's Quaternion::getEuler (roll, pitch, yaw) of (n, 4) w i j k quaternions."""
    w, i, j, k = q.T
    sinp = 2 * (w * j - k * i)
    pitch = np.where(np.abs(sinp) >= 1, np.copysign(math.pi / 2, sinp),
                     np.arcsin(np.clip(sinp, -1.0, 1.0)))
    roll = np.arctan2(2 * (w * i + j * k), 1 - 2 * (i * i + j * j))
    yaw = np.arctan2(2 * (w * k + i * j), 1 - 2 * (j * j + k * k))
    return np.column_stack([roll, pitch, yaw])


def is_2d(frame: Frame) -> bool:
    """A LAMMPS 2d run: z periodic, every z exactly 0 and no z motion in the frame."""
    if frame.count == 0 or frame.boundary[2] != "pp":
        return False
    x = frame.positions()
    if x is None or np.any(x[:, 2] != 0.0):
        return False
    return not any(c in frame.columns and np.any(frame.columns[c] != 0) for c in ("vz", "fz"))


# -- per-frame quantities ------------------------------------------------------------------
@dataclass
class Particles:
    """One frame in MercuryDPM terms; rows sorted by atom id (= MercuryDPM particle index)."""

    time: float
    ids: np.ndarray
    x: np.ndarray            # (n, 3) positions inside the box
    v: np.ndarray            # (n, 3)
    omega: np.ndarray        # (n, 3)
    radius: np.ndarray | None
    mass: np.ndarray | None
    species: np.ndarray      # (n,) type - 1
    angles: np.ndarray       # (n, 3) Euler angles
    lo: np.ndarray
    hi: np.ndarray


def particles(frame: Frame, time: float) -> Particles:
    n = frame.count
    zeros = np.zeros((n, 3))
    v = frame.vector("vx", "vy", "vz") if frame.has("vx", "vy", "vz") else zeros
    om = frame.vector("omegax", "omegay", "omegaz") if frame.has("omegax", "omegay", "omegaz") else zeros
    q = frame.vector("quatw", "quati", "quatj", "quatk") if frame.has("quatw", "quati", "quatj", "quatk") \
        else None
    return Particles(time, frame.column("id").astype(np.int64), frame.wrapped(), v, om,
                     frame.columns.get("radius"), frame.columns.get("mass"),
                     frame.column("type").astype(np.int64) - 1,
                     euler(q) if q is not None else zeros, frame.lo, frame.hi)


def energies(p: Particles, gravity: np.ndarray, elastic: float) -> list[float]:
    """time, -g.sum(m x), kinetic, rotational (I = 2/5 m r^2), elastic, centre of mass."""
    if p.mass is None:
        raise InputError(None, None, "the .ene energies need per-atom masses: a 'mass' dump column "
                         "or --data")
    m = p.mass
    ekin = 0.5 * float(np.sum(m * np.einsum("ij,ij->i", p.v, p.v)))
    if np.any(p.omega):
        if p.radius is None:
            raise InputError(None, None, "the rotational energy needs radii: a 'radius' dump column or --data")
        erot = 0.5 * float(np.sum(0.4 * m * p.radius ** 2 * np.einsum("ij,ij->i", p.omega, p.omega)))
    else:
        erot = 0.0
    mx = (m[:, None] * p.x).sum(axis=0)
    egrav = -float(np.dot(gravity, mx))      # -0 without gravity, as MercuryDPM prints it
    total = float(m.sum())
    com = mx / total if total > 0 else np.full(3, np.nan)
    return [p.time, egrav, ekin, erot, elastic, *map(float, com)]


# -- contacts from a local dump -------------------------------------------------------------
ALIASES = {
    "id1": ("id1", "patom1", "batom1", "atom1", "i"),
    "id2": ("id2", "patom2", "batom2", "atom2", "j"),
    "fx": ("fx",), "fy": ("fy",), "fz": ("fz",),
    "ftx": ("ftx", "p1"), "fty": ("fty", "p2"), "ftz": ("ftz", "p3"),
    "dx": ("dx", "delx", "p10"), "dy": ("dy", "dely", "p11"), "dz": ("dz", "delz", "p12"),
    "nx": ("nx",), "ny": ("ny",), "nz": ("nz",),
    "cx": ("cx",), "cy": ("cy",), "cz": ("cz",),
    "delta": ("delta", "overlap"), "deltat": ("deltat",), "dist": ("dist",),
    "eng": ("eng", "energy", "elastic"),
}


def local_columns(frame: Frame) -> dict[str, np.ndarray]:
    """Map a local dump's columns (named with dump_modify colname) to canonical names."""
    lower = {k.lower(): k for k in frame.columns}
    out = {}
    for canon, names in ALIASES.items():
        for n in names:
            if n in lower:
                out[canon] = np.asarray(frame.columns[lower[n]], np.float64)
                break
    return out


@dataclass
class Contacts:
    i: np.ndarray            # particle index (row) of side P
    j: np.ndarray            # particle index of side I, or -(wall)-1
    point: np.ndarray        # (m, 3)
    delta: np.ndarray
    deltat: np.ndarray
    fn: np.ndarray           # F.n, F the force on P, n from I to P (positive = repulsive)
    ft: np.ndarray
    n: np.ndarray            # (m, 3)
    t: np.ndarray            # (m, 3) unit tangential force direction, 0 when ft = 0
    energy: float | None


def contacts(local: Frame, p: Particles, bonds: set[tuple[int, int]] | None = None,
             periodic: np.ndarray | None = None, cell: np.ndarray | None = None) -> Contacts:
    c = local_columns(local)
    src = local.source
    for need in ("id1", "id2", "fx", "fy", "fz"):
        if need not in c:
            raise InputError(src, local.line, f"local dump has no column {need!r} (columns: "
                             f"{' '.join(local.columns)}); name them with dump_modify colname, see docs/post.md")
    id1, id2 = c["id1"].astype(np.int64), c["id2"].astype(np.int64)
    if bonds:
        key = np.minimum(id1, id2) * (1 << 32) + np.maximum(id1, id2)
        bonded = np.isin(key, np.fromiter((min(a, b) * (1 << 32) + max(a, b) for a, b in bonds), np.int64))
        keep = ~bonded                        # MercuryDPM skips bonded interactions
        id1, id2 = id1[keep], id2[keep]
        c = {k: v[keep] for k, v in c.items()}
    wall = id2 <= 0
    i = _index(p.ids, id1, src, local.line)
    j = np.where(wall, id2, 0)
    j[~wall] = _index(p.ids, id2[~wall], src, local.line)
    F = np.column_stack([c["fx"], c["fy"], c["fz"]])
    if "ftx" in c:
        F = F + np.column_stack([c["ftx"], c["fty"], c["ftz"]])
    x1 = p.x[i]
    r1 = p.radius[i] if p.radius is not None else None
    m = len(i)
    if "nx" in c:
        n = np.column_stack([c["nx"], c["ny"], c["nz"]])
    else:
        if "dx" in c:
            d = np.column_stack([c["dx"], c["dy"], c["dz"]])
        else:
            d = x1 - p.x[np.where(wall, 0, j)] if len(p.x) else np.zeros((m, 3))
            if periodic is not None and cell is not None and np.any(periodic):
                s = np.linalg.solve(cell, d.T).T          # minimum image
                s[:, periodic] -= np.round(s[:, periodic])
                d = s @ cell.T
        if np.any(wall):                      # no partner position: the normal is the force's
            d[wall] = F[wall]
        length = np.linalg.norm(d, axis=1)
        n = np.divide(d, length[:, None], out=np.zeros_like(d), where=length[:, None] > 0)
        if "dist" not in c:
            c["dist"] = np.where(wall, np.nan, length)
    if "delta" in c:
        delta = c["delta"]
    elif r1 is not None and "dist" in c:
        r2 = np.where(wall, 0.0, p.radius[np.where(wall, 0, j)])
        delta = np.where(wall, r1 - c["dist"], r1 + r2 - c["dist"])
        if np.any(wall & np.isnan(delta)):
            raise InputError(src, local.line, "wall contacts need a 'delta' (overlap) or 'dist' column")
    else:
        raise InputError(src, local.line, "the contact overlap needs a 'delta' column, or radii "
                         "(dump column 'radius' or --data) with positions")
    fn = np.einsum("ij,ij->i", F, n)
    Ft = F - fn[:, None] * n
    ft = np.linalg.norm(Ft, axis=1)
    t = np.divide(Ft, ft[:, None], out=np.zeros_like(Ft), where=ft[:, None] > 0)
    if "cx" in c:
        point = np.column_stack([c["cx"], c["cy"], c["cz"]])
    elif r1 is not None:
        point = x1 - n * (r1 - delta / 2)[:, None]     # middle of the overlap
    else:
        raise InputError(src, local.line, "the contact point needs radii (dump column 'radius' or "
                         "--data) or cx cy cz columns")
    deltat = c.get("deltat", np.zeros(m))
    energy = float(np.sum(c["eng"])) if "eng" in c else None
    return Contacts(i, j, point, delta, deltat, fn, ft, n, t, energy)


def _index(ids: np.ndarray, want: np.ndarray, src, line) -> np.ndarray:
    k = np.searchsorted(ids, want)
    k = np.minimum(k, max(len(ids) - 1, 0))
    bad = (len(ids) == 0) | (ids[k] != want) if len(ids) else np.ones(len(want), bool)
    if np.any(bad):
        raise InputError(src, line, f"contact with atom id {int(want[np.flatnonzero(bad)[0]])}, "
                         "which is not in the matching atom dump frame")
    return k


# -- text ----------------------------------------------------------------------------------
def data_frame_text(p: Particles, dim: int) -> str:
    n = len(p.ids)
    r = p.radius if p.radius is not None else np.zeros(n)
    info = p.species.astype(np.float64)
    if dim == 3:
        head = " ".join([str(n), g10(p.time)] + [g10(v) for v in (*p.lo, *p.hi)]) + " \n"
        cols = [p.x[:, 0], p.x[:, 1], p.x[:, 2], p.v[:, 0], p.v[:, 1], p.v[:, 2], r,
                p.angles[:, 0], p.angles[:, 1], p.angles[:, 2],
                p.omega[:, 0], p.omega[:, 1], p.omega[:, 2], info]
        fmt = "%.15g %.15g %.15g" + " %.10g" * 11 + "\n"
    else:
        head = " ".join([str(n), g10(p.time)] + [g10(v) for v in (p.lo[0], p.lo[1], p.hi[0], p.hi[1])]) + " \n"
        cols = [p.x[:, 0], p.x[:, 1], p.v[:, 0], p.v[:, 1], r, -p.angles[:, 2], -p.omega[:, 2], info]
        fmt = "%.15g %.15g" + " %.10g" * 6 + "\n"
    return head + format_rows(fmt, cols)


def ene_line(values: list[float]) -> str:
    return " ".join(g10(v).rjust(16) for v in values) + "\n"


def fstat_frame_text(time: float, p: Particles, c: Contacts | None) -> str:
    r = p.radius
    rmin, rmax = (float(r.min()), float(r.max())) if r is not None and len(r) else (math.nan, math.nan)
    head = (f"# {g10(time)} 1\n# " + " ".join(g10(v) for v in (*p.lo, *p.hi)) +
            f"\n# {g10(rmin)} {g10(rmax)} 0 0 0 0\n")
    if c is None or len(c.i) == 0:
        return head
    wall = c.j < 0
    pair = ~wall
    # particle pairs: (P, I, n, t) then (I, P, -n, -t); walls once with -n, -t
    i = np.concatenate([c.i[pair], c.j[pair], c.i[wall]])
    j = np.concatenate([c.j[pair], c.i[pair], c.j[wall]])
    sign = np.concatenate([np.ones(pair.sum()), -np.ones(pair.sum()), -np.ones(wall.sum())])
    take = np.concatenate([np.flatnonzero(pair), np.flatnonzero(pair), np.flatnonzero(wall)])
    # interleave each pair's two lines as MercuryDPM does
    npair = int(pair.sum())
    order = np.concatenate([np.column_stack([np.arange(npair), np.arange(npair) + npair]).ravel(),
                            np.arange(2 * npair, 2 * npair + int(wall.sum()))])
    i, j, sign, take = i[order], j[order], sign[order], take[order]
    n = c.n[take] * sign[:, None]
    t = c.t[take] * sign[:, None]
    cols = [np.full(len(i), time), i, j, c.point[take, 0], c.point[take, 1], c.point[take, 2],
            c.delta[take], c.deltat[take], c.fn[take], c.ft[take], n[:, 0], n[:, 1], n[:, 2],
            t[:, 0], t[:, 1], t[:, 2]]
    return head + format_rows("%.10g %d %d" + " %.10g" * 13 + "\n", cols)


# -- writer --------------------------------------------------------------------------------
@dataclass
class MercuryFrame:
    """One frame for ``MercuryWriter``: the dump frame, its time and its contacts (a frame of
    a local dump, or None)."""

    frame: Frame
    time: float
    local: Frame | None = None


class MercuryWriter(Writer):
    """``<base>.data`` + ``<base>.ene`` (+ ``<base>.fstat`` when contacts are given)."""

    format = "mercury"

    def __init__(self, base: Path, gravity: np.ndarray, fstat: bool, dim: int | None = None,
                 bonds: set[tuple[int, int]] | None = None, *, force: bool = True):
        self.fstat = fstat
        super().__init__(base, force=force)
        self.gravity = np.asarray(gravity, float)
        self.dim = dim
        self.bonds = bonds
        self.no_elastic = False

    def file(self, ext: str) -> Path:
        return self.target.with_name(self.target.name + ext)

    def outputs(self) -> list[Path]:
        return [self.file(e) for e in (".data", ".ene", ".fstat")[:3 if self.fstat else 2]]

    def write(self, item: MercuryFrame) -> None:
        frame, time = item.frame, item.time
        if self.count == 0:
            self.open(self.file(".data"), "w")
            self.open(self.file(".ene"), "w").write(ENE_HEADER)
        if self.dim is None:
            self.dim = 2 if is_2d(frame) else 3
        p = particles(frame, time)
        self.open(self.file(".data"), "w").write(data_frame_text(p, self.dim))
        c = None
        if item.local is not None:
            c = contacts(item.local, p, self.bonds, frame.periodic, frame.cell)
        elastic = c.energy if c is not None and c.energy is not None else 0.0
        if c is None or c.energy is None:
            self.no_elastic = True
        try:
            line = ene_line(energies(p, self.gravity, elastic))
        except InputError as exc:
            raise InputError(frame.source, frame.line, exc.message) from None
        self.open(self.file(".ene"), "w").write(line)
        if self.fstat:
            self.open(self.file(".fstat"), "w").write(fstat_frame_text(time, p, c))
