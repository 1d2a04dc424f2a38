"""The scene a generator works on: a ``.mdem`` file's scene message and its first time point,
changed in memory and written back as cmusen saves a generated scene (one time point at 0).

Object i is ``storage.info.particles[i]`` and row i of ``values`` (``mdem.timepoints``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.translate.musen.mdem import timepoints
from fibrelmp.translate.musen.mdem.objects import (DEFAULT_ACTIVITY_END, SOLID_BOND, SPHERE,
                                                   encode_bond, encode_sphere, read_objects)

SPHERE_FIELDS = timepoints.bit("coord", "vel", "angle_vel", "quaternion")   # as cmusen saves them
BOND_FIELDS = timepoints.bit("angle_vel")            # its tangential overlap, 0


@dataclass
class Scene:
    path: Path
    storage: Any                 # ProtoSimulationStorage
    values: np.ndarray           # (objects, 34) at the first time point
    masks: np.ndarray

    @property
    def info(self) -> Any:
        return self.storage.info

    @property
    def modules(self) -> Any:
        return self.storage.modules_data

    def objects(self):
        return read_objects(self.info, 2, self.path)

    def _grow(self, count: int) -> int:
        first = len(self.info.particles)
        values = np.zeros((first + count, timepoints.NCOLS))
        masks = np.zeros(first + count, np.uint32)
        n = min(len(self.values), first)
        values[:n], masks[:n] = self.values[:n], self.masks[:n]
        self.values, self.masks = values, masks
        return first

    def add_spheres(self, position: np.ndarray, radius: np.ndarray, contact_radius: np.ndarray,
                    compound: list[str], velocity: np.ndarray, quaternion: np.ndarray) -> None:
        """Spheres active from 0 on (``AddSeveralObjects(SPHERE)``: ids after the last)."""
        first = self._grow(len(position))
        for r, rc, key in zip(radius.tolist(), contact_radius.tolist(), compound):
            p = self.info.particles.add()
            p.id = len(self.info.particles) - 1
            p.type, p.compound, p.activity_start, p.activity_end = SPHERE, key, 0.0, DEFAULT_ACTIVITY_END
            p.encoded_properties = encode_sphere(r, rc)
        rows = slice(first, first + len(position))
        self.values[rows, timepoints.columns("coord")] = position
        self.values[rows, timepoints.columns("vel")] = velocity
        self.values[rows, timepoints.columns("quaternion")] = quaternion
        self.masks[rows] = SPHERE_FIELDS

    def add_bonds(self, left: np.ndarray, right: np.ndarray, diameter: np.ndarray,
                  length0: np.ndarray, compound: str) -> None:
        """Solid bonds active from 0 on."""
        first = self._grow(len(left))
        for i, j, d, length in zip(left.tolist(), right.tolist(), diameter.tolist(), length0.tolist()):
            p = self.info.particles.add()
            p.id = len(self.info.particles) - 1
            p.type, p.compound, p.activity_start, p.activity_end = (SOLID_BOND, compound, 0.0,
                                                                    DEFAULT_ACTIVITY_END)
            p.encoded_properties = encode_bond(i, j, d, length)
        self.masks[first:] = BOND_FIELDS

    def remove(self, types: tuple[int, ...]) -> None:
        """``DeleteAllParticles`` / ``DeleteAllBonds``: objects of these types become removed
        (type 0), the others keep their ids."""
        for i, p in enumerate(self.info.particles):
            if p.type in types:
                p.Clear()
                if i < len(self.masks):
                    self.values[i], self.masks[i] = 0.0, 0

    def write(self, fh) -> None:
        """The scene as a ``.mdem`` with one time point at 0."""
        from fibrelmp.translate.musen.mdem.document import MdemWriter

        out = MdemWriter(fh)
        n = len(self.info.particles)
        out.add(0.0, self.values[:n], self.masks[:n])
        out.finish(self.storage)


def read_generator_scene(path: Path) -> Scene:
    """A ``.mdem`` scene and its first time point (the state generators start from)."""
    from fibrelmp.translate.musen.mdem.document import MdemFile

    with MdemFile(path) as mdem:
        storage = mdem.scene
        first = next(iter(mdem.time_points()), None)
    n = len(storage.info.particles)
    values = np.zeros((n, timepoints.NCOLS))
    masks = np.zeros(n, np.uint32)
    if first is not None:
        k = min(n, len(first[2]))
        values[:k], masks[:k] = first[1][:k], first[2][:k]
    return Scene(Path(path), storage, values, masks)
