"""The VTK mesh's reference sample for the conformance tests (tests/conformance/
test_vtk_mesh.py; docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path


def bad_mesh(folder: Path) -> Path:
    """``bad.vtu``: a VTK header, then no XML to the end."""
    bad = folder / "bad.vtu"
    bad.write_text("<VTKFile type='UnstructuredGrid'> not XML to the end\n")
    return bad
