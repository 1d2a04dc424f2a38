"""``fibrelmp post --to musen``: LAMMPS dump frames as a MUSEN text result, through the
granular model (``post.to_granular``) and the writer ``fibrelmp run`` uses."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.formatbase import Writer
from fibrelmp.granmodel import GranularModel
from fibrelmp.post.target import ReadBack
from fibrelmp.post.to_granular import SingleFileTarget
from fibrelmp.units import SI


class MusenTarget(SingleFileTarget):
    """``<base>`` (``.txt`` added to a name without a suffix): a MUSEN text result (SI units)."""

    kind = "musen"
    keeps_ids = True                 # MUSEN objects keep their ids
    units = ("MUSEN", SI)
    takes_precision = True
    suffix = ".txt"                  # MUSEN's text results (and scenes) are .txt files

    def result_writer(self, model: GranularModel, dt: float) -> Writer:
        from fibrelmp.translate.musen.writer import MusenResultWriter

        precision = self.context.precision
        return MusenResultWriter(model, self.target, precision=6 if precision is None else precision)

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        from fibrelmp.translate.musen.scene import read_time_points

        tp = read_time_points(files[0], tags=(12, 15, 20))       # objects in id order
        return [ReadBack(tp.fields[12][k], rtol=6e-6, atol=1e-12,      # %g: 6 significant digits
                         values={("vx", "vy", "vz"): tp.fields[15][k], ("fx", "fy", "fz"): tp.fields[20][k]})
                for k in range(len(tp.times))]
