"""DEMDF JSON: input, run result (snapshots) and ``post --to`` target; the samples come from
the home (``fibrelmp.translate.demdf.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.translate.demdf import samples

from ..conftest import REPO
from .base import InputConformance, ResultConformance, TargetConformance, granular_frames


class TestDemdfInput(InputConformance):
    format = "demdf"
    sample = samples.DOCUMENT


class TestDemdfResult(ResultConformance):
    format = "demdf"

    def case(self, folder: Path):
        model = samples.sample_model(REPO)
        return (lambda: samples.result_writer(model, folder)), granular_frames(model, 3)


class TestDemdfTarget(TargetConformance):
    format = "demdf"
