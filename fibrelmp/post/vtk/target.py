"""``fibrelmp post --to vtk``: a ``.pvd`` series of particle (and bond) frames."""

from __future__ import annotations

import re
from pathlib import Path

from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.post.target import DumpTarget, ReadBack
from fibrelmp.post.vtk.frame import VECTORS, from_dump
from fibrelmp.post.vtk.reader import read_frame, read_pvd
from fibrelmp.post.vtk.writer import VtkWriter, check_output_name


def frame_pattern(base: Path) -> re.Pattern:
    """The names of a base's frame files (``.vtu``, ``_walls.vtu``: what earlier fibrelmp
    versions wrote)."""
    return re.compile(re.escape(base.name) + r"_\d{6}(\.vtp|_bonds\.vtp|_walls\.vtp|\.vtm|\.vtu|_walls\.vtu)")


class VtkTarget(DumpTarget):
    """``<base>.pvd`` and its frames (writer.py); bonds of ``--data`` as lines; frames of an
    earlier conversion to the same base are removed."""

    writes_nonfinite = True        # Float64 arrays hold inf/nan as they are (with a warning)

    def __init__(self, base: str | Path, context=None, *, force: bool = True):
        check_output_name(Path(base))
        super().__init__(base, context, force=force)

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        pattern = frame_pattern(base)
        frames = sorted(p for p in base.parent.glob(f"{base.name}_*") if pattern.fullmatch(p.name)) \
            if base.parent.is_dir() else []
        return [base.with_name(base.name + ".pvd")] + frames

    def start(self, first: list[Frame]) -> None:
        data = self.context.datafile
        self.out = self.adopt(VtkWriter(self.target, data.bonds if data is not None else None))

    def write_frame(self, frame: Frame) -> None:
        self.out.add(from_dump(frame, self.out.bonds, self.time_of(frame)))   # warns without times

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        pvd = next(p for p in files if p.suffix == ".pvd")
        out = []
        for _, path in read_pvd(pvd):
            piece = read_frame(path)["Particles"]
            order = piece.point_data["id"].argsort(kind="stable")
            values = {VECTORS[name]: piece.point_data[name][order] for name in ("Velocity", "Force")
                      if name in piece.point_data}
            out.append(ReadBack(piece.points[order], values=values))     # float64 as dumped
        return out
