"""FibreNet ``.xyz`` trajectories: run result and ``post --to`` target; the result sample
comes from the home (``fibrelmp.translate.fibrenet.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.translate.fibrenet import samples

from .base import ResultConformance, TargetConformance


class TestXyzResult(ResultConformance):
    format = "xyz"

    def case(self, folder: Path):
        return samples.xyz_result(folder)


class TestXyzTarget(TargetConformance):
    format = "xyz"
