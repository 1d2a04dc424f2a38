"""VTK unstructured-grid meshes (through meshio): the conformance checks of the ``mesh`` role;
the bad sample comes from the home (``fibrelmp.mesh.vtkmesh.samples``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.mesh.vtkmesh import samples

from .base import MeshConformance


class TestVtkMesh(MeshConformance):
    format = "vtk-mesh"
    suffix = ".vtu"
    needs = ("meshio",)

    def bad_sample(self, folder: Path) -> Path:
        return samples.bad_mesh(folder)
