"""LAMMPS text dumps: the conformance checks of the ``frames`` role (``post``'s reader)."""

from __future__ import annotations

from pathlib import Path

from .base import FramesConformance, write_dump


class TestLammpsDumpFrames(FramesConformance):
    format = "lammps-dump"
    atoms = 6

    def sample(self, folder: Path) -> tuple[Path, Path]:
        good, _ = write_dump(folder, frames=3, n=self.atoms)
        bad = folder / "bad.dump"
        bad.write_text("hello\n")
        return good, bad
