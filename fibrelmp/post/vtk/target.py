"""``fibrelmp post --to vtk``: ParaView ``.vtu`` frames and their ``.pvd`` index."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.post.target import DumpTarget, ReadBack
from fibrelmp.post.vtk.reader import read_pvd, read_vtu
from fibrelmp.post.vtk.writer import VtkWriter


def _vtus(base: Path) -> list[Path]:
    return sorted(base.parent.glob(f"{base.name}_[0-9][0-9][0-9][0-9][0-9][0-9].vtu"))


class VtkTarget(DumpTarget):
    """``<base>_NNNNNN.vtu`` per frame (bonds of ``--data`` as lines), ``<base>.pvd``; frames
    of an earlier conversion to the same base are removed."""

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        return [base.with_name(base.name + ".pvd")] + _vtus(base)

    def start(self, first: list[Frame]) -> None:
        data = self.context.datafile
        self.out = self.adopt(VtkWriter(self.target, data.bonds if data is not None else None))

    def write_frame(self, frame: Frame) -> None:
        self.time_of(frame)                  # (warns when the dump has no times)
        self.out.add(frame)

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        pvd = next(p for p in files if p.suffix == ".pvd")
        out = []
        for _, path in read_pvd(pvd):
            v = read_vtu(path)
            values = {cols: v.point_data[name] for name, cols in
                      (("velocity", ("vx", "vy", "vz")), ("force", ("fx", "fy", "fz")))
                      if name in v.point_data}
            out.append(ReadBack(v.points, values=values))         # float64 as dumped
        return out
