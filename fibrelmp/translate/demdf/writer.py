"""DEMDF snapshots, as BOS writes them: ``<filename>_<saveCount>.json``.

Each snapshot is the whole input document re-serialised with the particles' positions and
velocities, ``time`` and the output's ``saveCount`` replaced (and ``timeStepCount``, when the
document has one, advanced by the file's time steps run).  A particles file named by
``objects.particles`` is written inline, as BOS's snapshots do.  Numbers are written with
Python's shortest round-trip repr, so re-reading a snapshot gives the particles bit for bit.

Particles LAMMPS removed (they left the simulation box) keep their last saved state in the
array - the array index is the particle id - and are listed in ``removed``.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.errors import RunError
from fibrelmp.granmodel import GranularFrame, GranularModel
from fibrelmp.formatbase import Writer
from fibrelmp.translate.demdf.reader import read_snapshot
from fibrelmp.translate.demdf.record import demdf_record

__all__ = ["DemdfSnapshotWriter", "read_snapshot"]

_MARK = "@@fibrelmp-particles@@"


class DemdfSnapshotWriter(Writer):
    """A snapshot per frame added; snapshots are staged and renamed into place by ``close``
    (``written`` lists them then): a failed run leaves the folder as it was, an earlier run's
    snapshots untouched."""

    format = "demdf"

    def __init__(self, model: GranularModel, folder: str | Path, *, force: bool = True):
        info = demdf_record(model)
        super().__init__(folder, force=force)
        self.model = model
        self.folder = self.target
        self.doc = copy.deepcopy(info.document)
        self.dim: int = info.dimensionality
        self.types = [row[-1] for row in info.particle_rows]
        self.filename: str = info.filename
        self.save_count: int = info.save_count
        self.location = info.output_location
        self.file_dt: float = info.file_time_step
        self.step0: int = info.time_step_count
        self.t0 = model.plan.t_start
        self.position = model.spheres.position.copy()
        self.velocity = model.spheres.velocity.copy()
        self.written: list[Path] = []
        self.last: Path | None = None            # the snapshot the last add() staged
        self.removed: dict[int, float] = {}      # particle index -> time it was first missing
        self.doc.setdefault("objects", {})
        self.doc["objects"]["particles"] = _MARK

    def outputs(self) -> list[Path]:
        return []            # any earlier snapshots are the run's business (outputs.Outputs)

    def add(self, frame: GranularFrame) -> Path:
        """Stage the frame's snapshot; returns the path it gets at ``close``."""
        super().add(frame)
        return self.last

    def write(self, frame: GranularFrame) -> None:
        rows = np.asarray(frame.sphere_rows, dtype=np.int64)
        self.position[rows] = frame.position
        self.velocity[rows] = frame.velocity
        missing = np.ones(len(self.position), dtype=bool)
        missing[rows] = False
        for i in np.flatnonzero(missing):
            if int(i) not in self.removed:
                self.removed[int(i)] = frame.time
                self.model.warn("demdf", f"particle {i} left the simulation box at time "
                                f"{frame.time:g}; snapshots keep its last saved state")
        if not (np.isfinite(self.position).all() and np.isfinite(self.velocity).all()):
            raise RunError(f"non-finite particle positions or velocities at time {frame.time:g}; "
                           "the run became unstable")
        self._set_counters(frame.time)
        self.last = self.folder / f"{self.filename}_{self.save_count}.json"
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            exc.output = self.last
            raise
        self.write_file(self.last, self.render().encode("utf-8"))
        self.save_count += 1

    def close(self) -> list[Path]:
        """Move the staged snapshots into place."""
        done = super().close()
        self.written.extend(done)
        return done

    def _set_counters(self, time: float) -> None:
        doc = self.doc
        doc["time"] = float(time)
        if "timeStepCount" in doc:
            doc["timeStepCount"] = self.step0 + int(round((time - self.t0) / self.file_dt))
        if self.location is None:
            spec = doc.setdefault("output", {"snapshot": {"name": "demdf", "filename": self.filename}})
            self.location = ("output", "snapshot") if isinstance(spec, dict) and "snapshot" in spec \
                else None
            if self.location is None:          # an output the reader ignored: leave it alone
                return
        target: Any = doc
        for key in self.location:
            target = target[key]
        target["saveCount"] = self.save_count

    def render(self) -> str:
        text = json.dumps(self.doc, indent=4, ensure_ascii=False, allow_nan=False)
        at = text.index(f'"{_MARK}"')
        line = text[text.rfind("\n", 0, at) + 1: at]
        indent = len(line) - len(line.lstrip(" "))
        return text.replace(f'"{_MARK}"', self._particles(indent), 1) + "\n"

    def _particles(self, indent: int) -> str:
        d = self.dim
        if not len(self.types):
            return "[]"
        pos, vel = self.position[:, :d].tolist(), self.velocity[:, :d].tolist()
        pad = " " * (indent + 4)
        rows = [f"{pad}[{', '.join(map(_num, p + v))}, {json.dumps(t)}]"
                for p, v, t in zip(pos, vel, self.types)]
        return "[\n" + ",\n".join(rows) + "\n" + " " * indent + "]"


def _num(x: float) -> str:
    if not math.isfinite(x):
        raise RunError(f"non-finite value {x} in a snapshot")
    return repr(float(x))
