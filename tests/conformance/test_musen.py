"""MUSEN text scenes/results: input, run result, ``post --to`` target and ``convert``
document; the samples come from the home (``fibrelmp.translate.musen.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.translate.musen import samples

from .base import (DocumentConformance, InputConformance, ResultConformance, TargetConformance,
                   granular_frames, two_glass_spheres)


class TestMusenInput(InputConformance):
    format = "musen"
    sample = samples.SCENE


class TestMusenResult(ResultConformance):
    format = "musen"

    def case(self, folder: Path):
        model = two_glass_spheres()
        return (lambda: samples.result_writer(model, folder)), granular_frames(model, 3)


class TestMusenTarget(TargetConformance):
    format = "musen"


class TestMusenDocument(DocumentConformance):
    format = "musen"
    sample = samples.SCENE
    cut = samples.DOCUMENT_CUT
