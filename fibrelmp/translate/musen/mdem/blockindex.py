"""Where a ``.mdem``'s time points are: its block descriptors as arrays (``BlockIndex``) and
which block holds time point i (``PointIndex``), so that one time point is found by number
without decoding the others (``MdemFile.count``/``time_point``, docs/musen.md section 5)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from fibrelmp.translate.musen.mdem.document import MdemFile


@dataclass(frozen=True)
class BlockIndex:
    """The file's block descriptors (``ProtoBlockDescriptor``, in file order) as arrays: a
    million time points cost a few arrays, not a million protobuf messages."""

    start_time: np.ndarray                 # (k,) float64
    offset: np.ndarray                     # (k,) int64: in the time-dependent file thread
    size: np.ndarray                       # (k,) int64: stored bytes
    uncompressed_size: np.ndarray          # (k,) int64
    format: np.ndarray                     # (k,) int64: PLAIN, ZIPPED (or 0 for empty)

    @classmethod
    def of_messages(cls, blocks: Any) -> "BlockIndex":
        """From parsed ``ProtoBlockDescriptor`` messages (the path without the C helpers)."""
        ints = np.array([(d.offset_in_file, d.size, d.uncompressed_size, d.format) for d in blocks],
                        np.int64).reshape(-1, 4)
        return cls(np.array([d.start_time for d in blocks], float), *ints.T)

    def __len__(self) -> int:
        return len(self.start_time)


@dataclass(frozen=True)
class PointIndex:
    """Where each time point lies: block b holds time points first[b] .. first[b + 1] - 1.

    ``of_saved_times``: from the file's saved times (``savedTimePoints``, MUSEN's own list of
    time points, distinct) and the blocks' start times, without reading a block -- when they
    agree as MUSEN writes them (each block starts at a saved time; times increase): time
    point i is then the one saved at time i, as MUSEN numbers them.  The block read for it is
    checked (its number of time points, the time found) and a disagreement is an InputError
    (a file whose blocks hold other time points than its saved times list).  Else
    ``counted``: every block's time points counted (read through, not decoded), the numbering
    of ``time_points()``, as slow as reading them all."""

    first: np.ndarray              # (blocks + 1,) int64
    times: np.ndarray | None       # (total,) the saved times (None when counted)
    counted: bool

    @property
    def total(self) -> int:
        return int(self.first[-1])

    def held(self, block: int) -> int:
        return int(self.first[block + 1] - self.first[block])

    @classmethod
    def of_saved_times(cls, mdem: "MdemFile") -> "PointIndex | None":
        saved, starts = mdem._saved, mdem.blocks.start_time
        if not saved.size or not np.isfinite(saved).all() or not np.isfinite(starts).all() \
                or (np.diff(starts) <= 0).any():
            return None
        first = mdem._saved_before
        if first[0] != 0 or first[-1] >= len(saved) or (saved[first] != starts).any():
            return None
        return cls(np.append(first, len(saved)).astype(np.int64), saved, False)

    @classmethod
    def counted(cls, mdem: "MdemFile") -> "PointIndex":
        held = np.zeros(len(mdem.blocks), np.int64)
        for index in range(len(mdem.blocks)):
            with mdem._block_errors(index):
                held[index] = sum(1 for _ in mdem._point_payloads(index))
        return cls(np.concatenate([[0], np.cumsum(held)]).astype(np.int64), None, True)


def distinct(times: np.ndarray) -> np.ndarray:
    """The distinct values of ``times``, sorted (without sorting what already is)."""
    return times if (np.diff(times) > 0).all() else np.unique(times)


def cut(raw: bytes, spans: np.ndarray) -> bytes:
    """``raw`` without the byte ranges ``spans`` (sorted, disjoint)."""
    if not len(spans):
        return raw
    parts, at = [], 0
    with memoryview(raw) as view:
        for start, end in spans.tolist():
            parts.append(view[at:start])
            at = end
        parts.append(view[at:])
        return b"".join(parts)
