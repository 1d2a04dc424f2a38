"""A MUSEN ``.mdem`` file as a scene message plus a stream of time points.

``MdemFile`` opens a file: the time-independent ``ProtoSimulationStorage`` (scene, materials,
geometries, models) is decoded at once, its block descriptors into arrays (``BlockIndex``: a
million time points are a million blocks); time points are decoded one block at a time when
asked for, all in order or one by number, so memory does not grow with their number beyond
that index.  ``copy_to`` writes the file back unchanged (same layout, same bytes).

``MdemWriter`` writes a new file: time points are compressed and written as they come (one
block each, as MUSEN saves them), the scene message at the end, with the descriptors, saved
times and begin/end time of what was written.  Memory holds two time points (the one being
compressed on the helper thread and the next).
"""

from __future__ import annotations

import contextlib
import os
import zlib
from array import array
from pathlib import Path
from typing import Any, BinaryIO, Callable, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.numtext import fast
from fibrelmp.translate.musen.mdem import bounds, timepoints
from fibrelmp.translate.musen.mdem.blockindex import BlockIndex, PointIndex, cut, distinct
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
    """An open ``.mdem`` file (use as a context manager, or ``close()``).

    ``scene`` is the ``ProtoSimulationStorage`` without its block descriptors, which are in
    ``blocks`` (a ``BlockIndex``); ``storage`` is the whole message, parsed when first asked
    for.  ``time_points()`` streams every time point; ``count()`` and ``time_point(i)`` find
    one without decoding the others (see ``_locate``)."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self.container = Container(self.path)
        self._storage: Any = None
        self._points: PointIndex | None = None
        try:
            stored = self.container.sizes[0]
            raw = self._inflate_scene(self.container.read(0, 0, stored))
            try:                            # the count is bounded before arrays are made
                split = fast.mdem_blocks(raw, bounds.message_budget(stored))
            except OverflowError:
                raise self._too_many(stored) from None
            if split is None:               # no C helpers, or an unusual message: protobuf
                self._check_scene_messages(raw, stored, 0)
                self.scene: Any = self._parse(raw)
                self.blocks = BlockIndex.of_messages(self.scene.data_blocks)
                self.scene.ClearField("data_blocks")       # as the scan leaves it
            else:
                start, ints, spans = split
                raw = cut(raw, spans)      # memory: the descriptors' bytes are let go
                self._check_scene_messages(raw, stored, len(start))
                self.scene = self._parse(raw)
                self.blocks = BlockIndex(start, *ints)
            del raw
            self._check_blocks()
            self._check_layout()
        except BaseException:
            self.container.close()
            raise

    def _inflate_scene(self, packed: bytes) -> bytes:
        return _inflate(packed, bounds.scene_limit(len(packed)), "the scene (file thread 0)",
                        self.path, f"a MUSEN scene of {len(packed)} stored bytes decompresses "
                        f"to ({bounds.SCENE_RATIO}x + {bounds.SCENE_SLACK >> 20} MiB)")

    def _parse(self, raw: bytes) -> Any:
        from google.protobuf.message import DecodeError

        try:
            return new("ProtoSimulationStorage", raw)
        except DecodeError:
            raise InputError(self.path, None, "corrupt .mdem file: the scene message cannot "
                             "be decoded") from None

    @property
    def storage(self) -> Any:
        """The whole ``ProtoSimulationStorage`` (with its block descriptors), parsed at the
        first use (checked against the memory bounds when the file was opened)."""
        if self._storage is None:
            packed = self.container.read(0, 0, self.container.sizes[0])
            self._storage = self._parse(self._inflate_scene(packed))
        return self._storage

    def _check_scene_messages(self, raw: bytes, stored: int, descriptors: int) -> None:
        """Count the scene's messages on the wire before protobuf allocates them (~80 bytes
        each, from 2 bytes of wire): at most ``bounds.message_budget`` of its stored size,
        ``descriptors`` (block descriptors already cut out of ``raw``) included."""
        budget = bounds.message_budget(stored)
        try:
            if descriptors > budget:
                raise bounds.TooMany(f"more than {budget} messages")
            bounds.count_messages(raw, "ProtoSimulationStorage", budget - descriptors)
        except bounds.TooMany:
            raise self._too_many(stored) from None
        except ValueError as exc:
            raise InputError(self.path, None, f"corrupt .mdem file: the scene message cannot "
                             f"be decoded ({exc})") from None

    def _too_many(self, stored: int) -> InputError:
        return InputError(self.path, None, f"corrupt .mdem file: the scene (file thread 0, "
                          f"{stored} bytes stored) lists more than {bounds.message_budget(stored)} "
                          f"objects and other entries, more than a MUSEN file of its size holds "
                          f"(at most {bounds.MESSAGES_PER_BYTE} per stored byte + "
                          f"{bounds.MESSAGES_SLACK}; each costs ~80 bytes of memory); refused "
                          "before allocating them")

    def _check_blocks(self) -> None:
        """Every descriptor checked at once (numpy); the first bad block is reported."""
        b, size = self.blocks, self.container.sizes[1]
        if not len(b):
            raise InputError(self.path, None, "corrupt .mdem file: it lists no time-point blocks")
        outside = (b.offset < 0) | (b.size < 0) | (b.offset > size - b.size)
        bad_size = (b.uncompressed_size < 0) | ((b.format == ZIPPED) & (b.size != 0)
                                                & (b.uncompressed_size == 0))
        bad_format = (b.format != PLAIN) & (b.format != ZIPPED) & (b.size != 0)
        wrong = np.flatnonzero(outside | bad_size | bad_format)
        if len(wrong):
            i = int(wrong[0])
            offset, stored = int(b.offset[i]), int(b.size[i])
            if outside[i]:
                raise InputError(self.path, None, f"truncated .mdem file: time-point block {i} "
                                 f"(bytes {offset}..{offset + stored} of the time-dependent "
                                 f"data) lies beyond its end ({size} bytes)")
            if bad_size[i]:
                raise InputError(self.path, None, f"corrupt .mdem file: time-point block {i} has "
                                 f"uncompressed size {int(b.uncompressed_size[i])}")
            raise InputError(self.path, None, f"unsupported .mdem file: time-point block {i} "
                             f"has storage format {int(b.format[i])}")
        self._block_limits = self._check_block_sizes()

    def _check_block_sizes(self) -> np.ndarray:
        """The most bytes each time-point block may decompress to: its declared size, which
        must fit both zlib's largest expansion of its stored bytes and what its time points
        can hold for the scene's objects (``bounds.block_bound``); checked for every block
        here, before any is decompressed."""
        b = self.blocks
        entries = len(self.info.particles)
        # distinct: MUSEN writes one time point per time (and one per block)
        saved = self._saved = distinct(np.asarray(self.info.savedTimePoints, dtype=float))
        # a block holds the saved times from its start up to the next block's (one where the
        # file lists no saved times)
        # saved times before each block's start (MUSEN: one block per saved time, no search)
        self._saved_before = (np.arange(len(b)) if np.array_equal(saved, b.start_time)
                              else np.searchsorted(saved, b.start_time))
        counts = (np.diff(np.append(self._saved_before, len(saved)))
                  if saved.size else np.ones(len(b), np.int64))
        self._block_points = np.maximum(counts, 1)
        # float: exact below 2**53, and a declared size (int32) above it is never refused
        need = self._block_points * float(bounds.block_bound(entries, 1))
        zipped = b.format == ZIPPED
        too_zipped = zipped & (b.uncompressed_size > bounds.ZLIB_MAX_RATIO * b.size + 64)
        too_many = zipped & (b.uncompressed_size > need)
        wrong = np.flatnonzero(too_zipped | too_many)
        if len(wrong):
            i = int(wrong[0])
            where = (f"corrupt .mdem file: time-point block {i} declares "
                     f"{int(b.uncompressed_size[i])} bytes")
            if too_zipped[i]:
                raise InputError(self.path, None, f"{where} from {int(b.size[i])} stored bytes, "
                                 f"more than zlib can expand them to ({bounds.ZLIB_MAX_RATIO}x)")
            points = int(self._block_points[i])
            raise InputError(self.path, None, f"{where}, more than {points} time "
                             f"point(s) of a scene of {entries} objects can take (at most "
                             f"{bounds.block_bound(entries, points)} bytes: {bounds.MAX_ENTRY} "
                             "per object entry); refused before decompressing it")
        return np.where(zipped, b.uncompressed_size, b.size)

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
        return self.scene.info

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
        return self.container.read(1, int(self.blocks.offset[index]), int(self.blocks.size[index]))

    def block_bytes(self, index: int) -> bytes:
        """The serialized ``ProtoBlockOfTimePoints`` of block ``index``."""
        raw = self.block_raw(index)
        if self.blocks.format[index] == ZIPPED:
            raw = _inflate(raw, int(self._block_limits[index]), f"time-point block {index}", self.path)
        return raw

    def block(self, index: int) -> Any:
        """The decoded ``ProtoBlockOfTimePoints`` of block ``index``."""
        from google.protobuf.message import DecodeError

        try:
            return new("ProtoBlockOfTimePoints", self.block_bytes(index))
        except DecodeError:
            raise InputError(self.path, None, f"corrupt .mdem file: time-point block {index} "
                             "cannot be decoded") from None

    def time_points(self, decode: bool = True, wanted: Callable[[float], bool] | None = None
                    ) -> Iterator[tuple[float, np.ndarray, np.ndarray] | tuple[float]]:
        """Every stored time point in order: (time, values (n, 34), masks (n,)) -- see
        ``timepoints`` -- one time point in memory at a time (blocks are decompressed as
        they are read); ``decode=False`` gives (time,); ``wanted(time)`` false: the point is
        skipped undecoded."""
        for index in range(len(self.blocks)):
            with self._block_errors(index):
                for payload in self._point_payloads(index):
                    if not decode:
                        yield (timepoints.time_of(payload),)
                    elif wanted is None or wanted(timepoints.time_of(payload)):
                        yield self._decode(payload)

    def count(self) -> int:
        """The number of time points ``time_points()`` gives (see ``_locate``)."""
        return self._point_index().total

    def time_point(self, index: int) -> tuple[float, np.ndarray, np.ndarray]:
        """Time point ``index`` (0 <= index < ``count()``), decoding only the block that
        holds it (see ``PointIndex``)."""
        points = self._point_index()
        if not 0 <= index < points.total:
            raise IndexError(f"time point {index} of {points.total}")
        block = int(np.searchsorted(points.first, index, "right")) - 1
        wanted, held, found = index - int(points.first[block]), 0, None
        with self._block_errors(block):
            for payload in self._point_payloads(block):
                if held == wanted:
                    found = self._decode(payload)
                held += 1
        if points.counted:                  # counted from these very blocks: always found
            assert found is not None, "a counted index finds its time points"
            return found
        expected = points.times[index]
        if found is None or held != points.held(block) or found[0] != expected:
            got = "" if found is None else f", the {wanted + 1}. at {found[0]!r} s"
            raise InputError(self.path, None, f"corrupt .mdem file: time-point block {block} "
                             f"holds {held} time point(s){got}, where the file's saved times "
                             f"(savedTimePoints) place {points.held(block)} from "
                             f"{points.times[points.first[block]]!r} s (time point {index} at "
                             f"{expected!r} s)")
        return found

    def _point_index(self) -> "PointIndex":
        if self._points is None:
            self._points = PointIndex.of_saved_times(self) or PointIndex.counted(self)
        return self._points

    def _decode(self, payload: bytes) -> tuple[float, np.ndarray, np.ndarray]:
        # entries of removed trailing objects may outlast the object list a little; far more
        # is a hostile file (each empty entry costs 2 bytes, 276 decoded)
        return timepoints.decode(payload, bounds.objects_per_point(len(self.info.particles)))

    @contextlib.contextmanager
    def _block_errors(self, index: int) -> Iterator[None]:
        try:
            yield
        except ValueError as exc:
            raise InputError(self.path, None, f"corrupt .mdem file: time-point block "
                             f"{index}: {exc}") from None

    def _point_payloads(self, index: int) -> Iterator[bytes]:
        """The serialized time points of block ``index`` (field 2 of its
        ``ProtoBlockOfTimePoints``; other fields skipped), decompressed as they are read: at
        most ``bounds.block_bound(n, 1)`` bytes each and as many as the block's saved times."""
        stream = _BlockStream(self.block_raw(index), self.blocks.format[index] == ZIPPED,
                              int(self._block_limits[index]), f"time-point block {index}", self.path)
        most_bytes = bounds.block_bound(len(self.info.particles), 1)
        most_points = int(self._block_points[index])
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
                if points > most_points:
                    raise ValueError(f"more than the {most_points} time point(s) "
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
        """Write this file again, every block at the offset it had: the result equals the
        input byte for byte (tests show it).  Every block is read through (one time point in
        memory at a time, so that a block of garbage is refused before it is decompressed
        whole) and decoded by protobuf before its stored bytes are written."""
        layout: Layout = self.container.layout()
        out = ContainerWriter(fh, layout)
        for index in range(len(self.blocks)):
            with self._block_errors(index):
                for _ in self._point_payloads(index):
                    pass
            self.block(index)
            out.write(1, int(self.blocks.offset[index]), self.block_raw(index))
        out.write(0, 0, self.container.read(0, 0, self.container.sizes[0]))
        out.finish()

    def close(self) -> None:
        self.container.close()

    def __enter__(self) -> "MdemFile":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class MdemWriter:
    """Writes a new ``.mdem`` to an open binary file: ``add`` time points (each compressed
    and written in turn), then ``finish(storage)`` with the scene message.  Memory holds two
    time points (one being compressed) and 32 bytes per time point written (its block
    descriptor, in arrays)."""

    def __init__(self, fh: BinaryIO):
        self.out = ContainerWriter(fh)
        self.out._block(0, 0)              # the scene's first block first, as MUSEN places it
        self.end = 0                       # bytes of time-dependent data written
        # per block: time, offset, stored size, raw size
        self.times, self.offsets, self.sizes, self.raw_sizes = (array("d"), array("q"), array("q"),
                                                                 array("q"))
        self.pending = None                # (time, raw size, future of the compressed block)

    def add(self, time: float, values: np.ndarray, masks: np.ndarray) -> None:
        """One time point (one block, as MUSEN's simulator saves).  A large block is
        compressed on the second core while the caller prepares the next one (memory: two
        time points)."""
        block = _field2(timepoints.encode(time, values, masks))   # ProtoBlockOfTimePoints
        self._drain()
        pool = fast.helper_pool() if len(block) >= fast.SPLIT_BYTES else None
        if pool is None:
            self._store(float(time), len(block), zlib.compress(block, _LEVEL))
        else:
            self.pending = (float(time), len(block), pool.submit(zlib.compress, block, _LEVEL))

    def _drain(self) -> None:
        if self.pending is not None:
            time, raw, job = self.pending
            self.pending = None
            self._store(time, raw, job.result())

    def _store(self, time: float, raw: int, packed: bytes) -> None:
        self.out.write(1, self.end, packed)
        self.times.append(time)
        self.offsets.append(self.end)
        self.sizes.append(len(packed))
        self.raw_sizes.append(raw)
        self.end += len(packed)

    def finish(self, storage: Any) -> None:
        """Write ``storage`` (its block descriptors, saved times and begin/end time are set
        to what ``add`` wrote) and the headers."""
        self._drain()
        if not self.times:                                 # MUSEN files always have a block
            self.add(0.0, np.zeros((0, timepoints.NCOLS)), np.zeros(0, np.uint32))
        times = np.frombuffer(self.times, float)
        del storage.data_blocks[:]
        info = storage.info
        del info.savedTimePoints[:]
        info.savedTimePoints.extend(times)
        info.begin_time = min(0.0, min(self.times))
        info.end_time = max(self.times)
        scene = storage.SerializeToString()
        # the descriptors follow the scene's fields 1 and 2 as protobuf orders them (unless
        # the scene carries unknown fields, which protobuf writes last: then protobuf)
        records = (fast.mdem_put_blocks(times, self.offsets, self.sizes, self.raw_sizes, ZIPPED)
                   if _top_fields(scene) <= {1, 2} else None)
        if records is None:
            for d in zip(times.tolist(), self.offsets, self.sizes, self.raw_sizes):
                storage.data_blocks.add(start_time=d[0], offset_in_file=d[1], size=d[2],
                                        uncompressed_size=d[3], format=ZIPPED)
            scene, records = storage.SerializeToString(), b""
        self.out.write(0, 0, zlib.compress(scene + records, _LEVEL))
        self.out.finish()


def _top_fields(message: bytes) -> set[int]:
    """The field numbers at the top level of a serialized message (a scene: a few records)."""
    numbers, at = set(), 0
    while at < len(message):
        tag, at = _varint(message, at)
        numbers.add(tag >> 3)
        wire = tag & 7
        if wire == 0:
            _, at = _varint(message, at)
        elif wire == 2:
            size, at = _varint(message, at)
            at += size
        else:
            at += {1: 8, 5: 4}.get(wire, len(message))
    return numbers


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
