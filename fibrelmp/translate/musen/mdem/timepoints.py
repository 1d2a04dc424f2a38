"""Time points of ``.mdem`` files as numpy arrays: ``ProtoTimePoint`` <-> (time, values, masks).

``values`` has one row per object (row = object id) and the 34 columns of ``COLUMNS``; bit f
of ``masks[i]`` says field f of object i's ``ProtoTimeDependentProperties`` is present (a
message field MUSEN set, even if all zero).  The C helpers of ``fibrelmp.numtext.fast`` do
this for large scenes (100k objects: milliseconds); without them the ``protobuf`` messages
are walked in Python, with the same result (tests compare both).
"""

from __future__ import annotations

import numpy as np

from fibrelmp.numtext import fast
from fibrelmp.translate.musen.mdem.messages import new

# field name -> (field number, first column, number of columns)
FIELDS = {
    "coord": (1, 0, 3), "angles": (2, 3, 3), "vel": (3, 6, 3), "angle_vel": (4, 9, 3),
    "angle_accl": (6, 12, 3), "total_torque": (8, 15, 1), "temperature": (9, 16, 1),
    "liquid_film_mass": (10, 17, 1), "force": (11, 18, 3), "quaternion": (12, 21, 4),
    "stress_tensor": (13, 25, 9),
}
NCOLS = 34
_VECTOR = ("x", "y", "z")


def columns(name: str) -> slice:
    _, first, k = FIELDS[name]
    return slice(first, first + k)


def bit(*names: str) -> int:
    """The mask with the fields ``names`` set."""
    return sum(1 << FIELDS[n][0] for n in names)


def time_of(raw: bytes) -> float:
    """The time of a serialized ``ProtoTimePoint`` (field 1; 0 when absent); ValueError if
    it is malformed."""
    from google.protobuf.message import DecodeError

    tp = new("ProtoTimePoint")
    try:
        tp.MergeFromString(bytes(raw))
    except DecodeError as exc:
        raise ValueError(f"malformed time point ({exc})") from None
    return tp.time


def decode(raw: bytes, most: int | None = None) -> tuple[float, np.ndarray, np.ndarray]:
    """(time, values (n, 34), masks (n,)) of a serialized ``ProtoTimePoint``; ValueError if
    it is malformed or holds more than ``most`` objects (checked before allocating)."""
    done = fast.mdem_decode(raw, most)
    if done is not None:
        return done
    point = decode_py(raw)
    if most is not None and len(point[2]) > most:
        raise ValueError(f"{len(point[2])} objects in a time point of a scene of {most}")
    return point


def decode_py(raw: bytes) -> tuple[float, np.ndarray, np.ndarray]:
    """``decode`` through the protobuf messages (the path without the C helpers)."""
    from google.protobuf.message import DecodeError

    try:
        tp = new("ProtoTimePoint", bytes(raw))
    except DecodeError as exc:
        raise ValueError(f"malformed time point ({exc})") from None
    n = len(tp.particles)
    values = np.zeros((n, NCOLS))
    masks = np.zeros(n, np.uint32)
    for i, obj in enumerate(tp.particles):
        row = values[i]
        mask = 0
        for fd, value in obj.ListFields():
            number, first, k = FIELDS[fd.name]
            mask |= 1 << number
            if k == 1:
                row[first] = value
            elif fd.name == "quaternion":
                row[first:first + 4] = (value.q0, value.q1, value.q2, value.q3)
            elif fd.name == "stress_tensor":
                for j, v in enumerate((value.v1, value.v2, value.v3)):
                    row[first + 3 * j:first + 3 * j + 3] = (v.x, v.y, v.z)
            else:
                row[first:first + 3] = (value.x, value.y, value.z)
        masks[i] = mask
    return tp.time, values, masks


def encode(time: float, values: np.ndarray, masks: np.ndarray) -> bytes:
    """The serialized ``ProtoTimePoint`` (byte for byte what protobuf writes)."""
    done = fast.mdem_encode(time, values, masks)
    return done if done is not None else encode_py(time, values, masks)


def encode_py(time: float, values: np.ndarray, masks: np.ndarray) -> bytes:
    """``encode`` through the protobuf messages (the path without the C helpers)."""
    tp = new("ProtoTimePoint")
    tp.time = time
    for row, mask in zip(np.asarray(values, float), np.asarray(masks, np.uint32)):
        obj = tp.particles.add()
        for name, (number, first, k) in FIELDS.items():
            if not int(mask) >> number & 1:
                continue
            if k == 1:
                setattr(obj, name, float(row[first]))
                continue
            sub = getattr(obj, name)
            sub.SetInParent()
            if name == "quaternion":
                sub.q0, sub.q1, sub.q2, sub.q3 = map(float, row[first:first + 4])
            elif name == "stress_tensor":
                for j, v in enumerate((sub.v1, sub.v2, sub.v3)):
                    v.SetInParent()
                    v.x, v.y, v.z = map(float, row[first + 3 * j:first + 3 * j + 3])
            else:
                sub.x, sub.y, sub.z = map(float, row[first:first + 3])
    return tp.SerializeToString()
