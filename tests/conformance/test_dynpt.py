"""openCARP ``.dynpt`` node positions over time: the conformance checks of the ``motion``
role, on IGB files built byte by byte (not by fibrelmp's writer) by the home's samples
(``fibrelmp.mesh.opencarp.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.mesh.opencarp import samples

from .base import MotionConformance


class TestDynptMotion(MotionConformance):
    format = "dynpt"

    def sample(self, folder: Path):
        return samples.motion(folder)

    def bad_samples(self, folder: Path) -> list[Path]:
        return samples.bad_motions(folder)
