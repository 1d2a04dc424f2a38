"""``fibrelmp post --to mercury``: MercuryDPM ``.data``/``.ene``/``.restart`` (+ ``.fstat`` with
``--local`` or wall-contact columns in the dump)."""

from __future__ import annotations

from pathlib import Path
from typing import Iterator

import numpy as np

from fibrelmp.post.lammps_dump.reader import Frame, iter_frames
from fibrelmp.post.mercury.reader import read_data_file
from fibrelmp.post.mercury.writer import MercuryFrame, MercuryWriter, wall_columns
from fibrelmp.post.target import DumpTarget, ReadBack


def iter_matching(frames: Iterator[Frame], step: int, pending: list) -> Frame | None:
    """The local-dump frame with ``step`` from a step-ordered stream (None if it has none)."""
    while True:
        if pending:
            f = pending[0]
            if f.step == step:
                pending.pop(0)
                return f
            if f.step > step:
                return None
            pending.pop(0)
            continue
        nxt = next(frames, None)
        if nxt is None:
            return None
        pending.append(nxt)


class MercuryTarget(DumpTarget):
    """Every frame into ``<base>.data`` and ``<base>.ene``, the last one's state into
    ``<base>.restart``; contacts of the ``--local`` dump frame with the same step and the
    frame's own wall-contact columns into ``<base>.fstat``."""

    uses_local = True

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        return [base.with_name(base.name + s) for s in (".data", ".ene", ".fstat", ".restart")]

    def start(self, first: list[Frame]) -> None:
        ctx = self.context
        g = np.zeros(3) if ctx.gravity is None else np.asarray(ctx.gravity, float)
        bonds = {tuple(map(int, b)) for b in ctx.datafile.bonds} if ctx.datafile is not None else None
        walls = bool(first) and bool(wall_columns(first[0]))
        self.out = self.adopt(MercuryWriter(self.target, g, fstat=ctx.local is not None or walls, bonds=bonds,
                                            time_step=ctx.facts.time_step if ctx.facts is not None else None,
                                            warn=ctx.warn))
        facts = ctx.facts
        if facts is not None and facts.path is not None and not walls:
            from fibrelmp.translate.granular.mesh import MESH_NAME
            from fibrelmp.translate.granular_job import TILES_NAME

            work = facts.path.parent
            if (work / MESH_NAME).exists() or (work / TILES_NAME).exists():
                ctx.warn("no wall contacts", "the run's MUSEN walls are not in the .fstat: their "
                         "fix keeps the force on each wall triangle, not each sphere's contact "
                         "(docs/post.md); sphere-sphere contacts come from --local")
        self.local = iter_frames(ctx.local, ctx.warnings) if ctx.local is not None else None
        self.pending: list[Frame] = []

    def write_frame(self, frame: Frame) -> None:
        local = None
        if self.local is not None:
            local = iter_matching(self.local, frame.step, self.pending)
            if local is None:
                self.context.warn("no contacts", f"{self.context.local}: no local-dump frame for step "
                                  f"{frame.step}; its .fstat frame has no contact lines")
        self.out.add(MercuryFrame(frame, self.time_of(frame), local))

    def end(self) -> None:
        if self.count and (self.context.local is None or self.out.no_elastic):
            self.context.warn("no elastic energy", "elasticEnergy in the .ene file is 0: it comes from "
                              "an 'eng' column of a --local contact dump")

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        data = next(p for p in files if p.suffix == ".data")
        out = []
        for f in read_data_file(data):
            if f.rows.shape[1] == 14:        # %.15g positions, %.10g the rest
                out.append(ReadBack(f.rows[:, 0:3], rtol=1e-14, value_tol=(1e-9, 1e-300),
                                    values={("vx", "vy", "vz"): f.rows[:, 3:6], ("radius",): f.rows[:, 6:7]}))
            else:
                out.append(ReadBack(np.column_stack([f.rows[:, 0:2], np.zeros(len(f.rows))]), rtol=1e-14))
        return out
