"""DEMDF JSON: input, run result (snapshots) and ``post --to`` target."""

from __future__ import annotations

from pathlib import Path

from ..conftest import REPO
from .base import InputConformance, ResultConformance, TargetConformance, granular_frames

SAMPLE = "examples/demdf/head_on.json"


class TestDemdfInput(InputConformance):
    format = "demdf"
    sample = SAMPLE


class TestDemdfResult(ResultConformance):
    format = "demdf"

    def case(self, folder: Path):
        from fibrelmp.translate.demdf import reader as demdf
        from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

        model = demdf.read(REPO / SAMPLE)
        return (lambda: DemdfSnapshotWriter(model, folder)), granular_frames(model, 3)


class TestDemdfTarget(TargetConformance):
    format = "demdf"
