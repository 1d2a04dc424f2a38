"""LAMMPS text dumps: the streaming reader (Frame, iter_frames...) and ``DumpReader``, the
frame source of ``fibrelmp post``."""

from fibrelmp.post.lammps_dump.frames import DumpReader
from fibrelmp.post.lammps_dump.reader import Frame, frame_from, iter_frames, iter_headers

__all__ = ["DumpReader", "Frame", "frame_from", "iter_frames", "iter_headers"]
