"""VTK unstructured-grid mesh reader and writer, through meshio (a well-kept library that
reads and writes both VTK forms); region tags travel as the cell data array ``region``.

VTK has no length unit: a mesh is read in the unit the caller states (``unit``, metres per
coordinate unit; default 1 = metres) and written in metres unless told otherwise.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import ClassVar

import numpy as np

from fibrelmp.formatbase import Reader, Writer
from fibrelmp.mesh.model import CELL_NODES, CellBlock, Mesh, MeshFormat

TAGS = "region"


def _meshio():
    try:
        import meshio
    except ImportError:
        from fibrelmp.errors import InputError

        raise InputError(None, None, "VTK meshes need the meshio package: pip install meshio") from None
    return meshio


class VtkMeshReader(Reader):
    format: ClassVar[str] = "vtk-mesh"
    what: ClassVar[str] = "VTK mesh"

    def __init__(self, path: str | os.PathLike, unit: float = 1.0):
        super().__init__(path)
        self.unit = unit

    def read(self) -> Mesh:
        meshio = _meshio()
        try:
            m = meshio.read(self.path)
        except Exception as exc:           # meshio raises many kinds for bad files
            raise self.error(None, f"cannot read as a VTK mesh: {exc}") from None
        blocks = []
        tags = m.cell_data.get(TAGS)
        for i, block in enumerate(m.cells):
            if block.type not in CELL_NODES:
                if block.type == "vertex":
                    continue
                raise self.error(None, f"cell type {block.type!r} is not a finite-element cell "
                                 f"(known: {', '.join(CELL_NODES)})")
            t = np.asarray(tags[i]).reshape(-1) if tags is not None else np.zeros(len(block.data))
            blocks.append(CellBlock(block.type, block.data, t.astype(np.int64)))
        points = np.asarray(m.points, np.float64)
        if points.shape[1] == 2:
            points = np.hstack([points, np.zeros((len(points), 1))])
        if not np.isfinite(points).all():
            raise self.error(None, f"point {int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])}: "
                             "coordinates must be finite")
        for block in blocks:
            if len(block.nodes) and (block.nodes.min() < 0 or block.nodes.max() >= len(points)):
                bad = int(np.flatnonzero((block.nodes < 0).any(axis=1) | (block.nodes >= len(points)).any(axis=1))[0])
                raise self.error(None, f"{block.kind} cell {bad} names a point outside 0..{len(points) - 1}")
        return Mesh(points, blocks, unit=self.unit, name=self.path.stem)


class VtkMeshWriter(Writer):
    """``add(mesh)`` once: ``target`` (``.vtu`` or ``.vtk``), coordinates in ``unit``."""

    format: ClassVar[str] = "vtk-mesh"

    def __init__(self, target: str | os.PathLike, unit: float = 1.0, *, force: bool = True):
        super().__init__(target, force=force)
        self.unit = unit

    def write(self, mesh: Mesh) -> None:
        meshio = _meshio()
        out = meshio.Mesh(mesh.in_unit(self.unit), [(b.kind, b.nodes) for b in mesh.cells],
                          cell_data={TAGS: [b.tags for b in mesh.cells]})
        staged = self.stage(self.target)
        try:
            meshio.write(staged, out, file_format="vtu" if Path(self.target).suffix.lower() == ".vtu"
                         else "vtk", **({"binary": True} if Path(self.target).suffix.lower() == ".vtk" else {}))
        except OSError as exc:
            exc.output = self.target
            raise


class VtkMesh(MeshFormat):
    reader = VtkMeshReader
    writer = VtkMeshWriter
