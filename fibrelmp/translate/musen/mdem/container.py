"""MUSEN's ``.mdem`` container (``MDEMFile.cpp``): a 64-byte file header, one 1024-byte header
per file thread, and blocks of growing size holding each thread's bytes.

Layout (little endian)::

    0     u32 signature 0x12345678, u32 version (2), u32 threads (2), u32 cluster size (4096),
          48 reserved bytes
    64    per thread: 64-byte name ("simulation info" / "time-dependent"), u64 size (bytes of
          data), u64 reserved, 118 x u64 file offsets of the thread's blocks (0 = none)
    2112  blocks; block i holds 1, 1, 2, 3, 4, 6, 8, 12, 16, 24 ... clusters (``block_size``),
          the two threads' blocks interleaved in the order they were needed

Thread 0 is one zlib stream of the ``ProtoSimulationStorage`` message, thread 1 the zlib
streams of the time-point blocks at the offsets the storage message lists.  MUSEN truncates
the file at the end of the last data, so the last block may end beyond the end of the file.

``Container`` reads (and checks) a file and gives a thread's bytes by range, reading only
those blocks; ``ContainerWriter`` writes thread 1 as its blocks come and thread 0 at the end,
allocating blocks as MUSEN does, or at the offsets of a given ``Layout`` (a read file's), so a
read file is written back byte for byte.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from fibrelmp.errors import InputError

SIGNATURE = 0x12345678
FILE_VERSIONS = (0, 1, 2)        # MDEM_FILE_VERSION is 2; 0/1 are older files MUSEN converts
THREAD_NAMES = ("simulation info", "time-dependent")
CLUSTER = 4096
HEADER = 64
THREAD_HEADER = 1024
BLOCKS = 118                     # (1024 - 64 - 8 - 8) / 8 block offsets per thread
DATA_START = HEADER + THREAD_HEADER * len(THREAD_NAMES)
_FILE = struct.Struct("<4I48x")
_THREAD = struct.Struct(f"<64sQQ{BLOCKS}Q")


def block_size(index: int, cluster: int = CLUSTER) -> int:
    """Bytes of block ``index`` (``CMDEMFile::GetBlockSizeByIndex``)."""
    if index == 0:
        return cluster
    if index < 5:
        return index * cluster
    clusters = 4
    for step in range(index - 4):
        clusters = clusters // 2 * 3 if step % 2 == 0 else clusters // 3 * 4
    return clusters * cluster


_STARTS = [0]
for _i in range(BLOCKS):
    _STARTS.append(_STARTS[-1] + block_size(_i))


def locate(address: int) -> tuple[int, int]:
    """(block index, offset in it) of a thread address (``GetBlockByAddress``)."""
    import bisect

    index = bisect.bisect_right(_STARTS, address) - 1
    if index >= BLOCKS:
        raise ValueError(f"address {address} is beyond the last block")
    return index, address - _STARTS[index]


@dataclass(frozen=True)
class Layout:
    """Where each thread's blocks sit in a file (as read), and the file version."""

    offsets: tuple[tuple[int, ...], ...]     # per thread: file offsets of blocks 0, 1, ...
    version: int = 2
    # bytes of the file outside the headers and the threads' data: what earlier, longer
    # saves left in unused block space (MUSEN never reads them); kept so that a file read
    # and written back is the same byte for byte
    stale: tuple[tuple[int, bytes], ...] = ()


class Container:
    """An open ``.mdem`` file: checked headers, and thread bytes by range."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        try:
            self._fh: BinaryIO = open(self.path, "rb")
        except OSError as exc:
            raise InputError(self.path, None, f"cannot read: {exc.strerror or exc}") from None
        try:
            self._read_headers()
        except BaseException:
            self._fh.close()
            raise

    def error(self, message: str) -> InputError:
        return InputError(self.path, None, message)

    def _read_headers(self) -> None:
        self.file_size = os.fstat(self._fh.fileno()).st_size
        head = self._fh.read(DATA_START)
        if len(head) < 8 or struct.unpack_from("<I", head)[0] != SIGNATURE:
            raise self.error("not a MUSEN .mdem file (no signature 0x12345678 at its start)")
        if len(head) < DATA_START:
            raise self.error(f"truncated .mdem file: {len(head)} bytes, shorter than its headers "
                             f"({DATA_START} bytes)")
        _, self.version, threads, self.cluster = _FILE.unpack_from(head)
        if self.version not in FILE_VERSIONS:
            raise self.error(f"unsupported .mdem file version {self.version} (this fibrelmp reads "
                             f"versions {', '.join(map(str, FILE_VERSIONS))}; MUSEN 1.74 writes 2)")
        if threads != len(THREAD_NAMES) or self.cluster != CLUSTER:
            raise self.error(f"unsupported .mdem layout: {threads} file threads of cluster size "
                             f"{self.cluster} (MUSEN writes 2 threads, cluster size {CLUSTER})")
        self.sizes: list[int] = []
        self.offsets: list[tuple[int, ...]] = []
        for t, expected in enumerate(THREAD_NAMES):
            name, size, _, *offsets = _THREAD.unpack_from(head, HEADER + t * THREAD_HEADER)
            name = name.split(b"\0", 1)[0].decode("latin-1")
            if name != expected:
                raise self.error(f"file thread {t} is {name!r}, expected {expected!r}")
            used = 0
            while used < BLOCKS and offsets[used]:
                used += 1
            if size > _STARTS[used]:
                raise self.error(f"corrupt .mdem file: thread {name!r} holds {size} bytes but its "
                                 f"blocks only {_STARTS[used]}")
            # every block that holds data must lie inside the file (the last one up to its data)
            for i in range(used):
                need = min(block_size(i), size - _STARTS[i]) if size > _STARTS[i] else 0
                if need and (offsets[i] < DATA_START or offsets[i] + need > self.file_size):
                    raise self.error(f"truncated .mdem file: block {i} of thread {name!r} "
                                     f"(bytes {offsets[i]}..{offsets[i] + need}) lies beyond the end "
                                     f"of the file ({self.file_size} bytes)")
            self.sizes.append(size)
            self.offsets.append(tuple(offsets[:used]))

    def data_ranges(self) -> list[tuple[int, int]]:
        """(start, end) file offsets of the headers and of every thread's data."""
        ranges = [(0, DATA_START)]
        for t, size in enumerate(self.sizes):
            for i, offset in enumerate(self.offsets[t]):
                n = min(block_size(i), size - _STARTS[i])
                if n > 0:
                    ranges.append((offset, offset + n))
        return sorted(ranges)

    def layout(self, keep_stale: bool = True) -> Layout:
        """This file's layout; with ``keep_stale`` also its unused bytes (see ``Layout``)."""
        stale = []
        if keep_stale:
            at = 0
            for start, end in self.data_ranges() + [(self.file_size, self.file_size)]:
                if start > at:
                    self._fh.seek(at)
                    chunk = self._fh.read(start - at)
                    if chunk.strip(b"\0"):
                        stale.append((at, chunk))
                at = max(at, end)
        return Layout(tuple(self.offsets), self.version, tuple(stale))

    def read(self, thread: int, start: int, size: int) -> bytes:
        """``size`` bytes of ``thread`` from ``start`` (reads only the blocks involved)."""
        if start < 0 or size < 0 or start + size > self.sizes[thread]:
            raise self.error(f"corrupt .mdem file: bytes {start}..{start + size} requested from "
                             f"thread {THREAD_NAMES[thread]!r} of {self.sizes[thread]} bytes")
        parts = []
        while size:
            index, inside = locate(start)
            n = min(size, block_size(index) - inside)
            self._fh.seek(self.offsets[thread][index] + inside)
            chunk = self._fh.read(n)
            if len(chunk) != n:
                raise self.error("truncated .mdem file: a block ends early")
            parts.append(chunk)
            start += n
            size -= n
        return b"".join(parts)

    def close(self) -> None:
        self._fh.close()

    def __enter__(self) -> "Container":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class ContainerWriter:
    """Writes a ``.mdem`` container to an open binary file: ``write(thread, address, data)``
    in any order (blocks are allocated as they are first needed, as ``CMDEMFile`` does, or
    taken from ``layout``), then ``finish()`` writes the headers and truncates the file at
    the end of the last data (``CMDEMFile::FinalTruncate``)."""

    def __init__(self, fh: BinaryIO, layout: Layout | None = None):
        self.fh = fh
        self.version = layout.version if layout else 2
        self.offsets = [list(o) for o in layout.offsets] if layout else [[] for _ in THREAD_NAMES]
        self.fixed = layout is not None
        self.sizes = [0] * len(THREAD_NAMES)
        for offset, chunk in layout.stale if layout else ():
            fh.seek(offset)
            fh.write(chunk)

    def _append_address(self) -> int:
        end = DATA_START
        for offsets in self.offsets:
            if offsets:
                end = max(end, offsets[-1] + block_size(len(offsets) - 1))
        return end

    def _block(self, thread: int, index: int) -> int:
        offsets = self.offsets[thread]
        while len(offsets) <= index:
            if self.fixed:
                raise ValueError("the data does not fit the layout it should be written in")
            offsets.append(self._append_address())
        return offsets[index]

    def write(self, thread: int, address: int, data: bytes | memoryview) -> None:
        data = memoryview(data)
        end = address + len(data)
        while len(data):
            index, inside = locate(address)
            n = min(len(data), block_size(index) - inside)
            self.fh.seek(self._block(thread, index) + inside)
            self.fh.write(data[:n])
            address += n
            data = data[n:]
        self.sizes[thread] = max(self.sizes[thread], end)

    def finish(self) -> None:
        self.fh.seek(0)
        self.fh.write(_FILE.pack(SIGNATURE, self.version, len(THREAD_NAMES), CLUSTER))
        ends = []
        for t, name in enumerate(THREAD_NAMES):
            offsets = self.offsets[t] + [0] * (BLOCKS - len(self.offsets[t]))
            self.fh.write(_THREAD.pack(name.encode(), self.sizes[t], 0, *offsets))
            if self.sizes[t]:
                index, inside = locate(self.sizes[t])
                if inside == 0:                      # ends exactly at a block's end
                    index, inside = index - 1, block_size(index - 1)
                ends.append(self.offsets[t][index] + inside)
        end = max(ends, default=DATA_START)
        self.fh.truncate(end)                        # also extends, if the data ends in zeros
