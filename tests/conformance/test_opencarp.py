"""openCARP meshes (``.pts``/``.elem``): the conformance checks of the ``mesh`` role."""

from __future__ import annotations

from pathlib import Path

from .base import MeshConformance


class TestOpencarpMesh(MeshConformance):
    format = "opencarp"
    suffix = ""

    def bad_sample(self, folder: Path) -> Path:
        (folder / "bad.pts").write_text("3\n0 0 0\n1 1 1\n")        # says 3 points, has 2
        (folder / "bad.elem").write_text("0\n")
        return folder / "bad.pts"
