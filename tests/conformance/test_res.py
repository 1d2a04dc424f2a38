"""FibreNet ``_restart.res`` files: run result and ``post --to`` target."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .base import ResultConformance, TargetConformance


class TestResResult(ResultConformance):
    format = "res"

    def case(self, folder: Path):
        from fibrelmp.translate.fibrenet.writer import RestartState, RestartWriter

        z = np.zeros((2, 3))
        frames = [RestartState(10 * k, 0.1, np.ones(3) * 5, np.array([0, 1]), ["a", "b"], z + k, z + k, z, z)
                  for k in range(3)]
        return (lambda: RestartWriter(folder / "run_restart.res")), frames


class TestResTarget(TargetConformance):
    format = "res"
