"""openCARP meshes (``.pts``/``.elem``): the conformance checks of the ``mesh`` role; the bad
sample comes from the home (``fibrelmp.mesh.opencarp.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.mesh.opencarp import samples

from .base import MeshConformance


class TestOpencarpMesh(MeshConformance):
    format = "opencarp"
    suffix = ""

    def bad_sample(self, folder: Path) -> Path:
        return samples.bad_mesh(folder)
