"""FibreNet results in pictures (``fibrelmp plot``/``snapshot``): the frames of an xyz
family through the home's reader (``writer.iter_xyz``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.pictures.locate import DATA_NAME, family_prefix, run_folder
from fibrelmp.pictures.sources import SceneFrame, Source, noted_radii


class FibreNetSource(Source):
    """``<prefix>_coord.xyz`` (and ``_vel.xyz``); beads' radii, masses and the springs come
    from the run's ``data.lammps`` when its work folder is found."""

    what = "FibreNet xyz result"
    time_unit, energy_unit = "τ", "ε"

    def __init__(self, path: Path):
        super().__init__(path)
        prefix = family_prefix(path)
        self.coord = path.with_name(f"{prefix}_coord.xyz")
        if not self.coord.is_file():
            raise InputError(path, None, f"the positions are in {self.coord.name}, which is not here")
        if self.coord != path:
            self.notes.append(f"frames from {self.coord.name}")
        vel = path.with_name(f"{prefix}_vel.xyz")
        self.vel = vel if vel.is_file() else None
        self.radius_by_name: dict[str, float] = {}
        self.mass_by_name: dict[str, float] = {}
        self.bonds = np.zeros((0, 2), np.int64)
        folder, how = run_folder(path)
        data = folder / DATA_NAME if folder is not None else None
        if data is not None and data.is_file():
            self._read_data(data)
            self.notes.append(f"springs, radii and masses from {data} ({how})")
        else:
            self.notes.append(f"no springs, radii or masses: {how}")

    def _read_data(self, data: Path) -> None:
        from fibrelmp.post.lammps_data.reader import read_data

        facts = read_data(data)
        for t, name in facts.type_names.items():
            if t in facts.type_masses:
                self.mass_by_name[name] = facts.type_masses[t]
        self.radius_by_name = noted_radii(data)
        self.bonds = facts.rows(facts.bonds.ravel(), "springs").reshape(-1, 2) if len(facts.bonds) else self.bonds

    def frames(self) -> Iterator[SceneFrame]:
        from fibrelmp.translate.fibrenet.writer import iter_xyz

        velocities = iter_xyz(self.vel) if self.vel is not None else None
        for i, frame in enumerate(iter_xyz(self.coord)):
            v = next(velocities, None) if velocities is not None else None
            names = sorted(set(frame.names))
            kinds = np.array([names.index(n) for n in frame.names], np.int64)
            radius = np.array([self.radius_by_name.get(n, math.nan) for n in frame.names])
            mass = np.array([self.mass_by_name.get(n, math.nan) for n in frame.names])
            bonds = self.bonds if len(self.bonds) and self.bonds.max() < len(frame.names) else self.bonds[:0]
            yield SceneFrame(i, frame.step * frame.dt, frame.step, frame.values, radius
                             if np.isfinite(radius).all() else None, kinds, names,
                             velocity=None if v is None or v.step != frame.step else v.values,
                             mass=mass if np.isfinite(mass).all() else None, bonds=bonds,
                             box=(np.zeros(3), np.asarray(frame.lengths, float)))
