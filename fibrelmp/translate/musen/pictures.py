"""MUSEN text results in pictures (``fibrelmp plot``/``snapshot``): the scene (``scene.read``)
and its time points (``read_time_points``, read whole, as the reader does); ``musen_frame``
is shared with the ``.mdem`` source (``mdem.pictures``)."""

from __future__ import annotations

from pathlib import Path
from typing import Iterator

import numpy as np

from fibrelmp.pictures.sources import SceneFrame, Source, kind_indices


def musen_frame(model, index: int, time: float, rows: np.ndarray, position: np.ndarray,
                 velocity: np.ndarray | None, triangles: np.ndarray | None,
                 temperature: np.ndarray | None = None) -> SceneFrame:
    """A frame of the spheres at ``rows`` of the model (bonds between them, if intact, and
    liquid bonds, while active)."""
    s = model.spheres
    kinds, names = kind_indices([m.name for m in model.materials], s.material[rows])
    bonds, broken = np.zeros((0, 2), np.int64), None
    if model.bonds is not None and model.bonds.count:
        b = model.bonds
        where = np.full(s.count, -1)
        where[rows] = np.arange(len(rows))
        intact = (b.active_start <= time) & (time < b.active_end)
        ends = where[b.pair]
        bonds = ends[intact & (ends >= 0).all(axis=1)]
        broken = int(np.count_nonzero(b.active_end <= time))
    liquid = np.zeros((0, 2), np.int64)
    if model.liquid_bonds:
        where = {int(s.ids[r]): j for j, r in enumerate(np.asarray(rows).tolist())}
        # active by the interval the result holds (CPhysicalObject::IsActive, inclusive; an
        # empty interval is never active), both spheres in the frame
        liquid = np.array([(where[lb.left], where[lb.right]) for lb in model.liquid_bonds
                           if lb.active_start != lb.active_end
                           and lb.active_start <= time <= lb.active_end
                           and lb.left in where and lb.right in where], np.int64).reshape(-1, 2)
    domain = model.plan.domain
    return SceneFrame(index, time, None, position, s.radius[rows], kinds, names,
                      velocity=velocity, mass=s.mass[rows], bonds=bonds, broken_bonds=broken,
                      triangles=triangles, box=domain, liquid_bonds=liquid, temperature=temperature)


class MusenTextSource(Source):
    what = "MUSEN text result"
    time_unit, energy_unit = "s", "J"

    def __init__(self, path: Path):
        from fibrelmp.translate.musen import scene
        from fibrelmp.translate.musen.text import SPHERE, WALL, read_time_points

        super().__init__(path)
        self.model = scene.read(path)
        self.tp = read_time_points(path, types=(SPHERE, WALL), tags=(12, 15, 37, 44))
        ids = self.tp.ids
        self.sphere_cols = np.searchsorted(ids, self.model.spheres.ids)
        t = self.model.triangles
        self.wall_cols = np.searchsorted(ids, t.ids) if t is not None and t.count else None

    def count(self) -> int:
        return len(self.tp.times)

    def frames(self) -> Iterator[SceneFrame]:
        f = self.tp.fields
        for k, time in enumerate(self.tp.times):
            pos = f[12][k, self.sphere_cols]
            rows = np.flatnonzero(self.tp.present[k, self.sphere_cols] & np.isfinite(pos).all(axis=1))
            vel = f[15][k, self.sphere_cols][rows] if 15 in f else None
            tri = None
            if self.wall_cols is not None and 44 in f:
                tri = f[44][k, self.wall_cols].reshape(-1, 3, 3)
                tri = tri[np.isfinite(tri).all(axis=(1, 2))]
            # 37: MUSEN writes 0 for every sphere without a heat model
            temp = f[37][k, self.sphere_cols][rows, 0] if 37 in f else None
            yield musen_frame(self.model, k, float(time), rows, pos[rows], vel, tri, temp)
