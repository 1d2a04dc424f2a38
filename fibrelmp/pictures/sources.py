"""Frames of any result, as what a picture needs: ``SceneFrame``s.

One source class per kind of result, named by its format's registry record (``pictures``;
``open_source`` picks it from ``locate``), each reading through the format's own reader:
FibreNet xyz (``translate.fibrenet.pictures``), DEMDF snapshots (``translate.demdf.pictures``,
one file per frame), MUSEN text results (``translate.musen.pictures``) and ``.mdem`` results
(``translate.musen.mdem.pictures``), and here LAMMPS dumps (``post.lammps_dump``, with the
run's ``data.lammps`` for radii, masses, type names and bonds).  Sources stream: one frame is
in memory at a time (a MUSEN text result is read whole, as its reader does).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.pictures.locate import DATA_NAME, DUMP_NAME, LOG, WORK, Located


@dataclass
class SceneFrame:
    """One saved state, ready to draw or to sum up."""

    index: int                          # position among the source's frames
    time: float | None                  # simulated time (None: unknown)
    step: int | None
    position: np.ndarray                # (n,3)
    radius: np.ndarray | None           # (n,) None: unknown
    kind: np.ndarray                    # (n,) int: type / material index, for colours
    kind_names: list[str]               # name of each kind index
    velocity: np.ndarray | None = None  # (n,3)
    mass: np.ndarray | None = None      # (n,)
    bonds: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))  # rows, intact
    broken_bonds: int | None = None     # bonds whose activity ended by ``time``
    # MUSEN liquid bonds active at ``time`` (rows; drawn apart from solid bonds)
    liquid_bonds: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    triangles: np.ndarray | None = None # (k,3,3) wall triangles
    temperature: np.ndarray | None = None   # (n,) K: a MUSEN heat model's sphere temperatures
    planes: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)   # (normal, point)
    box: tuple[np.ndarray, np.ndarray] | None = None      # (lo, hi)
    dimension: int = 3

    @property
    def count(self) -> int:
        return len(self.position)


class Source:
    """The frames of one result."""

    what = "result"
    time_unit = ""                      # "s", "τ" (LAMMPS lj) or "" (dimensionless)
    energy_unit = ""

    def __init__(self, path: Path):
        self.path = path
        self.notes: list[str] = []      # what the pictures are based on, for the user

    def frames(self) -> Iterator[SceneFrame]:
        raise NotImplementedError

    def count(self) -> int:
        return sum(1 for _ in self.frames())

    def frame(self, index: int | None) -> SceneFrame:
        """Frame ``index`` (negative: from the end; None: the last)."""
        total = self.count()
        i = total - 1 if index is None else index + total if index < 0 else index
        if not 0 <= i < total:
            raise InputError(self.path, None, f"--frame {index}: the {self.what} has {total} "
                             f"frame(s) (0..{total - 1}, or -{total}..-1 from the end)"
                             if total else f"the {self.what} has no frames")
        for frame in self.frames():
            if frame.index == i:
                return frame
        raise InputError(self.path, None, f"frame {i} could not be read")     # file changed


def kind_indices(names: list[str], kinds: np.ndarray) -> tuple[np.ndarray, list[str]]:
    """Kind indices 0..k-1 of the kinds present, and their names (legend order)."""
    used = np.unique(kinds)
    lookup = {int(k): i for i, k in enumerate(used)}
    return (np.array([lookup[int(k)] for k in kinds], np.int64),
            [names[int(k)] if 0 <= int(k) < len(names) else str(int(k)) for k in used])


def noted_radii(data: Path) -> dict[str, float]:
    """Type name -> radius, where fibrelmp's data file notes it in the Masses comments
    (``1 1.0  # F1 m=1 R=0.42``: FibreNet beads, whose atom style has no radius)."""
    radii = {}
    with open(data, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            hit = re.match(r"\s*\d+\s+\S+\s*#\s*(\S+)\s.*\bR=([-+.\deE]+)", line)
            if hit:
                radii[hit.group(1)] = float(hit.group(2))
    return radii


# -- LAMMPS dumps ----------------------------------------------------------------------------
class DumpSource(Source):
    """A LAMMPS text dump; per-atom facts it lacks (radius, mass, type names, bonds) from the
    ``data.lammps`` beside it (a run's work folder has both)."""

    what = "LAMMPS dump"

    def __init__(self, path: Path):
        from fibrelmp.post.lammps_dump import DumpReader

        super().__init__(path)
        self.warnings: list[tuple[str, str]] = []
        self.reader = DumpReader(path, None, self.warnings)
        data = path.with_name(DATA_NAME)
        self.data = None
        self.radius_by_name: dict[str, float] = {}
        if data.is_file():
            from fibrelmp.post.lammps_data.reader import read_data

            self.data = read_data(data)
            self.radius_by_name = noted_radii(data) if self.data.radius is None else {}
            self.notes.append(f"radii, masses, type names and bonds from {data}"
                              + (" (bonds as at the start: breakage is not in the dump)"
                                 if len(self.data.bonds) and self.data.radius is not None else ""))

    def count(self) -> int:
        return self.reader.count()

    def frames(self) -> Iterator[SceneFrame]:
        for i, f in enumerate(self.reader):
            yield self._frame(i, f)

    def frame(self, index: int | None) -> SceneFrame:
        total = self.count()
        i = total - 1 if index is None else index + total if index < 0 else index
        if not 0 <= i < total:
            return super().frame(index)             # the error, with the frame count
        for f in self.reader.frames(lambda k: k == i, i + 1):   # other frames are not parsed
            return self._frame(i, f)
        raise InputError(self.path, None, f"frame {i} could not be read")

    def _frame(self, i: int, f) -> SceneFrame:
        d = self.data
        ids = f.column("id").astype(np.int64) if f.has("id") else np.arange(1, f.count + 1)
        rows = d.rows(ids, "pictures") if d is not None else None
        labels = None
        if f.has("type"):
            raw = f.column("type")
            try:
                types = raw.astype(np.int64)
            except (TypeError, ValueError):          # type labels (dump_modify types labels)
                labels, types = np.unique(raw.astype(str), return_inverse=True)
                types = types.astype(np.int64) + 1
        else:
            types = d.types[rows] if d is not None else np.ones(f.count, np.int64)
        radius = mass = None
        if f.has("radius"):
            radius = f.vector("radius")[:, 0]
        elif f.has("diameter"):
            radius = f.vector("diameter")[:, 0] / 2
        elif d is not None and d.radius is not None:
            radius = d.radius[rows]
        elif d is not None and self.radius_by_name and labels is None:
            noted = np.array([self.radius_by_name.get(d.name(t), math.nan) for t in types])
            radius = noted if np.isfinite(noted).all() else None
        if f.has("mass"):
            mass = f.vector("mass")[:, 0]
        elif d is not None and d.mass is not None:
            mass = d.mass[rows]
        top = int(types.max(initial=0))
        if labels is not None:
            names = ["", *labels]
        else:
            names = [d.name(t) if d is not None else str(t) for t in range(top + 1)]
        kinds, kind_names = kind_indices(names, types)
        bonds = np.zeros((0, 2), np.int64)
        if d is not None and len(d.bonds) and len(ids):
            order = np.argsort(ids, kind="stable")
            at = np.minimum(np.searchsorted(ids[order], d.bonds), len(ids) - 1)
            found = (ids[order][at] == d.bonds).all(axis=1)        # both atoms in this frame
            bonds = order[at[found]]
        velocity = f.vector("vx", "vy", "vz") if f.has("vx", "vy", "vz") else None
        temperature = f.vector("d_musen_temperature")[:, 0] if f.has("d_musen_temperature") else None
        return SceneFrame(i, f.time, f.step, f.wrapped(), radius, kinds, kind_names,
                          velocity=velocity, mass=mass, bonds=bonds, box=(f.lo, f.hi),
                          temperature=temperature)


class WorkFolderSource(DumpSource):
    """A run's work folder: its frame dump (``frames.dump``) and data file."""

    def __init__(self, path: Path):
        dump = path / DUMP_NAME
        if not dump.is_file():
            raise InputError(path, None, f"this work folder has no {DUMP_NAME} (frames) to draw")
        super().__init__(dump)


def open_source(located: Located) -> Source:
    """The frame source of a located result (a log has no frames: an InputError): a work
    folder's dump, else the picture source its format's registry record names (its home's)."""
    from fibrelmp import registry

    if located.kind == WORK:
        return WorkFolderSource(located.path)
    fmt = registry.formats_by_name().get(located.kind)
    if fmt is None or not fmt.pictures:
        if located.kind == LOG:
            raise InputError(located.path, None, "a LAMMPS log has no frames: give a result file "
                             "or the run's work folder")
        raise InputError(located.path, None, f"fibrelmp does not draw {located.kind} files")
    return fmt.load_pictures()(located.path)
