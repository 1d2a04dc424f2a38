"""FibreNet ``_restart.res`` files: run result and ``post --to`` target; the result sample
comes from the home (``fibrelmp.translate.fibrenet.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.translate.fibrenet import samples

from .base import ResultConformance, TargetConformance


class TestResResult(ResultConformance):
    format = "res"

    def case(self, folder: Path):
        return samples.restart_result(folder)


class TestResTarget(TargetConformance):
    format = "res"
