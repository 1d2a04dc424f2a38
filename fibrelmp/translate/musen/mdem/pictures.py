"""MUSEN ``.mdem`` results in pictures (``fibrelmp plot``/``snapshot``): the scene and its time
points through the home's ``MdemReader``, one frame in memory at a time."""

from __future__ import annotations

from pathlib import Path
from typing import Iterator

from fibrelmp.pictures.sources import SceneFrame, Source
from fibrelmp.translate.musen.pictures import musen_frame


class MdemSource(Source):
    what = "MUSEN .mdem result"
    time_unit, energy_unit = "s", "J"

    def __init__(self, path: Path):
        from fibrelmp.translate.musen.mdem.model import MdemReader

        super().__init__(path)
        self.reader = MdemReader(path)
        self.model = self.reader.read()

    def count(self) -> int:
        from fibrelmp.translate.musen.mdem.document import MdemFile

        with MdemFile(self.path) as mdem:
            return sum(1 for _ in mdem.time_points())

    def frames(self) -> Iterator[SceneFrame]:
        for i, f in enumerate(self.reader):
            yield musen_frame(self.model, i, f.time, f.sphere_rows, f.position, f.velocity,
                               f.triangle_vertices, f.temperature)
