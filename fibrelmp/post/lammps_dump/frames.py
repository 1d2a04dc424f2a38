"""``DumpReader``: a LAMMPS text dump as a stream of Frames (the ``frames`` role of the
registry's ``lammps-dump`` format; ``fibrelmp post`` reads through it)."""

from __future__ import annotations

import os
import zlib
from pathlib import Path
from typing import Callable, Iterator

from fibrelmp.formatbase import Reader
from fibrelmp.post.lammps_dump.reader import Frame, frame_from, iter_frames, iter_headers


def is_text_dump(path: Path) -> bool:
    """Does the file (plain or gzip) begin like a LAMMPS text dump (or hold nothing)?"""
    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
        if head[:2] == b"\x1f\x8b":
            # the start of the stream only: a gzip dump cut short (LAMMPS still writing) is
            # still a dump, and a hostile stream is not expanded beyond these 4 kB
            head = zlib.decompressobj(31).decompress(head, 4096)
    except (OSError, zlib.error):
        return False
    text = head.lstrip()
    return not text or text.startswith(b"ITEM:")


class DumpReader(Reader):
    """Frames of a text dump, parsed only when wanted; memory holds one frame at a time.
    Problems are InputErrors ``path:line: message`` (from the dump reader, which also says
    what is wrong with a missing file or a directory)."""

    format = "lammps-dump"
    what = "LAMMPS dump"

    def __init__(self, path: str | os.PathLike, topology: Path | None = None,
                 warnings: list[tuple[str, str]] | None = None):
        self.path = Path(path)
        self.warnings = warnings if warnings is not None else []
        self.type_names: dict[int, str] = {}     # dumps number their types

    @classmethod
    def claims(cls, path: Path, topology: Path | None) -> bool:
        return is_text_dump(path) or path.is_dir()

    def count(self) -> int:
        # warnings come from the conversion pass itself; this pass only counts
        return sum(1 for _ in iter_headers(self.path, [], want=lambda i, h: False))

    def frames(self, want: Callable[[int], bool] | None = None,
               stop: int | None = None) -> Iterator[Frame]:
        """The frames whose index ``want`` accepts; reading ends at index ``stop``."""
        seen = [0]

        def wanted(i: int, h) -> bool:
            seen[0] = i + 1
            return want is None or want(i)

        for frame in iter_frames(self.path, self.warnings, wanted):
            yield frame
            if stop is not None and seen[0] >= stop:
                return                  # the selection is exhausted: do not read the rest

    def last(self) -> Frame | None:
        # keep the newest block unparsed; parse only the one that survives
        last = None
        for head, block in iter_headers(self.path, self.warnings):
            last = (head, block)
        return None if last is None else frame_from(last[0], last[1], self.path)

    def __iter__(self) -> Iterator[Frame]:
        return self.frames()

    def universe(self):
        """The frames as an MDAnalysis ``Universe`` (``ts.time`` is the dump's ITEM: TIME)."""
        from fibrelmp.post.lammps_dump.universe import dump_universe

        return dump_universe(self.path)

    def describe(self) -> list[str]:
        from fibrelmp.post.lammps_dump.info import describe_dump

        return describe_dump(self.path, self.warnings)
