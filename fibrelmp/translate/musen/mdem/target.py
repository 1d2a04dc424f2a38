"""``fibrelmp post --to mdem``: LAMMPS dump frames as a MUSEN ``.mdem`` result, through the
granular model (``post.to_granular``) and the writer ``fibrelmp run`` uses."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.formatbase import Writer
from fibrelmp.granmodel import GranularModel
from fibrelmp.post.target import ReadBack
from fibrelmp.post.to_granular import SingleFileTarget
from fibrelmp.units import SI


class MdemTarget(SingleFileTarget):
    """``<base>`` (``.mdem`` added to a name without a suffix): a MUSEN ``.mdem`` result (SI
    units), as ``fibrelmp run`` writes one."""

    kind = "musen"
    keeps_ids = True
    units = ("MUSEN", SI)
    suffix = ".mdem"                 # MUSEN opens results by this extension

    def result_writer(self, model: GranularModel, dt: float) -> Writer:
        from fibrelmp.translate.musen.mdem.result import MdemResultWriter

        return MdemResultWriter(model, self.target)

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        """Sphere positions, velocities and forces of every time point, as stored (exact)."""
        from fibrelmp.translate.musen.mdem.document import MdemFile
        from fibrelmp.translate.musen.mdem.objects import SPHERE, read_objects
        from fibrelmp.translate.musen.mdem.timepoints import columns

        out = []
        with MdemFile(files[0]) as mdem:
            obj = read_objects(mdem.info, mdem.version, mdem.path)
            ids = obj.ids[obj.types == SPHERE]
            for _, values, masks in mdem.time_points():
                live = ids[masks[ids] != 0]
                v = values[live]
                out.append(ReadBack(v[:, columns("coord")], rtol=0.0, atol=0.0,
                                    values={("vx", "vy", "vz"): v[:, columns("vel")],
                                            ("fx", "fy", "fz"): v[:, columns("force")]}))
        return out
