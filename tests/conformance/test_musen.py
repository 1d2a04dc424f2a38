"""MUSEN text scenes/results: input, run result, ``post --to`` target and ``convert``
document."""

from __future__ import annotations

from pathlib import Path

from .base import (DocumentConformance, InputConformance, ResultConformance, TargetConformance,
                   granular_frames, two_glass_spheres)

SAMPLE = "examples/musen/SingelParticle_text.txt"


class TestMusenInput(InputConformance):
    format = "musen"
    sample = SAMPLE


class TestMusenResult(ResultConformance):
    format = "musen"

    def case(self, folder: Path):
        from fibrelmp.translate.musen.writer import MusenResultWriter

        model = two_glass_spheres()
        return (lambda: MusenResultWriter(model, folder / "result.txt")), granular_frames(model, 3)


class TestMusenTarget(TargetConformance):
    format = "musen"


class TestMusenDocument(DocumentConformance):
    format = "musen"
    sample = SAMPLE
    cut = 1500                # in the middle of a record (tag 15 needs 3 values)
