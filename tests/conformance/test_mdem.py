"""MUSEN ``.mdem`` files: input, run result, ``post --to`` target and ``convert`` document."""

from __future__ import annotations

from pathlib import Path

from .base import (DocumentConformance, InputConformance, ResultConformance, TargetConformance,
                   granular_frames, two_glass_spheres)

SAMPLE = "examples/musen/SingelParticle.mdem"


class TestMdemInput(InputConformance):
    format = "mdem"
    sample = SAMPLE


class TestMdemResult(ResultConformance):
    format = "mdem"

    def case(self, folder: Path):
        from fibrelmp.translate.musen.mdem.result import MdemResultWriter

        model = two_glass_spheres()
        return (lambda: MdemResultWriter(model, folder / "result.mdem")), granular_frames(model, 3)


class TestMdemTarget(TargetConformance):
    format = "mdem"


class TestMdemDocument(DocumentConformance):
    format = "mdem"
    sample = SAMPLE
    cut = 3000                # a data block beyond the end
