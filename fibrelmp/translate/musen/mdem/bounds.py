"""Memory bounds of ``.mdem`` reading, checked before anything large is allocated.

A ``.mdem`` file is zlib streams of protobuf messages: a small file can declare (and hold)
gigabytes, since zlib expands up to 1032 times and an empty protobuf entry costs 2 bytes on
the wire but about 80 bytes once parsed.  Two bounds keep memory proportional to the file:

* **scene** (file thread 0): decompressed to at most ``SCENE_RATIO`` x its stored size +
  ``SCENE_SLACK`` (zlib holds the output twice while it finishes); then, before the
  protobuf parse, its messages are counted on the wire (``count_messages``): at most
  ``MESSAGES_PER_BYTE`` per stored byte + ``MESSAGES_SLACK`` (MUSEN's densest scene,
  identical spheres, stores about 2.4 bytes per object at zlib level 1; removed objects'
  empty entries ~0.25 bytes each, so up to ~7 removed objects per present one pass; the
  walk takes at most ``message_budget`` steps, and runs of identical entries are skipped
  at C speed).  Each message then costs at most ``PARSED_BYTES_PER_MESSAGE``.
* **time-point block**: its declared uncompressed size must fit both what zlib can expand
  its stored bytes to (``ZLIB_MAX_RATIO``) and what its time points can need for the scene's
  object entries (``block_bound``: ``MAX_ENTRY`` bytes per entry, the largest
  ``ProtoTimeDependentProperties`` MUSEN can write); it is read one time point at a time,
  each at most ``block_bound(n, 1)`` bytes (``document.MdemFile``).

docs/musen.md states the resulting figures.
"""

from __future__ import annotations

from functools import lru_cache

from fibrelmp.translate.musen.mdem.messages import fields

ZLIB_MAX_RATIO = 1032            # deflate's largest expansion (258 bytes per 2-bit code)
# real scenes compress 2.6x-6.5x (MUSEN's examples), 29x (identical spheres), 35x (90% of
# them removed); only runs of removed objects compress more (229x), and those are capped by
# the message count below
SCENE_RATIO = 64
SCENE_SLACK = 16 << 20
MESSAGES_PER_BYTE = 2
MESSAGES_SLACK = 1 << 20
# measured (upb): empty ProtoParticleInfo 80, ProtoCompound 113, ProtoPackageGenerator 150
PARSED_BYTES_PER_MESSAGE = 160


def _varint_size(value: int) -> int:
    return max(1, (value.bit_length() + 6) // 7)


@lru_cache(maxsize=None)
def max_size(message: str) -> int:
    """The largest serialized size of ``message`` whose fields are doubles or such messages,
    each present once (as protobuf writes them)."""
    total = 0
    for _, number, kind, repeated in fields(message):
        assert not repeated, message
        tag = _varint_size(number << 3)
        if kind == "double":
            total += tag + 8
        else:
            sub = max_size(kind)
            total += tag + _varint_size(sub) + sub
    return total


# one object entry of a ProtoTimePoint: tag, length, every field present (331 bytes)
MAX_ENTRY = 1 + _varint_size(max_size("ProtoTimeDependentProperties")) + \
    max_size("ProtoTimeDependentProperties")
_POINT_OVERHEAD = 6 + 9          # the point's tag and length in its block; its time field


def objects_per_point(scene_entries: int) -> int:
    """Object entries a time point may hold: entries of removed trailing objects may outlast
    the scene's object list a little (far more is a hostile file)."""
    return 2 * scene_entries + 1024


def block_bound(scene_entries: int, points: int) -> int:
    """The most bytes a block of ``points`` time points of a scene of ``scene_entries``
    object entries can take."""
    return points * (_POINT_OVERHEAD + objects_per_point(scene_entries) * MAX_ENTRY)


def scene_limit(stored: int) -> int:
    """The most bytes the scene message may decompress to."""
    return min(SCENE_RATIO * stored + SCENE_SLACK, ZLIB_MAX_RATIO * stored + 64)


def message_budget(stored: int) -> int:
    """The most protobuf messages a scene stored in ``stored`` bytes may hold."""
    return MESSAGES_PER_BYTE * stored + MESSAGES_SLACK


@lru_cache(maxsize=None)
def _message_fields(message: str) -> dict[int, tuple[str, bool]]:
    """field number -> (message type, whether that type has message fields itself), for the
    message-typed fields of ``message``."""
    from fibrelmp.translate.musen.mdem.messages import _SPEC

    def nested(kind: str) -> bool:
        return any(k in _SPEC for _, _, k, _ in fields(kind))

    return {number: (kind, nested(kind)) for _, number, kind, _ in fields(message) if kind in _SPEC}


class TooMany(ValueError):
    """More messages than the budget allows."""


def count_messages(data: bytes | memoryview, message: str, budget: int) -> int:
    """The protobuf messages a parse of ``data`` as ``message`` would create (itself and every
    nested message; unknown fields are skipped), counted on the wire without allocating
    them.  Raises ``TooMany`` as soon as the count passes ``budget`` (so the walk is at most
    ``budget`` steps) and ``ValueError`` if the wire format is broken.  Messages without
    message fields (the scene's object entries) are counted and skipped, not entered."""
    buf = data if isinstance(data, bytes) else bytes(data)
    count = 1
    stack = [(0, len(buf), message)]
    while stack:
        at, end, kind = stack.pop()
        subs = _message_fields(kind)
        while at < end:
            start = at
            tag = buf[at]
            at += 1
            if tag >= 0x80:                      # a multi-byte tag (field number >= 16)
                tag, at = _varint(buf, at - 1, end)
            if tag < 8:
                raise ValueError("field number 0")
            wire = tag & 7
            if wire == 2:
                size = buf[at] if at < end else 0x80
                if size < 0x80 and at < end:
                    at += 1
                else:
                    size, at = _varint(buf, at, end)
                stop = at + size
                if stop > end:
                    raise ValueError("a field runs past its message")
                sub = subs.get(tag >> 3)
                if sub is not None:
                    count += 1
                    if sub[1]:
                        stack.append((at, stop, sub[0]))
                    elif stop - start <= 4 and buf.startswith(buf[start:stop], stop):
                        # a run of identical short entries (removed objects): skipped at C
                        # speed, so a hostile run of millions is refused at once
                        repeats = _repeats(buf, stop, end, buf[start:stop])
                        count += repeats
                        stop += repeats * (stop - start)
                    if count > budget:
                        raise TooMany(f"more than {budget} messages")
                at = stop
            elif wire == 0:
                _, at = _varint(buf, at, end)
            elif wire == 1 or wire == 5:
                at += 8 if wire == 1 else 4
            else:
                raise ValueError(f"unknown wire type {wire}")
        if at != end:
            raise ValueError("the last field runs past its message")
    return count


def _repeats(buf: bytes, at: int, end: int, record: bytes) -> int:
    """How many copies of ``record`` follow one another from ``at`` (galloping compares of
    at most 1 MiB)."""
    total, k, most = 0, 1, max(1, (1 << 20) // len(record))
    while k:
        chunk = record * k
        if at + len(chunk) <= end and buf.startswith(chunk, at):
            at += len(chunk)
            total += k
            k = min(2 * k, most)
        else:
            k //= 2
    return total


def _varint(buf: bytes, at: int, end: int) -> tuple[int, int]:
    value = shift = 0
    while True:
        if at >= end or shift > 63:
            raise ValueError("a varint runs past its message")
        byte = buf[at]
        value |= (byte & 0x7F) << shift
        at += 1
        if byte < 0x80:
            return value, at
        shift += 7
