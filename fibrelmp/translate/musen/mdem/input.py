"""MUSEN ``.mdem`` scenes (and results), run as cmusen simulates them: from the first saved
time point, with the same settings a text scene takes; the result is a ``.mdem`` beside the
scene (or ``-o``, ``.mdem`` or text by its name)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.translate.musen.input import SceneInput

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.textio import Patch


class MdemSceneInput(SceneInput):
    name = "mdem"

    def read_scene(self, path: Path) -> "GranularModel":
        from fibrelmp.translate.musen.mdem.model import read_scene

        return read_scene(path)

    def check_patch(self, path: Path) -> "Patch | None":
        return None                      # binary: the first error is the one reported
