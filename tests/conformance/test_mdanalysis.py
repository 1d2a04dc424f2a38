"""Trajectories read through MDAnalysis: the ``frames`` role, on a small XYZ file made by the
home's samples (``fibrelmp.post.mdanalysis.samples``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fibrelmp.post.mdanalysis import samples

from .base import FramesConformance


class TestMdanalysisFrames(FramesConformance):
    format = "mdanalysis"
    atoms = samples.ATOMS

    def sample(self, folder: Path) -> tuple[Path, Path]:
        pytest.importorskip("MDAnalysis")
        return samples.trajectories(folder)
