"""The SPH pressure-outflow boundary of the CardioProof seed, as numpy.

An opening is a set of shell elements (triangles; quads split in two) with an outward normal.
Each cycle, with the mesh where it is now:

1. candidates are the particles inside the opening's bounding box enlarged by the search
   distance ``d`` on every side;
2. a candidate is *near* the opening if its projection on some element's plane falls inside
   that element (barycentric coordinates >= -3 %, the projection margin) and it is on the
   fluid's side of that plane (behind it: the outward normal points away) at a distance of at
   most ``d`` (the closest such element counts); particles in front of the plane have left
   (the LAMMPS run removes them and counts them as crossed);
3. near particles share the force ``-p(t) A n`` (A the opening's area, n its area-weighted unit
   outward normal), weighted linearly by normal distance: ``w = 1 - delta/d`` (1 on the plane,
   1/2 at half the search distance);
4. the volume flux is estimated two ways: particles that were inside (behind the plane) at the
   last cycle and are outside now, times the particle volume; and A times the mean outward
   normal velocity of the near particles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MARGIN = 0.03


@dataclass
class Opening:
    triangles: np.ndarray          # (k, 3, 3) vertices, counter-clockwise seen from outside

    @property
    def normals(self) -> np.ndarray:
        """(k, 3) area vectors (|a| = 2 x area... halved here: |n_i| = area_i)."""
        t = self.triangles
        return 0.5 * np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])

    @property
    def area(self) -> float:
        return float(np.linalg.norm(self.normals, axis=1).sum())

    @property
    def normal(self) -> np.ndarray:
        """The unit outward normal, area weighted."""
        n = self.normals.sum(axis=0)
        return n / np.linalg.norm(n)


def triangles_of(points: np.ndarray, blocks: list[tuple[str, np.ndarray]]) -> np.ndarray:
    """(k, 3, 3) triangles of shell elements (triangles; quads split along 0-2)."""
    out = []
    for kind, nodes in blocks:
        nodes = np.asarray(nodes)
        if kind == "triangle":
            out.append(points[nodes])
        elif kind == "quad":
            out.append(points[nodes[:, [0, 1, 2]]])
            out.append(points[nodes[:, [0, 2, 3]]])
        else:
            raise ValueError(f"an opening is made of shell elements (triangles, quads), not {kind}")
    return np.concatenate(out) if out else np.zeros((0, 3, 3))


@dataclass
class Share:
    rows: np.ndarray               # (m,) indices of the near particles
    distance: np.ndarray           # (m,) normal distance to their element's plane
    weight: np.ndarray             # (m,) 1 - distance / d
    force: np.ndarray              # (m, 3) their share of -p A n


def near(opening: Opening, x: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray]:
    """(rows, normal distance >= 0) of the particles near the opening (steps 1-2)."""
    t = opening.triangles
    lo, hi = t.reshape(-1, 3).min(axis=0) - d, t.reshape(-1, 3).max(axis=0) + d
    rows = np.flatnonzero(np.all((x >= lo) & (x <= hi), axis=1))
    if not len(rows) or not len(t):
        return rows[:0], np.zeros(0)
    p = x[rows][:, None, :]                                 # (m, 1, 3)
    a, b, c = t[:, 0], t[:, 1], t[:, 2]                     # (k, 3)
    n = np.cross(b - a, c - a)
    n = n / np.linalg.norm(n, axis=1)[:, None]
    delta = np.einsum("mkj,kj->mk", p - a, n)               # signed distance to each plane
    q = p - delta[..., None] * n                            # projections
    v0, v1, v2 = b - a, c - a, q - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    d20, d21 = (v2 * v0).sum(-1), (v2 * v1).sum(-1)
    den = d00 * d11 - d01 * d01
    beta = (d11 * d20 - d01 * d21) / den
    gamma = (d00 * d21 - d01 * d20) / den
    alpha = 1.0 - beta - gamma
    inside = (alpha >= -MARGIN) & (beta >= -MARGIN) & (gamma >= -MARGIN) & (delta <= 0) & (delta >= -d)
    dist = np.where(inside, -delta, np.inf)
    best = dist.min(axis=1)
    keep = np.isfinite(best)
    return rows[keep], best[keep]


def share(opening: Opening, x: np.ndarray, d: float, pressure: float) -> Share:
    """The outflow force of one cycle on the near particles (steps 1-3)."""
    rows, delta = near(opening, x, d)
    weight = 1.0 - delta / d
    total = weight.sum()
    force = np.zeros((len(rows), 3))
    if total > 0:
        force = (-pressure * opening.area * opening.normal)[None, :] * (weight / total)[:, None]
    return Share(rows, delta, weight, force)


def flux(opening: Opening, x_before: np.ndarray, x_now: np.ndarray, v_now: np.ndarray,
         d: float, particle_volume: float) -> tuple[float, float]:
    """(crossing estimate, velocity estimate) of the outward volume flux over one cycle:
    the volume of the particles that were near the opening (behind its plane) at the last
    cycle and are in front of it now, and A x the mean outward normal velocity of the
    particles near it now."""
    n, origin = opening.normal, opening.triangles[:, 0].mean(axis=0)
    was, _ = near(opening, x_before, d)
    crossed = int(np.count_nonzero((x_now[was] - origin) @ n > 0))
    rows, _ = near(opening, x_now, d)
    mean_vn = float((v_now[rows] @ n).mean()) if len(rows) else 0.0
    return crossed * particle_volume, opening.area * mean_vn
