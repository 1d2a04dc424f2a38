"""VTK unstructured-grid meshes (through meshio): the conformance checks of the ``mesh`` role."""

from __future__ import annotations

from pathlib import Path

from .base import MeshConformance


class TestVtkMesh(MeshConformance):
    format = "vtk-mesh"
    suffix = ".vtu"
    needs = ("meshio",)

    def bad_sample(self, folder: Path) -> Path:
        bad = folder / "bad.vtu"
        bad.write_text("<VTKFile type='UnstructuredGrid'> not XML to the end\n")
        return bad
