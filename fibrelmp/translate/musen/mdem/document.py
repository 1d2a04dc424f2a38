"""A MUSEN ``.mdem`` file as a scene message plus a stream of time points.

``MdemFile`` opens a file: the time-independent ``ProtoSimulationStorage`` (scene, materials,
geometries, models, block descriptors) is decoded at once; time points are decoded one block
at a time when asked for, so memory does not grow with their number.  ``copy_to`` writes the
file back unchanged (same layout, same bytes).

``MdemWriter`` writes a new file: time points are compressed and written as they come (one
block each, as MUSEN saves them), the scene message at the end, with the descriptors, saved
times and begin/end time of what was written.  Memory holds one time point at a time.
"""

from __future__ import annotations

import os
import zlib
from pathlib import Path
from typing import Any, BinaryIO, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.mdem import bounds, timepoints
from fibrelmp.translate.musen.mdem.container import Container, ContainerWriter, Layout
from fibrelmp.translate.musen.mdem.messages import new

ZIPPED = 2            # ProtoBlockDescriptor.format: kZippedProtoBuff
PLAIN = 1             # kProtoBuf
_LEVEL = 1            # MUSEN's GzipOutputStream compression level


def _inflate(data: bytes, limit: int | None, what: str, path: Path,
             limit_is: str = "its descriptor says") -> bytes:
    """zlib data, decompressed (at most ``limit`` bytes if given: memory holds no more)."""
    d = zlib.decompressobj()
    try:
        out = d.decompress(data, 0 if limit is None else max(limit, 1))
        if limit is not None and (d.unconsumed_tail or len(out) > limit):
            raise InputError(path, None, f"corrupt .mdem file: {what} is larger than "
                             f"{limit_is} ({limit} bytes)")
        if not d.eof:
            raise InputError(path, None, f"truncated .mdem file: {what} ends early")
    except zlib.error as exc:
        raise InputError(path, None, f"corrupt .mdem file: {what} cannot be decompressed ({exc})") from None
    return out


class MdemFile:
    """An open ``.mdem`` file (use as a context manager, or ``close()``)."""

    def __init__(self, path: str | os.PathLike):
        from google.protobuf.message import DecodeError

        self.path = Path(path)
        self.container = Container(self.path)
        try:
            packed = self.container.read(0, 0, self.container.sizes[0])
            raw = _inflate(packed, bounds.scene_limit(len(packed)), "the scene (file thread 0)",
                           self.path, f"a MUSEN scene of {len(packed)} stored bytes decompresses "
                           f"to ({bounds.SCENE_RATIO}x + {bounds.SCENE_SLACK >> 20} MiB)")
            self._check_scene_messages(raw, len(packed))
            try:
                self.storage: Any = new("ProtoSimulationStorage", raw)
            except DecodeError:
                raise InputError(self.path, None, "corrupt .mdem file: the scene message cannot "
                                 "be decoded") from None
            self._check_blocks()
            self._check_layout()
        except BaseException:
            self.container.close()
            raise

    def _check_scene_messages(self, raw: bytes, stored: int) -> None:
        """Count the scene's messages on the wire before protobuf allocates them (~80 bytes
        each, from 2 bytes of wire): at most ``bounds.message_budget`` of its stored size."""
        budget = bounds.message_budget(stored)
        try:
            bounds.count_messages(raw, "ProtoSimulationStorage", budget)
        except bounds.TooMany:
            raise InputError(self.path, None, f"corrupt .mdem file: the scene (file thread 0, "
                             f"{stored} bytes stored) lists more than {budget} objects and other "
                             f"entries, more than a MUSEN file of its size holds (at most "
                             f"{bounds.MESSAGES_PER_BYTE} per stored byte + "
                             f"{bounds.MESSAGES_SLACK}; each costs ~80 bytes of memory); "
                             "refused before allocating them") from None
        except ValueError as exc:
            raise InputError(self.path, None, f"corrupt .mdem file: the scene message cannot "
                             f"be decoded ({exc})") from None

    def _check_blocks(self) -> None:
        size = self.container.sizes[1]
        if not len(self.storage.data_blocks):
            raise InputError(self.path, None, "corrupt .mdem file: it lists no time-point blocks")
        for i, d in enumerate(self.storage.data_blocks):
            if d.offset_in_file < 0 or d.size < 0 or d.offset_in_file + d.size > size:
                raise InputError(self.path, None, f"truncated .mdem file: time-point block {i} "
                                 f"(bytes {d.offset_in_file}..{d.offset_in_file + d.size} of the "
                                 f"time-dependent data) lies beyond its end ({size} bytes)")
            if d.uncompressed_size < 0 or (d.format == ZIPPED and d.size and not d.uncompressed_size):
                raise InputError(self.path, None, f"corrupt .mdem file: time-point block {i} has "
                                 f"uncompressed size {d.uncompressed_size}")
            if d.format not in (PLAIN, ZIPPED) and d.size:
                raise InputError(self.path, None, f"unsupported .mdem file: time-point block {i} "
                                 f"has storage format {d.format}")
        self.block_times = [d.start_time for d in self.storage.data_blocks]
        self._block_limits = self._check_block_sizes()

    def _check_block_sizes(self) -> list[int]:
        """The most bytes each time-point block may decompress to: its declared size, which
        must fit both zlib's largest expansion of its stored bytes and what its time points
        can hold for the scene's objects (``bounds.block_bound``); checked for every block
        here, before any is decompressed."""
        entries = len(self.storage.info.particles)
        # distinct: MUSEN writes one time point per time (and one per block)
        saved = np.unique(np.array(self.storage.info.savedTimePoints, dtype=float))
        # a block holds the saved times from its start up to the next block's (one where the
        # file lists no saved times)
        starts = np.array(self.block_times + [np.inf])
        counts = (np.searchsorted(saved, starts[1:]) - np.searchsorted(saved, starts[:-1])
                  if saved.size else np.ones(len(self.block_times), int))
        limits = []
        self._block_points = []
        for i, d in enumerate(self.storage.data_blocks):
            points = max(int(counts[i]), 1)
            self._block_points.append(points)
            need = bounds.block_bound(entries, points)
            if d.format != ZIPPED:
                limits.append(d.size)
                continue
            where = f"corrupt .mdem file: time-point block {i} declares {d.uncompressed_size} bytes"
            if d.uncompressed_size > bounds.ZLIB_MAX_RATIO * d.size + 64:
                raise InputError(self.path, None, f"{where} from {d.size} stored bytes, more than "
                                 f"zlib can expand them to ({bounds.ZLIB_MAX_RATIO}x)")
            if d.uncompressed_size > need:
                raise InputError(self.path, None, f"{where}, more than {points} time "
                                 f"point(s) of a scene of {entries} objects can take (at most "
                                 f"{need} bytes: {bounds.MAX_ENTRY} per object entry); refused "
                                 "before decompressing it")
            limits.append(d.uncompressed_size)
        return limits

    def _check_layout(self) -> None:
        """Files of header version 0 may keep the oldest time-point layout (Euler angles,
        wall vertices in ``angles``/``angle_accl``), which MUSEN converts with its file
        converter on opening (``IsOldFileVersion``); fibrelmp reads only the current one."""
        if self.container.version >= 1 or self.info.file_version >= 1:
            return
        first = next((i for i, p in enumerate(self.info.particles) if p.type in (1, 14)), None)
        if first is None:
            return
        _, _, masks = next(self.time_points())
        if first >= len(masks) or not masks[first] >> timepoints.FIELDS["quaternion"][0] & 1:
            raise InputError(self.path, None, "a MUSEN file of the oldest layout (file version 0, "
                             "orientations as angles): open it in MUSEN and save it once, which "
                             "converts it to the current layout, then use that file")

    # -- scene ----------------------------------------------------------------------------
    @property
    def info(self) -> Any:
        return self.storage.info

    @property
    def version(self) -> int:
        return self.container.version

    def times(self) -> np.ndarray:
        """The saved times (``savedTimePoints``; for old files without it, the blocks')."""
        saved = np.array(self.info.savedTimePoints, dtype=float)
        if saved.size:
            return saved
        return np.array([tp[0] for tp in self.time_points(decode=False)])

    # -- time points ----------------------------------------------------------------------
    def block_raw(self, index: int) -> bytes:
        """Compressed bytes of time-point block ``index`` as stored."""
        d = self.storage.data_blocks[index]
        return self.container.read(1, d.offset_in_file, d.size)

    def block_bytes(self, index: int) -> bytes:
        """The serialized ``ProtoBlockOfTimePoints`` of block ``index``."""
        d = self.storage.data_blocks[index]
        raw = self.block_raw(index)
        if d.format == ZIPPED:
            raw = _inflate(raw, self._block_limits[index], f"time-point block {index}", self.path)
        return raw

    def block(self, index: int) -> Any:
        """The decoded ``ProtoBlockOfTimePoints`` of block ``index``."""
        from google.protobuf.message import DecodeError

        try:
            return new("ProtoBlockOfTimePoints", self.block_bytes(index))
        except DecodeError:
            raise InputError(self.path, None, f"corrupt .mdem file: time-point block {index} "
                             "cannot be decoded") from None

    def time_points(self, decode: bool = True) -> Iterator[tuple[float, np.ndarray, np.ndarray] | tuple[float]]:
        """Every stored time point in order: (time, values (n, 34), masks (n,)) -- see
        ``timepoints`` -- one time point in memory at a time (blocks are decompressed as
        they are read); ``decode=False`` gives (time,)."""
        # entries of removed trailing objects may outlast the object list a little; far more
        # is a hostile file (each empty entry costs 2 bytes, 276 decoded)
        most = bounds.objects_per_point(len(self.info.particles))
        for index in range(len(self.storage.data_blocks)):
            try:
                for payload in self._point_payloads(index):
                    yield timepoints.decode(payload, most) if decode else (timepoints.time_of(payload),)
            except ValueError as exc:
                raise InputError(self.path, None, f"corrupt .mdem file: time-point block "
                                 f"{index}: {exc}") from None

    def _point_payloads(self, index: int) -> Iterator[bytes]:
        """The serialized time points of block ``index`` (field 2 of its
        ``ProtoBlockOfTimePoints``; other fields skipped), decompressed as they are read: at
        most ``bounds.block_bound(n, 1)`` bytes each and as many as the block's saved times."""
        d = self.storage.data_blocks[index]
        stream = _BlockStream(self.block_raw(index), d.format == ZIPPED, self._block_limits[index],
                              f"time-point block {index}", self.path)
        most_bytes = bounds.block_bound(len(self.info.particles), 1)
        points = 0
        while not stream.done():
            tag = stream.varint()
            if tag < 8:                  # field number 0: not protobuf (e.g. a run of zeros)
                raise ValueError("field number 0 (not a protobuf message)")
            wire = tag & 7
            if wire == 2:
                size = stream.varint()
                if tag >> 3 != 2:
                    stream.skip(size)
                    continue
                if size > most_bytes:
                    raise ValueError(f"a time point of {size} bytes, more than the scene's "
                                     f"{len(self.info.particles)} objects can take ({most_bytes})")
                points += 1
                if points > self._block_points[index]:
                    raise ValueError(f"more than the {self._block_points[index]} time point(s) "
                                     "the file's saved times place in it")
                yield stream.read(size)
            elif wire == 0:
                stream.varint()
            elif wire in (1, 5):
                stream.skip(8 if wire == 1 else 4)
            else:
                raise ValueError(f"unknown wire type {wire}")

    # -- whole file -----------------------------------------------------------------------
    def copy_to(self, fh: BinaryIO) -> None:
        """Write this file again: every message re-serialized, every block re-compressed
        (MUSEN's zlib level 1), at the offsets they had; the result equals the input byte
        for byte (tests show it)."""
        layout: Layout = self.container.layout()
        out = ContainerWriter(fh, layout)
        for index, d in enumerate(self.storage.data_blocks):
            # read through once a time point at a time (one in memory), so that a block of
            # garbage is refused before it is decompressed whole
            try:
                for _ in self._point_payloads(index):
                    pass
            except ValueError as exc:
                raise InputError(self.path, None, f"corrupt .mdem file: time-point block "
                                 f"{index}: {exc}") from None
            stored = self.block_raw(index)
            block = self.block(index).SerializeToString()
            again = zlib.compress(block, _LEVEL) if d.format == ZIPPED else block
            # another zlib (or level) than MUSEN's gives other bytes for the same message:
            # then the stored bytes, which hold the same message, are written
            out.write(1, d.offset_in_file, again if again == stored else stored)
        stored = self.container.read(0, 0, self.container.sizes[0])
        again = zlib.compress(self.storage.SerializeToString(), _LEVEL)
        out.write(0, 0, again if again == stored else stored)
        out.finish()

    def close(self) -> None:
        self.container.close()

    def __enter__(self) -> "MdemFile":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class MdemWriter:
    """Writes a new ``.mdem`` to an open binary file: ``add`` time points (each compressed
    and written at once), then ``finish(storage)`` with the scene message."""

    def __init__(self, fh: BinaryIO):
        self.out = ContainerWriter(fh)
        self.out._block(0, 0)              # the scene's first block first, as MUSEN places it
        self.end = 0                       # bytes of time-dependent data written
        self.blocks: list[tuple[float, int, int, int]] = []   # time, offset, size, raw size

    def add(self, time: float, values: np.ndarray, masks: np.ndarray) -> None:
        """One time point (one block, as MUSEN's simulator saves)."""
        block = _field2(timepoints.encode(time, values, masks))   # ProtoBlockOfTimePoints
        packed = zlib.compress(block, _LEVEL)
        self.out.write(1, self.end, packed)
        self.blocks.append((float(time), self.end, len(packed), len(block)))
        self.end += len(packed)

    def finish(self, storage: Any) -> None:
        """Write ``storage`` (its block descriptors, saved times and begin/end time are set
        to what ``add`` wrote) and the headers."""
        if not self.blocks:                                # MUSEN files always have a block
            self.add(0.0, np.zeros((0, timepoints.NCOLS)), np.zeros(0, np.uint32))
        del storage.data_blocks[:]
        info = storage.info
        del info.savedTimePoints[:]
        for time, offset, size, raw in self.blocks:
            d = storage.data_blocks.add()
            d.start_time, d.offset_in_file, d.size, d.uncompressed_size = time, offset, size, raw
            d.format = ZIPPED
            info.savedTimePoints.append(time)
        times = [b[0] for b in self.blocks]
        info.begin_time = min(0.0, min(times))
        info.end_time = max(times)
        self.out.write(0, 0, zlib.compress(storage.SerializeToString(), _LEVEL))
        self.out.finish()


class _BlockStream:
    """A time-point block's bytes, decompressed 1 MiB at a time as they are read (at most
    ``limit`` bytes in all: the block's declared size); ValueError past its end."""

    _CHUNK = 1 << 20

    def __init__(self, raw: bytes, zipped: bool, limit: int, what: str, path: Path):
        self.inflater = zlib.decompressobj() if zipped else None
        self.pending = raw if zipped else b""
        self.buf = bytearray() if zipped else bytearray(raw)
        self.pos = 0
        self.total = 0 if zipped else len(raw)
        self.limit, self.what, self.path = limit, what, path

    def _fill(self, need: int) -> None:
        while len(self.buf) - self.pos < need and self.inflater is not None and not self.inflater.eof:
            try:
                # what is needed in one piece (a time point is bounded before it is read)
                out = self.inflater.decompress(self.pending,
                                               max(self._CHUNK, need - len(self.buf) + self.pos))
            except zlib.error as exc:
                raise InputError(self.path, None, f"corrupt .mdem file: {self.what} cannot be "
                                 f"decompressed ({exc})") from None
            self.pending = self.inflater.unconsumed_tail
            self.total += len(out)
            if self.total > self.limit:
                raise InputError(self.path, None, f"corrupt .mdem file: {self.what} is larger "
                                 f"than its descriptor says ({self.limit} bytes)")
            if not out and not self.pending and not self.inflater.eof:
                raise InputError(self.path, None, f"truncated .mdem file: {self.what} ends early")
            if self.pos == len(self.buf):
                self.buf, self.pos = bytearray(out), 0
            else:
                del self.buf[:self.pos]
                self.pos = 0
                self.buf += out

    def done(self) -> bool:
        self._fill(1)
        return len(self.buf) == self.pos

    def read(self, size: int) -> bytes:
        self._fill(size)
        if len(self.buf) - self.pos < size:
            raise ValueError("a field runs past its message")
        with memoryview(self.buf) as view:
            out = bytes(view[self.pos:self.pos + size])
        self.pos += size
        return out

    def skip(self, size: int) -> None:
        while size:
            step = min(size, self._CHUNK)
            self.read(step)
            size -= step

    def varint(self) -> int:
        self._fill(10)
        value, at = _varint(self.buf, self.pos)
        self.pos = at
        return value


def _varint(data: bytes, at: int) -> tuple[int, int]:
    value = shift = 0
    while True:
        if at >= len(data) or shift > 63:
            raise ValueError("a varint runs past its message")
        byte = data[at]
        value |= (byte & 0x7F) << shift
        at += 1
        if byte < 0x80:
            return value, at
        shift += 7


def _field2(payload: bytes) -> bytes:
    """``payload`` as field 2 (length-delimited) of a message."""
    n, head = len(payload), bytearray([0x12])
    while n >= 0x80:
        head.append(n & 0x7F | 0x80)
        n >>= 7
    head.append(n)
    return bytes(head) + payload
