"""How fast and how far a sphere can get during a run: bounds the wall particles that matter
(``tiles``) and paces the domain removal and the reach check (``box``)."""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from fibrelmp.granmodel import GranularModel
from fibrelmp.sanity import close_pairs

REACH_SAFETY = 2.0          # wall particles: kept within twice the distance a sphere can travel


def speed_bound(model: GranularModel, rows: np.ndarray, crad: np.ndarray, mass: np.ndarray,
                smat: np.ndarray) -> float:
    """Estimate of the fastest a sphere can get without gravity and moving walls: the largest
    |v| + |w| r in the input, plus the speed the elastic (Hertz) energy of all initial
    overlaps would give the lightest sphere."""
    sp = model.spheres
    if not len(rows):
        return 0.0
    r = crad[rows]
    with np.errstate(all="ignore"):
        fast = float(np.max(np.linalg.norm(sp.velocity[rows], axis=1)
                            + np.linalg.norm(sp.omega[rows], axis=1) * r))
    if not math.isfinite(fast):
        return math.inf
    try:
        pairs = close_pairs(sp.position[rows], 2.0 * float(r.max()))
    except ImportError:                  # pragma: no cover - scipy comes with MDAnalysis
        return fast
    if not len(pairs):
        return fast
    i, j = pairs[:, 0], pairs[:, 1]
    delta = r[i] + r[j] - np.linalg.norm(sp.position[rows][i] - sp.position[rows][j], axis=1)
    sel = delta > 0
    if not sel.any():
        return fast
    i, j, delta = i[sel], j[sel], delta[sel]
    estar = np.array([getattr(model.contacts.get((min(a, b), max(a, b))), "youngs_eff", 0.0)
                      for a, b in zip(smat[i].tolist(), smat[j].tolist())], float)
    reff = r[i] * r[j] / (r[i] + r[j])
    with np.errstate(all="ignore"):
        energy = float(np.sum(8.0 / 15.0 * estar * np.sqrt(reff) * delta ** 2.5))
        fast += math.sqrt(2.0 * energy / float(mass.min()))
    return fast if math.isfinite(fast) else math.inf


def wall_speed(wall_plans) -> float:
    """Fastest translation speed of any moving geometry (pacing only)."""
    out = 0.0
    for wp in wall_plans:
        for _, _, vel in wp.kinematics.intervals:
            out = max(out, float(np.linalg.norm(vel)))
    return out


class Travel:
    """Speed and travel of the simulated spheres over a run of ``span`` time units, with
    gravity and the moving walls.  The speed bound needs a pair search: it is computed once,
    when first asked for (many wall particles or an oversized domain)."""

    def __init__(self, model: GranularModel, spheres, span: float, wall_plans):
        self.model, self.spheres, self.span, self.wall_plans = model, spheres, span, wall_plans
        self.gravity = float(np.linalg.norm(model.plan.gravity))

    @cached_property
    def speed(self) -> float:
        s = self.spheres
        return speed_bound(self.model, s.rows, s.crad, s.mass, s.smat)

    def reach(self, r_max: float) -> float:
        """How far wall particles must extend around the spheres (at least 2 ``r_max``)."""
        return max(REACH_SAFETY * (self.speed * self.span + 0.5 * self.gravity * self.span ** 2), 2.0 * r_max)

    def end_speed(self) -> float:
        """The fastest a sphere (or a moving wall, counted twice) can get by the end."""
        return self.speed + self.gravity * self.span + 2.0 * wall_speed(self.wall_plans)
