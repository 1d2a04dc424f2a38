"""Liquid bonds' activity in a MUSEN result, as cmusen 1.74.2 writes it.  Their law
(ModelLBCapilarViscous) is a no-op at MUSEN e0ff360, so nothing breaks them; what changes is
the activity end BaseSimulator::SaveData writes at every save: a bond active when the run
starts (CSimplifiedScene::AddLiquidBond: IsActive(t_start)) stays active, and
SetObjectActivity(t, true) moves its end up to the save's time t (a scene end of 0.003 in a
run to 0.005 is written 0.005); a bond whose sphere left the domain is deactivated
(CPUSimulator: EndActivity = the removal time) and, if still active by its interval at the
next save, ends there.  A bond inactive at the start never gets a time point and cmusen's
result holds it as an object of type 0 (its .mdem; its text export leaves it out): so do
fibrelmp's writers (``untyped``)."""

from __future__ import annotations

import numpy as np

from fibrelmp.granmodel import GranularModel


class LiquidBondActivity:
    """The activity end of each of ``model.liquid_bonds`` as the saves go (``save``)."""

    def __init__(self, model: GranularModel):
        liquid = model.liquid_bonds or []
        self.start = np.array([lb.active_start for lb in liquid], np.float64)
        self.end = np.array([lb.active_end for lb in liquid], np.float64)
        t0 = model.plan.t_start
        self.active = self._by_interval(t0)
        self.untyped = ~self.active
        rows = {int(i): r for r, i in enumerate(np.asarray(model.spheres.ids).tolist())}
        self.left = np.array([rows[lb.left] for lb in liquid], np.int64)
        self.right = np.array([rows[lb.right] for lb in liquid], np.int64)

    def _by_interval(self, t: float) -> np.ndarray:
        """CPhysicalObject::IsActive(t): an empty interval is never active."""
        return (self.start != self.end) & (self.start <= t) & (t <= self.end)

    def save(self, t: float, sphere_present: np.ndarray) -> None:
        """A save at time ``t``; ``sphere_present``: per sphere row, False once it has left
        the domain.  A removed sphere's time is taken as this save's, as the writers do for
        the sphere."""
        if not len(self.end):
            return
        lost = self.active & ~(sphere_present[self.left] & sphere_present[self.right])
        self.end[lost & self._by_interval(t)] = t
        self.active &= ~lost
        self.end[self.active] = np.maximum(self.end[self.active], t)
