"""The objects of a ``.mdem`` scene (``ProtoSimulationInfo.particles``) as numpy arrays.

Object i is ``particles[i]`` (its id); type 0 marks a removed object.  ``encoded_properties``
holds, little endian and packed: spheres ``radius, contact radius`` (2 doubles), solid and
liquid bonds ``left id, right id`` (2 uint32) ``diameter, initial length`` (2 doubles), walls
nothing (their vertices are time-dependent).  Files of header version < 2 hold the same values
as text (``"r rc"``, ``"left right d L0"``).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.errors import InputError

SPHERE, SOLID_BOND, LIQUID_BOND, WALL = 1, 9, 13, 14
TYPES = (SPHERE, SOLID_BOND, LIQUID_BOND, WALL)
DEFAULT_ACTIVITY_END = 1e300
_SPHERE = struct.Struct("<dd")
_BOND = struct.Struct("<IIdd")


@dataclass
class Objects:
    """Every object of a scene, ascending id (removed objects left out)."""

    ids: np.ndarray            # (n,) int64
    types: np.ndarray          # (n,) int64
    compound: list[str]        # key as stored ("" = none)
    start: np.ndarray          # activity interval
    end: np.ndarray
    radius: np.ndarray         # spheres (nan elsewhere)
    contact_radius: np.ndarray
    left: np.ndarray           # bonds: sphere ids (-1 elsewhere)
    right: np.ndarray
    diameter: np.ndarray       # bonds (nan elsewhere)
    length0: np.ndarray

    @property
    def count(self) -> int:
        return len(self.ids)


def read_objects(info: Any, header_version: int, path: Path) -> Objects:
    """The objects of ``ProtoSimulationInfo`` ``info``."""
    particles = info.particles
    n = len(particles)
    types = np.fromiter((p.type for p in particles), np.int64, n)
    keep = np.flatnonzero(types != 0)
    unknown = set(types[keep].tolist()) - set(TYPES)
    if unknown:
        raise InputError(path, None, f"unsupported MUSEN object type(s) {sorted(unknown)} "
                         "(spheres 1, solid bonds 9, liquid bonds 13 and walls 14 are known)")
    m = len(keep)
    radius = np.full(m, np.nan)
    contact = np.full(m, np.nan)
    left = np.full(m, -1, np.int64)
    right = np.full(m, -1, np.int64)
    diameter = np.full(m, np.nan)
    length0 = np.full(m, np.nan)
    compound, start, end = [], np.empty(m), np.empty(m)
    for j, i in enumerate(keep.tolist()):
        p = particles[i]
        compound.append(p.compound)
        start[j], end[j] = p.activity_start, p.activity_end
        data, kind = p.encoded_properties, int(types[i])
        try:
            if kind == SPHERE:
                radius[j], contact[j] = (_text(data, 2) if header_version < 2
                                         else _SPHERE.unpack(data[:16].ljust(16, b"\0")))
            elif kind in (SOLID_BOND, LIQUID_BOND):
                values = (_text(data, 4) if header_version < 2
                          else _BOND.unpack(data[:24].ljust(24, b"\0")))
                left[j], right[j], diameter[j], length0[j] = values
        except ValueError:
            raise InputError(path, None, f"corrupt .mdem file: object {i} has unreadable "
                             f"properties {bytes(data[:40])!r}") from None
    return Objects(keep.astype(np.int64), types[keep], compound, start, end, radius, contact,
                   left, right, diameter, length0)


def _text(data: bytes, k: int) -> tuple[float, ...]:
    values = [float(t) for t in data.decode("ascii").split()]
    if len(values) != k:
        raise ValueError("wrong count")
    return tuple(values)


def encode_sphere(radius: float, contact_radius: float) -> bytes:
    return _SPHERE.pack(radius, contact_radius)


def encode_bond(left: int, right: int, diameter: float, length0: float) -> bytes:
    return _BOND.pack(left, right, diameter, length0)
