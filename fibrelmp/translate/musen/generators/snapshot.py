"""SNAPSHOT_GENERATOR: a result's state at ``SNAPSHOT_TIME`` as a new scene
(``CSystemStructure::CreateFromSystemStructure``, e0ff360).

Objects active at that time keep their ids, become active from 0 on, and take the values of
the two saved time points around it, interpolated linearly (MUSEN's ``CTimePointR``: the left
one itself at a saved time); stress tensors are not carried over; dynamic generators are
switched off.  The scene has one time point at 0.  A time outside the saved ones is refused:
cmusen writes NaN values there (0/0 in its interpolation).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.generators.scene import Scene
from fibrelmp.translate.musen.mdem import timepoints
from fibrelmp.translate.musen.mdem.objects import (DEFAULT_ACTIVITY_END, LIQUID_BOND, SOLID_BOND,
                                                   SPHERE, WALL)

# the fields CreateFromSystemStructure sets on each kind of object (scalars only when not 0)
_SET = {SPHERE: timepoints.bit("coord", "vel", "angle_vel", "force", "quaternion"),
        SOLID_BOND: timepoints.bit("force", "angle_vel"), LIQUID_BOND: timepoints.bit("force"),
        WALL: 0}
_SCALARS = ("temperature", "total_torque")


def _pair(mdem, t: float):
    """The saved time points around ``t`` (MUSEN's ``FindPairInBlock``)."""
    left = right = None
    for point in mdem.time_points():
        if point[0] <= t:
            left = point
        else:
            right = point
            break
    return left, right


def snapshot(source: Path, job) -> Scene:
    """The scene at ``job.snapshot_time`` of the ``.mdem`` result ``source``."""
    from fibrelmp.translate.musen.mdem.document import MdemFile

    t = job.snapshot_time
    with MdemFile(source) as mdem:
        storage = mdem.scene
        times = mdem.times()
        left, right = _pair(mdem, t)
    if left is None or (left[0] < t and right is None):
        raise InputError(job.path, job.where("SNAPSHOT_TIME"), f"SNAPSHOT_TIME {t:g} is outside "
                         f"the saved times of {source.name} ({times.min():g} .. {times.max():g} s); "
                         "cmusen writes NaN values there")
    values, masks = left[1].copy(), left[2].copy()
    if left[0] < t:
        n = min(len(values), len(right[1]))
        values[:n] = values[:n] + (right[1][:n] - values[:n]) / (right[0] - left[0]) * (t - left[0])
    n = len(storage.info.particles)
    full = np.zeros((n, timepoints.NCOLS))
    full_masks = np.zeros(n, np.uint32)
    k = min(n, len(values))
    full[:k], full_masks[:k] = values[:k], masks[:k]
    scene = Scene(Path(source), storage, full, full_masks)
    _objects_at(scene, t)
    for g in storage.modules_data.objects_generator.generators:
        g.activity = False
    return scene


def _objects_at(scene: Scene, t: float) -> None:
    """Objects inactive at ``t`` removed, the others active from 0 on; masks as MUSEN sets them."""
    stress = timepoints.columns("stress_tensor")
    scene.values[:, stress] = 0.0
    for i, p in enumerate(scene.info.particles):
        if p.type == 0:
            continue
        if p.activity_end == p.activity_start or not p.activity_start <= t <= p.activity_end:
            p.Clear()
            scene.values[i], scene.masks[i] = 0.0, 0
            continue
        p.activity_start, p.activity_end = 0.0, DEFAULT_ACTIVITY_END
        mask = int(scene.masks[i]) & ~timepoints.bit("stress_tensor") | _SET.get(p.type, 0)
        for name in _SCALARS:
            on = scene.values[i, timepoints.columns(name)][0] != 0
            mask = mask | timepoints.bit(name) if on else mask & ~timepoints.bit(name)
        scene.masks[i] = mask
