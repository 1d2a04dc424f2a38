"""MercuryDPM output files from LAMMPS frames: ``.data`` (XBalls), ``.ene``, ``.fstat`` and
``.restart`` (``DPMBase::write``'s layout: what MercuryCG reads, docs/post.md).

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
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

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
    quaternion: np.ndarray | None = None     # (n, 4) w i j k
    force: np.ndarray | None = None          # (n, 3)


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
                     euler(q) if q is not None else zeros, frame.lo, frame.hi, q,
                     frame.vector("fx", "fy", "fz") if frame.has("fx", "fy", "fz") else None)


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
            if periodic is not None and cell is not None:
                d = _minimum_image(d, periodic, cell)
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


# per-atom wall contacts in the atom dump: fibrelmp's work dumps name them v_w<k>_fx..v_w<k>_cz
# (fix wall/gran/region's force on the sphere and its contact point on the wall), a user's
# dump can name them wall<k>_fx..wall<k>_cz with dump_modify colname
WALL_COLUMN = re.compile(r"(?:v_w|wall)([1-9][0-9]*)_([fc])([xyz])")


def wall_columns(frame: Frame) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Wall number k (from 1) -> (force on each atom (n, 3), contact point on the wall (n, 3))
    of an atom frame's wall-contact columns; a wall needs all six columns."""
    found: dict[int, dict[str, np.ndarray]] = {}
    for name, values in frame.columns.items():
        m = WALL_COLUMN.fullmatch(name)
        if m:
            found.setdefault(int(m.group(1)), {})[m.group(2) + m.group(3)] = np.asarray(values, np.float64)
    out = {}
    for k, cols in sorted(found.items()):
        if len(cols) != 6:
            raise InputError(frame.source, frame.line, f"wall {k}'s contact columns are incomplete: "
                             f"{', '.join(sorted(cols))} (a wall needs fx fy fz cx cy cz)")
        out[k] = (np.column_stack([cols["fx"], cols["fy"], cols["fz"]]),
                  np.column_stack([cols["cx"], cols["cy"], cols["cz"]]))
    return out


def wall_contacts(frame: Frame, p: Particles) -> Contacts | None:
    """The particle-wall contacts of an atom frame's wall-contact columns (None without such
    columns): an atom touches wall k where its force from the wall is not zero; the normal
    points from the contact point on the wall to the centre (minimum image on periodic
    axes), the overlap is radius - distance, the contact point (as for pairs) the middle of
    the overlap, and the partner is -(k - 1) - 1 = -k, MercuryDPM's index of wall k - 1."""
    walls = wall_columns(frame)
    if not walls:
        return None
    if p.radius is None:
        raise InputError(frame.source, frame.line, "wall contacts need radii: a 'radius' dump column or --data")
    parts = []
    for k, (force, point) in walls.items():
        i = np.flatnonzero(np.any(force != 0.0, axis=1))
        d = _minimum_image(p.x[i] - point[i], frame.periodic, frame.cell)
        dist = np.linalg.norm(d, axis=1)
        if np.any(dist == 0):
            raise InputError(frame.source, frame.line, f"atom id {int(p.ids[i[dist == 0][0]])} has its centre "
                             f"on wall {k}'s contact point: no contact normal")
        n = d / dist[:, None]
        F = force[i]
        fn = np.einsum("ij,ij->i", F, n)
        Ft = F - fn[:, None] * n
        ft = np.linalg.norm(Ft, axis=1)
        t = np.divide(Ft, ft[:, None], out=np.zeros_like(Ft), where=ft[:, None] > 0)
        delta = p.radius[i] - dist
        parts.append(Contacts(i, np.full(len(i), -k), p.x[i] - n * (p.radius[i] - delta / 2)[:, None],
                              delta, np.zeros(len(i)), fn, ft, n, t, None))
    return join_contacts(parts)


def join_contacts(parts: list[Contacts]) -> Contacts:
    """One ``Contacts`` of several, rows in order; the energy is the sum of the known ones."""
    energies = [c.energy for c in parts if c.energy is not None]
    return Contacts(*(np.concatenate([getattr(c, f) for c in parts])
                      for f in ("i", "j", "point", "delta", "deltat", "fn", "ft", "n", "t")),
                    energy=float(sum(energies)) if energies else None)


def _minimum_image(d: np.ndarray, periodic: np.ndarray, cell: np.ndarray) -> np.ndarray:
    if not np.any(periodic) or not len(d):
        return d
    s = np.linalg.solve(cell, d.T).T
    s[:, periodic] -= np.round(s[:, periodic])
    return s @ cell.T


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


def g15(x: float) -> str:
    return "%.15g" % x


class SpeciesDensities:
    """Each species' particle density m / (4/3 pi r^3) over all frames: its range and mean
    (MercuryDPM gives a species one density; particleDimensions 3 makes MercuryDPM's masses
    rho 4/3 pi r^3 again, in 2D too)."""

    def __init__(self) -> None:
        self.low: dict[int, float] = {}
        self.high: dict[int, float] = {}
        self.total: dict[int, float] = {}
        self.count: dict[int, int] = {}

    def add(self, p: Particles) -> None:
        if p.mass is None or p.radius is None:
            return
        ok = (p.mass > 0) & (p.radius > 0)          # a fixed (massless) or point particle has none
        rho = p.mass[ok] / (4.0 / 3.0 * math.pi * p.radius[ok] ** 3)
        for s in np.unique(p.species[ok]):
            r = rho[p.species[ok] == s]
            s = int(s)
            self.low[s] = min(self.low.get(s, math.inf), float(r.min()))
            self.high[s] = max(self.high.get(s, -math.inf), float(r.max()))
            self.total[s] = self.total.get(s, 0.0) + float(r.sum())
            self.count[s] = self.count.get(s, 0) + len(r)

    def density(self, s: int) -> float | None:
        return self.total[s] / self.count[s] if s in self.count else None

    def spread(self) -> list[tuple[int, float, float]]:
        """Species whose particles' densities differ by more than round-off: (s, low, high)."""
        return [(s, self.low[s], self.high[s]) for s in sorted(self.count)
                if self.high[s] - self.low[s] > 1e-12 * self.high[s]]


def restart_text(name: str, p: Particles, step: int, frames: int, dim: int, gravity: np.ndarray,
                 time_step: float, densities: SpeciesDensities, fstat: bool) -> str:
    """MercuryDPM's ``.restart`` of the last frame, as ``DPMBase::write`` lays it out and
    ``DPMBase::read`` (restart version 1.0; MercuryCG: up to the particles) reads it: the
    file lines, the domain, time step and time, dimensions and gravity, one
    ``LinearViscoelasticSpecies`` per species (its density; stiffness and dissipation 0:
    no MercuryDPM law is claimed) with its mixed species, no walls or boundaries, the
    particles (force from the dump, torque 0: dumps carry none), no interactions."""
    n_species = int(p.species.max()) + 1 if len(p.species) else 1
    n_species = max(n_species, max(densities.count, default=-1) + 1)
    saved = f"fileType ONE_FILE saveCount 1 counter {frames} lastSavedTimeStep {step}"
    files = "".join(f"{label:<12}{saved if written else 'fileType NO_FILE saveCount 1 counter 0'}\n"
                    for label, written in (("dataFile", True), ("fStatFile", fstat), ("eneFile", True),
                                           ("restartFile", True)))
    lines = [f"MercuryDPM 1.0 name {name} revision fibrelmp repository https://bitbucket.org/mercurydpm/mercurydpm.git\n",
             files,
             "statFile    fileType ONE_FILE saveCount 1 counter 0\n",
             "interactionFile fileType NO_FILE saveCount 0 counter 0\n",
             " ".join(f"{a}Min {g15(p.lo[k])} {a}Max {g15(p.hi[k])}" for k, a in enumerate("xyz")) + "\n",
             f"timeStep {g15(time_step)} time {g15(p.time)} ntimeSteps {step} timeMax {g15(p.time)}\n",
             f"systemDimensions {dim} particleDimensions 3 gravity {' '.join(g15(v) for v in gravity)} "
             "backgroundDrag 0\n",
             f"Species {n_species}\n"]
    for s in range(n_species):
        rho = densities.density(s)
        lines.append(f"LinearViscoelasticSpecies id {s} density {g15(1.0 if rho is None else rho)} "
                     "stiffness 0 dissipation 0\n")
        lines += [f"LinearViscoelasticMixedSpecies idA {s} idB {other} stiffness 0 dissipation 0\n"
                  for other in range(s)]
    lines += ["Walls 0\n", "Boundaries 0\n", f"Particles {len(p.ids)}\n"]
    n = len(p.ids)
    radius = p.radius if p.radius is not None else np.zeros(n)
    mass = p.mass if p.mass is not None else np.zeros(n)
    inv_mass = np.divide(1.0, mass, out=np.zeros(n), where=mass > 0)     # MercuryDPM: 0 = fixed
    q = p.quaternion if p.quaternion is not None else np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    force = p.force if p.force is not None else np.zeros((n, 3))
    cols = [np.arange(n), p.species, *p.x.T, *q.T, *p.v.T, *p.omega.T, *force.T, radius, inv_mass]
    fmt = ("BaseParticle id %d indSpecies %d position %.15g %.15g %.15g orientation %.15g %.15g %.15g %.15g "
           "velocity %.15g %.15g %.15g angularVelocity %.15g %.15g %.15g force %.15g %.15g %.15g "
           "torque 0 0 0 radius %.15g invMass %.15g timeStamp 0\n")
    return "".join(lines) + format_rows(fmt, cols) + "Interactions 0\n"


# -- writer --------------------------------------------------------------------------------
@dataclass
class MercuryFrame:
    """One frame for ``MercuryWriter``: the dump frame, its time and its contacts (a frame of
    a local dump, or None)."""

    frame: Frame
    time: float
    local: Frame | None = None


class MercuryWriter(Writer):
    """``<base>.data`` + ``<base>.ene`` + ``<base>.restart`` (the last frame; not without masses
    and radii) (+ ``<base>.fstat`` when ``fstat``: contacts of the frames' local dump and their
    wall-contact columns)."""

    format = "mercury"

    def __init__(self, base: Path, gravity: np.ndarray, fstat: bool, dim: int | None = None,
                 bonds: set[tuple[int, int]] | None = None, *, force: bool = True,
                 time_step: float | None = None, warn: Callable[[str, str], None] | None = None):
        self.fstat = fstat
        super().__init__(base, force=force)
        self.gravity = np.asarray(gravity, float)
        self.dim = dim
        self.bonds = bonds
        self.no_elastic = False
        self.time_step = time_step
        self.warn = warn or (lambda kind, text: None)
        self.densities = SpeciesDensities()
        self.last: tuple[Particles, int] | None = None
        self.first: tuple[float, int] | None = None

    def file(self, ext: str) -> Path:
        return self.target.with_name(self.target.name + ext)

    def outputs(self) -> list[Path]:
        return [self.file(e) for e in (".data", ".ene", ".restart") + ((".fstat",) if self.fstat else ())]

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
        walls = wall_contacts(frame, p)
        if walls is not None:
            c = walls if c is None else join_contacts([c, walls])
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
        self.densities.add(p)
        self.last = (p, frame.step)
        if self.first is None:
            self.first = (time, frame.step)
        elif self.time_step is None and frame.step != self.first[1]:
            self.time_step = (time - self.first[0]) / (frame.step - self.first[1])

    def finish(self) -> None:
        p, step = self.last if self.last is not None else (None, 0)
        if p is None:
            return
        if p.radius is None or p.mass is None:
            self.warn("no .restart", f"{self.file('.restart')} is not written: the species densities "
                      "need masses and radii (dump columns 'mass' and 'radius', or --data)")
            return
        for s, low, high in self.densities.spread():
            self.warn("species density", f"{self.file('.restart')}: the particles of species {s} (LAMMPS "
                      f"type {s + 1}) have densities from {low!r} to {high!r}; MercuryDPM gives a species "
                      "one density, the mean is written")
        if self.time_step is None:
            self.warn("no time step", f"{self.file('.restart')}: timeStep 0: one frame and no --data "
                      "job facts give no time step")
        self.open(self.file(".restart"), "w").write(
            restart_text(self.target.name, p, step, self.count, self.dim or 3, self.gravity,
                         self.time_step or 0.0, self.densities, self.fstat))
