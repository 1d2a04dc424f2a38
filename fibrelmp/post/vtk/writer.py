"""ParaView output: one XML UnstructuredGrid ``.vtu`` per frame and a ``.pvd`` collection.

Each atom is a VTK_VERTEX cell at its position (as dumped: wrapped into the box on
periodic axes); bonds (from ``--data``) are VTK_LINE cells, except those that span more
than half a periodic box length (they cross the boundary and would be drawn across the
box).  Point data: id, type, radius, mass, velocity, force, omega when known, and every
other numeric dump column as a scalar.  Arrays are base64 "binary" (VTK XML version 1.0,
UInt64 headers) or ascii.  The ``.pvd`` lists every ``.vtu`` with its time.
"""

from __future__ import annotations

import base64
from pathlib import Path

import numpy as np

from fibrelmp.formatbase import Writer
from fibrelmp.post.lammps_dump.reader import Frame

VTK_VERTEX, VTK_LINE = 1, 3
_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32", np.dtype(np.int64): "Int64",
          np.dtype(np.int32): "Int32", np.dtype(np.uint8): "UInt8"}
VECTORS = {"velocity": ("vx", "vy", "vz"), "force": ("fx", "fy", "fz"),
           "omega": ("omegax", "omegay", "omegaz"), "angmom": ("angmomx", "angmomy", "angmomz"),
           "torque": ("tqx", "tqy", "tqz"), "orientation": ("quatw", "quati", "quatj", "quatk")}
SKIP = {"x", "y", "z", "xs", "ys", "zs", "xu", "yu", "zu", "xsu", "ysu", "zsu", "id", "type"}


def _array_xml(name: str, data: np.ndarray, ascii_: bool) -> str:
    data = np.ascontiguousarray(data)
    ncomp = data.shape[1] if data.ndim == 2 else 1
    kind = _TYPES[data.dtype]
    comp = f' NumberOfComponents="{ncomp}"' if ncomp > 1 else ""
    if ascii_:
        flat = data.ravel()
        text = " ".join(map(repr, flat.tolist())) if data.dtype.kind == "f" else " ".join(map(str, flat.tolist()))
        return f'<DataArray type="{kind}" Name="{name}"{comp} format="ascii">{text}</DataArray>\n'
    raw = data.astype(data.dtype.newbyteorder("<"), copy=False).tobytes()
    payload = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode()
    return f'<DataArray type="{kind}" Name="{name}"{comp} format="binary">{payload}</DataArray>\n'


def bond_cells(ids: np.ndarray, bonds: np.ndarray, x: np.ndarray, frame: Frame) -> np.ndarray:
    """(m, 2) point indices of the bonds whose atoms are both in the frame."""
    if len(bonds) == 0 or len(ids) == 0:
        return np.zeros((0, 2), np.int64)
    k = np.searchsorted(ids, bonds)
    k = np.minimum(k, len(ids) - 1)
    ok = np.all(ids[k] == bonds, axis=1)
    pairs = k[ok]
    d = x[pairs[:, 1]] - x[pairs[:, 0]]
    per = frame.periodic
    if per.any():
        s = np.linalg.solve(frame.cell, d.T).T
        pairs = pairs[~np.any(np.abs(s[:, per]) > 0.5, axis=1)]
    return pairs


def vtu_text(frame: Frame, bonds: np.ndarray | None = None, ascii_: bool = False) -> str:
    """The .vtu document of one frame (atoms sorted by id)."""
    n = frame.count
    x = frame.wrapped()
    ids = frame.column("id").astype(np.int64)
    lines = bond_cells(ids, bonds, x, frame) if bonds is not None else np.zeros((0, 2), np.int64)
    m = len(lines)
    connectivity = np.concatenate([np.arange(n, dtype=np.int64), lines.ravel()])
    offsets = np.concatenate([np.arange(1, n + 1, dtype=np.int64), n + 2 * np.arange(1, m + 1, dtype=np.int64)])
    types = np.concatenate([np.full(n, VTK_VERTEX, np.uint8), np.full(m, VTK_LINE, np.uint8)])
    point = [_array_xml("id", ids, ascii_)]
    if "type" in frame.columns and np.asarray(frame.columns["type"]).dtype.kind in "fiu":
        point.append(_array_xml("type", frame.columns["type"].astype(np.int32), ascii_))
    used = set(SKIP)
    for name, cols in VECTORS.items():
        if frame.has(*cols):
            point.append(_array_xml(name, frame.vector(*cols), ascii_))
            used.update(cols)
    for name, col in frame.columns.items():
        if name in used or np.asarray(col).dtype.kind != "f":
            continue
        point.append(_array_xml(name, np.asarray(col, np.float64), ascii_))
    parts = [
        '<?xml version="1.0"?>\n',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
        "<UnstructuredGrid>\n",
        '<FieldData><DataArray type="Int64" Name="TimeStep" NumberOfTuples="1" format="ascii">'
        f"{frame.step}</DataArray></FieldData>\n",
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{n + m}">\n',
        "<PointData>\n", *point, "</PointData>\n",
        "<Points>\n", _array_xml("Points", x.reshape(n, 3), ascii_), "</Points>\n",
        "<Cells>\n", _array_xml("connectivity", connectivity, ascii_),
        _array_xml("offsets", offsets, ascii_), _array_xml("types", types, ascii_), "</Cells>\n",
        "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n",
    ]
    return "".join(parts)


class VtkWriter(Writer):
    """``<base>_NNNNNN.vtu`` per frame and the ``<base>.pvd`` index (at close), all renamed
    into place by ``close``.  A frame's time is its ITEM: TIME, else its step."""

    format = "vtk"

    def __init__(self, base: Path, bonds: np.ndarray | None = None, ascii_: bool = False, *,
                 force: bool = True):
        super().__init__(base, force=force)
        self.bonds = bonds
        self.ascii = ascii_
        self.entries: list[tuple[float, Path]] = []
        self.stage(self.pvd_path)             # listed first, written at close

    @property
    def base(self) -> Path:
        return self.target

    @property
    def pvd_path(self) -> Path:
        return self.target.with_name(self.target.name + ".pvd")

    def outputs(self) -> list[Path]:
        return [self.pvd_path]

    def vtu_path(self, index: int) -> Path:
        return self.target.with_name(f"{self.target.name}_{index:06d}.vtu")

    def write(self, frame: Frame) -> None:
        path = self.vtu_path(len(self.entries))
        self.write_file(path, vtu_text(frame, self.bonds, self.ascii).encode())
        self.entries.append((float(frame.step) if frame.time is None else frame.time, path))

    def finish(self) -> None:
        rows = "".join(f'<DataSet timestep="{t!r}" group="" part="0" file="{p.name}"/>\n'
                       for t, p in self.entries)
        self.write_file(self.pvd_path, ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" '
                                        'byte_order="LittleEndian">\n<Collection>\n' + rows +
                                        "</Collection>\n</VTKFile>\n").encode())
