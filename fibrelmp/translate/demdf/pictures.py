"""DEMDF results in pictures (``fibrelmp plot``/``snapshot``): a snapshot series through the
home's reader (``reader.read_snapshot``)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Iterator

from fibrelmp.pictures.sources import SceneFrame, Source, kind_indices


class DemdfSource(Source):
    """A DEMDF snapshot and the other snapshots of its family (``<name>_<n>.json``), in
    ``n`` order; any other DEMDF document is one frame."""

    what = "DEMDF snapshot series"

    def __init__(self, path: Path):
        super().__init__(path)
        hit = re.fullmatch(r"(.*)_(\d+)", path.stem)
        if hit:
            same = [p for p in path.parent.glob(f"{hit.group(1)}_*.json")
                    if re.fullmatch(rf"{re.escape(hit.group(1))}_\d+", p.stem)]
            self.files = sorted(same, key=lambda p: int(p.stem.rsplit("_", 1)[1]))
        else:
            self.files = [path]
        self.own = self.files.index(path) if path in self.files else 0

    def count(self) -> int:
        return len(self.files)

    def frame(self, index: int | None) -> SceneFrame:
        return super().frame(self.own if index is None else index)

    def frames(self) -> Iterator[SceneFrame]:
        from fibrelmp.translate.demdf.reader import read_snapshot

        for i, file in enumerate(self.files):
            m = read_snapshot(file)
            s = m.spheres
            kinds, names = kind_indices([x.name for x in m.materials], s.material)
            yield SceneFrame(i, m.plan.t_start, None, s.position, s.radius, kinds, names,
                             velocity=s.velocity, mass=s.mass,
                             planes=[(p.normal, p.point) for p in m.planes], box=m.plan.domain,
                             dimension=m.plan.dimension)
