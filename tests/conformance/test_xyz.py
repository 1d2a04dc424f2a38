"""FibreNet ``.xyz`` trajectories: run result and ``post --to`` target."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .base import ResultConformance, TargetConformance


class TestXyzResult(ResultConformance):
    format = "xyz"

    def case(self, folder: Path):
        from fibrelmp.translate.fibrenet.writer import XyzFrame, XyzWriter

        frames = [XyzFrame(10 * k, 0.1, np.ones(3) * 5, ["a", "b"], np.full((2, 3), 0.5 + k))
                  for k in range(3)]
        return (lambda: XyzWriter(folder / "run", fields=("position",))), frames


class TestXyzTarget(TargetConformance):
    format = "xyz"
