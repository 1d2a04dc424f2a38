"""MUSEN ``.mdem`` files: input, run result, ``post --to`` target and ``convert`` document;
the samples come from the home (``fibrelmp.translate.musen.mdem.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.translate.musen.mdem import samples

from .base import (DocumentConformance, InputConformance, ResultConformance, TargetConformance,
                   granular_frames, two_glass_spheres)


class TestMdemInput(InputConformance):
    format = "mdem"
    sample = samples.SCENE


class TestMdemResult(ResultConformance):
    format = "mdem"

    def case(self, folder: Path):
        model = two_glass_spheres()
        return (lambda: samples.result_writer(model, folder)), granular_frames(model, 3)


class TestMdemTarget(TargetConformance):
    format = "mdem"


class TestMdemDocument(DocumentConformance):
    format = "mdem"
    sample = samples.SCENE
    cut = samples.DOCUMENT_CUT
