"""Trajectories read through MDAnalysis: the ``frames`` role, on a small XYZ file."""

from __future__ import annotations

from pathlib import Path

import pytest

from .base import FramesConformance


class TestMdanalysisFrames(FramesConformance):
    format = "mdanalysis"
    atoms = 2

    def sample(self, folder: Path) -> tuple[Path, Path]:
        pytest.importorskip("MDAnalysis")
        good = folder / "t.xyz"
        good.write_text("".join(f"2\nframe {k}\nC 0 0 {k}\nO 1 0 {k}\n" for k in range(3)))
        bad = folder / "bad.xyz"
        bad.write_text("not a trajectory\n")
        return good, bad
