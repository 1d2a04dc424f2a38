"""PACKAGE_GENERATOR: MUSEN's packing algorithm (``Modules/PackageGenerator``, e0ff360),
written anew with numpy and scipy's k-d tree.

For each active generator: the number of spheres of each mixture fraction follows from the
volume, the porosity and the fractions' number shares (``ParticlesPerFraction``, rounded
down); they are dropped at uniformly random points of the volume's bounding box, those
lying totally inside the volume (and clear of spheres already there) kept, until every
fraction is complete.  Then MUSEN's pseudo-dynamics pushes them apart: unit mass, unit
time step, a normal force ``kn * overlap`` between spheres whose coefficient ``kn`` adapts
(from 0.001, x/÷1.2, below 0.05), the old velocity kept at 0.4, velocities scaled by
``r_min / r`` so that large spheres move less, a step undone when a sphere would move more
than 0.1 of its radius, and the volume's surface pushing back with coefficient 0.9.  It
stops when the largest overlap (sphere-sphere or sphere-wall, checked every 10 steps as
MUSEN does) is at most the target, or after the iteration limit.  The spheres get the
fraction's compound, the generator's initial velocity and a random orientation.

The packing is random, as MUSEN's is: count, porosity and size distribution equal
cmusen's, positions do not (tests compare the statistics with cmusen's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.generators import mesh
from fibrelmp.translate.musen.generators.scene import Scene
from fibrelmp.translate.musen.mdem.objects import SPHERE

_KN_START, _KN_FACTOR, _KN_TOP = 0.001, 1.2, 0.05
_KN_WALL, _KEEP_VELOCITY = 0.9, 0.4
_MOVE_LIMIT, _CALM = 0.1, 0.01


@dataclass
class PackResult:
    """What one generator made (for the log and the tests)."""
    name: str
    count: int
    per_fraction: list[int]
    porosity: float
    max_overlap: float
    iterations: int
    seconds: float


@dataclass
class _Fractions:
    compound: list[str]
    diameter: np.ndarray
    contact: np.ndarray
    share: np.ndarray


def mixture_fractions(scene: Scene, key: str, where: str) -> _Fractions:
    """The mixture's fractions, checked as ``IsMixtureCorrect`` checks them."""
    db = scene.modules.materials_database
    mix = next((m for m in db.mixture if m.uniqueKey == key), None)
    if mix is None:
        raise InputError(scene.path, None, f"{where}: mixture {key!r} not found")
    if not mix.fraction:
        raise InputError(scene.path, None, f"{where}: mixture {mix.mixtureName!r} has no fractions")
    compounds = {c.uniqueKey for c in db.compound}
    for f in mix.fraction:
        if f.compoundKey not in compounds:
            raise InputError(scene.path, None, f"{where}: mixture {mix.mixtureName!r}: fraction "
                             f"{f.fractionName!r} names compound {f.compoundKey!r}, which is not defined")
    share = np.array([f.fraction for f in mix.fraction])
    if abs(share.sum() - 1.0) > 16 * np.finfo(float).eps:
        raise InputError(scene.path, None, f"{where}: the fractions of mixture {mix.mixtureName!r} "
                         f"add up to {share.sum():.6g}, not 1 (cmusen refuses it too)")
    return _Fractions([f.compoundKey for f in mix.fraction],
                      np.array([f.diameter for f in mix.fraction]),
                      np.array([f.contact_diameter for f in mix.fraction]), share)


def particles_per_fraction(fr: _Fractions, volume: float, porosity: float) -> list[int]:
    """``ParticlesPerFraction``: solid volume over the mean sphere volume, by number share."""
    mean = float((fr.share * math.pi / 6.0 * fr.diameter ** 3).sum())
    solid = (1.0 - porosity) * volume
    return [int(solid / mean * s) for s in fr.share]


def place(tri: np.ndarray, normals: np.ndarray, counts: list[int], contact: np.ndarray,
          fixed_x: np.ndarray, fixed_r: np.ndarray, rng: np.random.Generator,
          ) -> tuple[np.ndarray, np.ndarray]:
    """``PlaceParticlesInitially``: (centres, fraction of each) of spheres dropped uniformly in
    the bounding box, kept when totally inside the volume and clear of ``fixed`` spheres."""
    from scipy.spatial import cKDTree

    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    left = list(counts)
    xs, fs = [], []
    fixed = cKDTree(fixed_x) if len(fixed_x) else None
    for _ in range(10000):
        if not sum(left):
            break
        frac = np.repeat(np.arange(len(left)), left)
        x = rng.uniform(lo, hi, (len(frac), 3))
        r = contact[frac]
        ok = mesh.totally_inside(x, r, tri, normals)
        if fixed is not None and ok.any():
            for i in np.flatnonzero(ok):
                near = fixed.query_ball_point(x[i], r[i] + fixed_r.max())
                if near and np.any(np.linalg.norm(fixed_x[near] - x[i], axis=1) < r[i] + fixed_r[near]):
                    ok[i] = False
        xs.append(x[ok])
        fs.append(frac[ok])
        left = [n - int((frac[ok] == k).sum()) for k, n in enumerate(left)]
    else:
        raise ValueError("the generation volume takes no sphere of this mixture after "
                         "10000 random drops")
    return np.concatenate(xs), np.concatenate(fs)


class _Relaxation:
    """MUSEN's pseudo-dynamics on ``x`` (moving spheres first, ``fixed`` ones after them)."""

    def __init__(self, x: np.ndarray, rc: np.ndarray, moving: int, tri: np.ndarray,
                 normals: np.ndarray):
        self.x, self.rc, self.moving = x, rc, moving
        self.tri, self.normals = tri, normals
        self.v_old = np.zeros((moving, 3))
        self.scale = (rc[:moving].min() / rc[:moving])[:, None]
        self.skin = 0.5 * rc[:moving].min()
        self.x_built = None

    def neighbours(self) -> None:
        """Verlet lists (pairs and sphere-triangle candidates), rebuilt after moving half the skin."""
        from scipy.spatial import cKDTree

        if self.x_built is not None:
            moved = np.linalg.norm(self.x[:self.moving] - self.x_built[:self.moving], axis=1).max()
            if moved < 0.5 * self.skin:
                return
        self.x_built = self.x.copy()
        pairs = cKDTree(self.x).query_pairs(2 * self.rc.max() + self.skin, output_type="ndarray")
        pairs = pairs[(pairs[:, 0] < self.moving) | (pairs[:, 1] < self.moving)]
        d = np.linalg.norm(self.x[pairs[:, 0]] - self.x[pairs[:, 1]], axis=1)
        self.pairs = pairs[d < self.rc[pairs[:, 0]] + self.rc[pairs[:, 1]] + self.skin]
        m = self.moving
        self.wall_rows, self.wall_tris, _ = mesh.near_pairs(self.x[:m], self.rc[:m] + self.skin,
                                                            self.tri, self.normals)

    def pp(self) -> tuple[np.ndarray, np.ndarray]:
        """Overlaps and unit vectors i->j of the listed pairs."""
        i, j = self.pairs[:, 0], self.pairs[:, 1]
        d = self.x[j] - self.x[i]
        dist = np.sqrt(np.einsum("ij,ij->i", d, d))
        return self.rc[i] + self.rc[j] - dist, d / np.maximum(dist, 1e-300)[:, None]

    def pw(self) -> tuple[np.ndarray, np.ndarray]:
        """Overlaps with the surface and MUSEN's PW force direction (inward normal, scaled by
        the contact's cosine)."""
        rows, tris = self.wall_rows, self.wall_tris
        c = self.x[rows]
        q = mesh.closest_points(c, self.tri[tris, 0], self.tri[tris, 1], self.tri[tris, 2])
        rc = c - q
        dist = np.linalg.norm(rc, axis=1)
        n = self.normals[tris]
        cosine = np.abs(np.einsum("ij,ij->i", rc / np.maximum(dist, 1e-300)[:, None], n))
        return self.rc[rows] - dist, n * cosine[:, None]

    def max_overlap(self) -> float:
        self.neighbours()
        ov_pp, _ = self.pp()
        ov_pw, _ = self.pw()
        return float(max(ov_pp.max(initial=0.0), ov_pw.max(initial=0.0)))

    def step(self, kn: float) -> float:
        """One iteration of ``StartGeneration``'s loop; returns the new ``kn``."""
        m = self.moving
        self.neighbours()
        ov, u = self.pp()
        hit = ov > 0
        push = u[hit] * (kn * ov[hit])[:, None]
        f = _sum_rows(self.pairs[hit, 1], push, len(self.x)) - _sum_rows(self.pairs[hit, 0], push, len(self.x))
        v = (_KEEP_VELOCITY * self.v_old + f[:m]) * self.scale
        rel = float(np.sqrt((np.einsum("ij,ij->i", v, v) / self.rc[:m] ** 2).max(initial=0.0)))
        if rel > _MOVE_LIMIT:                        # ResetMovement: undone, softer force
            self.v_old[:] = 0.0
            return kn / _KN_FACTOR
        self.x[:m] += v
        self.v_old = v
        ov_w, n_w = self.pw()                        # the walls' step moves by v again
        hit = ov_w > 0
        fw = _sum_rows(self.wall_rows[hit], n_w[hit] * (_KN_WALL * ov_w[hit])[:, None], m)
        self.x[:m] += v + fw
        if rel < _CALM and kn < _KN_TOP:
            kn *= _KN_FACTOR
        return kn


def _sum_rows(rows: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Sum of ``values`` per row index (``np.add.at``, but with bincount: many times faster)."""
    return np.stack([np.bincount(rows, values[:, k], n) for k in range(3)], axis=1)


def relax(x: np.ndarray, rc: np.ndarray, moving: int, tri: np.ndarray, normals: np.ndarray,
          target: float, max_iterations: int,
          progress: Callable[[int, float], None] | None = None) -> tuple[float, int]:
    """Push the spheres apart in place; (largest overlap reached, iterations)."""
    sim = _Relaxation(x, rc, moving, tri, normals)
    kn, it = _KN_START, 0
    reached = sim.max_overlap()
    while reached > target and it < max_iterations:
        if it % 10 == 0:
            reached = sim.max_overlap()
            if progress is not None and it % 1000 == 0:
                progress(it, reached)
            if reached <= target:
                break
        kn = sim.step(kn)
        it += 1
    return sim.max_overlap(), it


def random_quaternions(n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform random rotations (Shoemake), stored as MUSEN's q0..q3 columns."""
    u1, u2, u3 = rng.random((3, n))
    a, b = np.sqrt(1 - u1), np.sqrt(u1)
    return np.stack([a * np.sin(2 * np.pi * u2), a * np.cos(2 * np.pi * u2),
                     b * np.sin(2 * np.pi * u3), b * np.cos(2 * np.pi * u3)], axis=1)


def existing_spheres(scene: Scene, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Spheres already in the volume (centre inside): fixed obstacles (``AddOverlayedParticles``)."""
    from fibrelmp.translate.musen.mdem import timepoints

    objs = scene.objects()
    rows = objs.ids[objs.types == SPHERE]
    if not len(rows):
        return np.zeros((0, 3)), np.zeros(0)
    x = scene.values[rows][:, timepoints.columns("coord")]
    rc = objs.contact_radius[objs.types == SPHERE]
    ins = mesh.inside(x, tri)
    return x[ins], rc[ins]
