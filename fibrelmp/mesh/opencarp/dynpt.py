"""openCARP ``.dynpt`` files: node positions over time (IGB format, ``type:vec3f``).

IGB: a 1024-byte ASCII header of ``key:value`` items (``x y z t`` sizes, ``type``,
``systeme`` byte order, optional ``org_t`` first time, ``inc_t`` time between frames,
``unites_t``...), padded with spaces and ending in a form feed, then ``t`` frames of
``x*y*z`` records; a ``vec3f`` record is a node's position (µm, like ``.pts``), float32 x y z.
meshalyzer replaces the mesh's points by each frame (positions, not displacements).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import ClassVar, Iterator

import numpy as np

from fibrelmp.formatbase import Reader, Writer

HEADER = 1024
_TYPES = {"vec3f": "f4", "vec3d": "f8"}
_ORDER = {"little_endian": "<", "big_endian": ">"}


@dataclass
class PointsFrame:
    index: int
    time: float                    # org_t + index * inc_t (the header's time unit)
    points: np.ndarray             # (n, 3) float64, µm


def parse_header(head: bytes) -> dict[str, str]:
    """The ``key:value`` items of an IGB header (keys lower case)."""
    text = head.split(b"\f", 1)[0].decode("ascii", "replace")
    items = {}
    for line in text.splitlines():
        if line.lstrip().startswith("#"):
            continue
        for word in line.split():
            key, sep, value = word.partition(":")
            if sep:
                items[key.lower()] = value
    return items


class DynptReader(Reader):
    """Frames one at a time (memory: one frame); ``count`` and ``nodes`` from the header."""

    format: ClassVar[str] = "dynpt"
    what: ClassVar[str] = "openCARP .dynpt file"

    def __init__(self, path: str | os.PathLike):
        super().__init__(path)
        size = self.path.stat().st_size
        with open(self.path, "rb") as fh:
            head = fh.read(HEADER)
        if len(head) < HEADER:
            raise self.error(None, f"truncated: {len(head)} bytes, shorter than the IGB header")
        items = parse_header(head)
        self.header = items
        try:
            dims = [int(items[k]) for k in ("x", "y", "z", "t")]
        except (KeyError, ValueError):
            raise self.error(None, "the IGB header needs integer x, y, z and t") from None
        kind = items.get("type", "")
        if kind not in _TYPES:
            raise self.error(None, f"IGB type {kind!r}: a .dynpt holds positions (vec3f)")
        order = _ORDER.get(items.get("systeme", "little_endian"))
        if order is None:
            raise self.error(None, f"unknown byte order systeme:{items.get('systeme')}")
        if min(dims) < 0:
            raise self.error(None, "negative sizes in the IGB header")
        self.nodes = dims[0] * dims[1] * dims[2]
        self.count = dims[3]
        self.dtype = np.dtype(order + _TYPES[kind])
        self.frame_bytes = 3 * self.nodes * self.dtype.itemsize
        if size != HEADER + self.count * self.frame_bytes:
            raise self.error(None, f"the header says {self.count} frames of {self.nodes} nodes "
                             f"({HEADER + self.count * self.frame_bytes} bytes) but the file has "
                             f"{size} bytes")
        try:
            self.org_t = float(items.get("org_t", 0.0))
            self.inc_t = float(items.get("inc_t", 1.0))
        except ValueError:
            raise self.error(None, "org_t and inc_t must be numbers") from None
        if not (np.isfinite(self.org_t) and np.isfinite(self.inc_t)):
            raise self.error(None, "org_t and inc_t must be finite numbers")

    def __iter__(self) -> Iterator[PointsFrame]:
        with open(self.path, "rb") as fh:
            fh.seek(HEADER)
            for k in range(self.count):
                data = fh.read(self.frame_bytes)
                if len(data) != self.frame_bytes:
                    raise self.error(None, f"truncated in frame {k}")
                points = np.frombuffer(data, self.dtype).reshape(self.nodes, 3).astype(np.float64)
                if not np.isfinite(points).all():
                    raise self.error(None, f"frame {k}: positions must be finite")
                yield PointsFrame(k, self.org_t + k * self.inc_t, points)


class DynptWriter(Writer):
    """``add`` position frames (``(n, 3)`` in µm, or ``PointsFrame``s); the header is written
    at ``close`` when the frame count is known (``inc_t``/``org_t`` given here)."""

    format: ClassVar[str] = "dynpt"

    def __init__(self, target: str | os.PathLike, inc_t: float = 1.0, org_t: float = 0.0,
                 unit_t: str = "ms", *, force: bool = True):
        super().__init__(target, force=force)
        self.inc_t, self.org_t, self.unit_t = inc_t, org_t, unit_t
        self.nodes: int | None = None

    def write(self, frame) -> None:
        points = np.asarray(getattr(frame, "points", frame), np.float64)
        if self.nodes is None:
            self.nodes = len(points)
            self.put(self.target, bytes(HEADER))           # the header's place
        if points.shape != (self.nodes, 3):
            raise ValueError(f"frame of shape {points.shape}, expected ({self.nodes}, 3)")
        self.put(self.target, points.astype("<f4").tobytes())

    def finish(self) -> None:
        fh = self.open(self.target)
        fh.seek(0)
        fh.write(igb_header(self.nodes or 0, self.count, self.inc_t, self.org_t, self.unit_t))


def igb_header(nodes: int, frames: int, inc_t: float, org_t: float, unit_t: str) -> bytes:
    """meshalyzer's IGB header: items, lines ending CR LF, space padding, form feed last."""
    first = (f"x:{nodes} y:1 z:1 t:{frames} type:vec3f systeme:little_endian "
             f"org_t:{org_t!r} inc_t:{inc_t!r} dim_t:{(frames - 1) * inc_t if frames else 0.0!r} "
             f"unites_t:{unit_t} unites:um\r\n")
    body = first.encode()
    pad = HEADER - len(body) - 1
    if pad < 0:
        raise ValueError("IGB header too long")
    lines, left = [], pad
    while left >= 74:
        lines.append(b" " * 70 + b"\r\n")
        left -= 72
    lines.append(b" " * (left - 2) + b"\r\n" if left >= 2 else b" " * left)
    return body + b"".join(lines) + b"\f"
