"""MUSEN ``.mdem`` results in pictures (``fibrelmp plot``/``snapshot``): the scene and its time
points through the home's ``MdemFrames``, one frame in memory at a time.  The file stays open
while the source lives: ``frame(i)`` decodes only the block holding time point ``i`` (the block
index is read from the file's descriptors and saved times, not from its blocks)."""

from __future__ import annotations

import weakref
from pathlib import Path
from typing import Iterator

from fibrelmp.errors import InputError
from fibrelmp.pictures.sources import SceneFrame, Source
from fibrelmp.translate.musen.pictures import musen_frame


class MdemSource(Source):
    what = "MUSEN .mdem result"
    time_unit, energy_unit = "s", "J"

    def __init__(self, path: Path):
        from fibrelmp.translate.musen.mdem.document import MdemFile
        from fibrelmp.translate.musen.mdem.model import MdemFrames, read_scene

        super().__init__(path)
        self.mdem = MdemFile(path)
        weakref.finalize(self, self.mdem.close)
        self.model = read_scene(path, self.mdem)
        self.frames_of = MdemFrames(self.mdem)

    def count(self) -> int:
        return self.frames_of.count()

    def frames(self) -> Iterator[SceneFrame]:
        for i, (time, values, masks) in enumerate(self.mdem.time_points()):
            yield self._scene_frame(i, self.frames_of.frame(i, time, values, masks))

    def frame(self, index: int | None) -> SceneFrame:
        total = self.count()
        i = total - 1 if index is None else index + total if index < 0 else index
        if not 0 <= i < total:
            return super().frame(index)             # the error, with the frame count
        try:
            return self._scene_frame(i, self.frames_of.at(i))
        except IndexError:
            raise InputError(self.path, None, f"frame {i} could not be read") from None

    def _scene_frame(self, i: int, f) -> SceneFrame:
        return musen_frame(self.model, i, f.time, f.sphere_rows, f.position, f.velocity,
                           f.triangle_vertices, f.temperature)
