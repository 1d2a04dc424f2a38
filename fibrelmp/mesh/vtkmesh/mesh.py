"""VTK unstructured-grid mesh reader and writer, through meshio (a well-kept library that
reads and writes both VTK forms); region tags travel as the cell data array ``region``.

VTK has no length unit: a mesh is read in the unit the caller states (``unit``, metres per
coordinate unit; default 1 = metres) and written in metres unless told otherwise.

meshio reads a file whole: memory is of the order of the file's (decompressed) size.  Legacy
``.vtk`` structured datasets (STRUCTURED_POINTS, STRUCTURED_GRID, RECTILINEAR_GRID), whose
points and cells meshio generates from three header numbers (or coordinate counts), are
refused before meshio sees them: they are volume grids, never a surface mesh, and their
headers could ask for gigabytes.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import ClassVar

import numpy as np

from fibrelmp.formatbase import Reader, Writer
from fibrelmp.mesh.model import CELL_NODES, CellBlock, Mesh, MeshFormat

TAGS = "region"
SURFACE_DATASETS = ("UNSTRUCTURED_GRID", "POLYDATA")    # legacy .vtk datasets read
TAG_LIMIT = 2 ** 31                                       # region tags are 32-bit ints (openCARP's)


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
        legacy = self.path.suffix.lower() == ".vtk"
        if legacy:
            self._check_legacy_dataset()
        try:
            # the format's own reader: meshio.read() prints a failure and calls sys.exit(1)
            m = (meshio.vtk.read if legacy else meshio.vtu.read)(self.path)
        except (Exception, SystemExit) as exc:      # meshio raises many kinds for bad files
            what = "legacy VTK unstructured grid" if legacy else "VTK XML unstructured grid (.vtu)"
            raise self.error(None, f"cannot read as a {what}: meshio's {type(exc).__name__}"
                             + (f": {exc}" if str(exc).strip() else " (the file is not one, is cut "
                                "short, or its NumberOfPoints/NumberOfCells do not match its data)")) from None
        blocks = []
        tags = m.cell_data.get(TAGS)
        for i, block in enumerate(m.cells):
            if block.type not in CELL_NODES:
                if block.type == "vertex":
                    continue
                raise self.error(None, f"cell type {block.type!r} is not a finite-element cell "
                                 f"(known: {', '.join(CELL_NODES)})")
            data = np.asarray(block.data)
            if data.dtype.kind not in "iu":
                raise self.error(None, f"{block.type} cells: point indices of type {data.dtype}, "
                                 "expected integers")
            t = np.asarray(tags[i]).reshape(-1) if tags is not None else np.zeros(len(data), np.int64)
            if len(t) != len(data):
                raise self.error(None, f"{block.type} cells: {len(data)} cells but {len(t)} "
                                 f"'{TAGS}' values")
            if t.dtype.kind not in "iu":
                if t.dtype.kind != "f" or not np.all(np.isfinite(t) & (t == np.round(t))):
                    raise self.error(None, f"{block.type} cells: the '{TAGS}' tags must be integers")
            if len(t) and not (np.all(t >= -TAG_LIMIT) and np.all(t < TAG_LIMIT)):
                raise self.error(None, f"{block.type} cells: a '{TAGS}' tag outside the 32-bit range")
            blocks.append(CellBlock(block.type, data, t.astype(np.int64)))
        points = np.asarray(m.points, np.float64)
        if points.ndim != 2 or points.shape[1] not in (2, 3):
            raise self.error(None, f"points of shape {points.shape}, expected (n, 3)")
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

    def _check_legacy_dataset(self) -> None:
        """A legacy file's DATASET (line 4) must be one meshio reads without generating it."""
        try:
            with open(self.path, "rb") as fh:
                head = [fh.readline(1024) for _ in range(4)]
        except OSError as exc:
            raise self.error(None, f"cannot read VTK mesh: {exc.strerror or exc}") from None
        words = head[3].decode("ascii", "replace").split()
        if not head[0].startswith(b"# vtk DataFile Version"):
            raise self.error(1, "not a legacy VTK file (expected '# vtk DataFile Version ...')")
        if len(words) != 2 or words[0].upper() != "DATASET" or words[1].upper() not in SURFACE_DATASETS:
            raise self.error(4, f"expected DATASET {' or '.join(SURFACE_DATASETS)} (a surface mesh), "
                             f"got {' '.join(words)[:60]!r}")


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
