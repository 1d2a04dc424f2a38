"""Files ParaView and OVITO both open: a ``.pvd`` time series of VTK XML PolyData frames.

Layout (``<base>`` = the output name without suffix)::

    <base>.pvd                  the frames with their simulation times (open this)
    <base>_NNNNNN.vtp           the particles of frame NNNNNN: points with one vertex each
    <base>_NNNNNN_bonds.vtp     its bonds as lines (output with bonds; none in a frame without)
    <base>_NNNNNN.vtm           the two above as one multiblock frame (output with bonds)
    <base>_walls.pvd            wall triangles over time (runs with MUSEN walls; open it too)
    <base>_NNNNNN_walls.vtp     the walls of frame NNNNNN: PolyData of triangles (polygons)

Why PolyData and not an UnstructuredGrid (``.vtu``): OVITO (3.17) reads particles only from
PolyData made of vertices (its ``.vtu`` reader takes a simulation cell: 8 points, 1 cell),
and bonds from a PolyData file of lines with the cell arrays ``id1``/``id2``, joined per
frame by a ``.vtm`` (the layout of Aspherix's output).  ParaView reads all of them.  Arrays
are inline base64 (``format="binary"``) or ascii, never compressed (OVITO reads no
compressed arrays), with UInt64 headers (VTK XML version 1.0).

Walls are a separate series of PolyData files of triangles: OVITO reads PolyData with
polygons as a surface mesh (its ``.vtu`` reader takes only a simulation cell), ParaView and
VTK as any PolyData; meshio reads no PolyData.  They are a series of their own, since only
runs with walls have them.

Bonds that cross a periodic face are drawn cut at the face (``frame.bond_segments``): each
piece is its own line with the bond's ``id1``/``id2``, so a bond is one or more lines.
"""

from __future__ import annotations

import base64
import re
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.post.vtk.frame import ViewerFrame, bond_rows, bond_segments, from_dump

_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32", np.dtype(np.int64): "Int64",
          np.dtype(np.int32): "Int32", np.dtype(np.uint8): "UInt8"}
COMPONENTS = {3: ("X", "Y", "Z"), 4: ("X", "Y", "Z", "W")}     # named, as OVITO shows them
HEAD = ('<?xml version="1.0"?>\n<VTKFile type="{kind}" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n')


# characters XML 1.0 cannot hold at all, escaped or not (C0 controls but tab/LF/CR, lone
# surrogates of undecodable file-name bytes, U+FFFE/U+FFFF)
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_ATTR_ENTITIES = {'"': "&quot;", "\n": "&#10;", "\r": "&#13;", "\t": "&#9;"}


def xml_attr(value: str, what: str = "name") -> str:
    """``value`` as a double-quoted XML attribute value: every name and file name the VTK
    files carry goes through here (``&``, ``<``, ``>``, ``"`` and line breaks escaped, so
    VTK's expat parser reads back exactly ``value``).  Characters XML cannot hold at all
    are an InputError naming ``what``."""
    value = str(value)
    bad = _NOT_XML.search(value)
    if bad:
        raise InputError(None, None, f"{what} {value!r} has a character a VTK XML file cannot hold "
                         f"({bad.group()!r}); rename it")
    return '"' + escape(value, _ATTR_ENTITIES) + '"'


def check_output_name(base: Path) -> None:
    """An output base name the ``.pvd``/``.vtm`` files can name (an InputError before
    anything is written, not an unreadable file afterwards)."""
    try:
        xml_attr(Path(base).name, "output name")
    except InputError as exc:
        raise InputError(base, None, exc.message) from None


def time_text(time: float) -> str:
    """A time as written in the ``.pvd`` and ``TimeValue``: rounded to 15 significant digits
    (shortest form), so 8 x 0.1 reads ``0.8``, not ``0.7999999999999999``; a double holds
    15 digits exactly, and the 16th-17th of a running sum are round-off."""
    return repr(float(f"{float(time):.15g}"))


def data_array(name: str, data: np.ndarray, ascii_: bool = False) -> str:
    """One ``<DataArray>``: (n,) or (n, k) numbers, k components named X Y Z (W)."""
    data = np.ascontiguousarray(data)
    if data.dtype not in _TYPES:
        data = data.astype(np.int64 if data.dtype.kind in "iub" else np.float64)
    ncomp = data.shape[1] if data.ndim == 2 else 1
    attrs = f'type="{_TYPES[data.dtype]}" Name={xml_attr(name, "array name")}'
    if ncomp > 1:
        attrs += f' NumberOfComponents="{ncomp}"'
        attrs += "".join(f' ComponentName{k}="{c}"' for k, c in enumerate(COMPONENTS.get(ncomp, ())))
    if ascii_:
        flat = data.ravel().tolist()
        text = " ".join(map(repr, flat)) if data.dtype.kind == "f" else " ".join(map(str, flat))
        return f'<DataArray {attrs} format="ascii">{text}</DataArray>\n'
    raw = data.astype(data.dtype.newbyteorder("<"), copy=False).tobytes()
    payload = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode()
    return f'<DataArray {attrs} format="binary">{payload}</DataArray>\n'


def _field_data(frame: ViewerFrame) -> str:
    # TimeValue: the name VTK readers take as the dataset's time
    return ("<FieldData>\n"
            f'<DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">{time_text(frame.time)}</DataArray>\n'
            f'<DataArray type="Int64" Name="TimeStep" NumberOfTuples="1" format="ascii">{int(frame.step)}</DataArray>\n'
            "</FieldData>\n")


def _cells(tag: str, per_cell: int, count: int, ascii_: bool) -> str:
    return (f"<{tag}>\n" + data_array("connectivity", np.arange(per_cell * count, dtype=np.int64), ascii_)
            + data_array("offsets", per_cell * np.arange(1, count + 1, dtype=np.int64), ascii_)
            + f"</{tag}>\n")


def _piece(frame: ViewerFrame, points: np.ndarray, verts: int, lines: int, data: str,
           cells: str, ascii_: bool) -> bytes:
    # FieldData after the Piece: OVITO recognises the file by the first element inside
    # <PolyData>, which must be the Piece (VTK finds FieldData anywhere in it)
    return (HEAD.format(kind="PolyData") + "<PolyData>\n" +
            f'<Piece NumberOfPoints="{len(points)}" NumberOfVerts="{verts}" NumberOfLines="{lines}" '
            'NumberOfStrips="0" NumberOfPolys="0">\n' + data +
            "<Points>\n" + data_array("Points", points.reshape(-1, 3), ascii_) + "</Points>\n" +
            cells + "</Piece>\n" + _field_data(frame) + "</PolyData>\n</VTKFile>\n").encode()


def particles_vtp(frame: ViewerFrame, ascii_: bool = False) -> bytes:
    """The particles: one vertex per point; point data ``id`` then the frame's arrays."""
    n = len(frame.ids)
    arrays = [data_array("id", frame.ids.astype(np.int64), ascii_)]
    arrays += [data_array(name, values, ascii_) for name, values in frame.point_data.items()]
    return _piece(frame, frame.positions, n, 0, "<PointData>\n" + "".join(arrays) + "</PointData>\n",
                  _cells("Verts", 1, n, ascii_), ascii_)


def bonds_vtp(frame: ViewerFrame, ascii_: bool = False) -> bytes | None:
    """The bonds whose atoms are in the frame, as lines (two points each, cut at periodic
    faces); cell data ``id1``/``id2`` (atom ids) and the frame's bond arrays.  None when
    the frame has no such bond."""
    rows, which = bond_rows(frame.ids, frame.bonds)
    if len(rows) == 0:
        return None
    x = frame.positions
    seg = bond_segments(x[rows[:, 0]], x[rows[:, 1]], frame.origin, frame.cell, frame.periodic)
    bond = which[seg.bond]
    pairs = frame.bonds[bond]
    arrays = [data_array("id1", pairs[:, 0].astype(np.int64), ascii_),
              data_array("id2", pairs[:, 1].astype(np.int64), ascii_)]
    arrays += [data_array(name, values[bond], ascii_) for name, values in frame.bond_data.items()]
    points = np.stack([seg.start, seg.end], axis=1).reshape(-1, 3)
    return _piece(frame, points, 0, len(bond), "<CellData>\n" + "".join(arrays) + "</CellData>\n",
                  _cells("Lines", 2, len(bond), ascii_), ascii_)


def walls_vtp(frame: ViewerFrame, ascii_: bool = False) -> bytes:
    """The wall triangles as PolyData: three points and one polygon each (OVITO reads a
    PolyData file with polygons as a surface mesh, VTK and ParaView as any PolyData); cell
    data the frame's wall arrays (``Velocity``, ``Force``; CardioProof ``opening``)."""
    tri = np.asarray(frame.walls, np.float64).reshape(-1, 3, 3)
    k = len(tri)
    arrays = "".join(data_array(name, values, ascii_) for name, values in frame.wall_data.items())
    # Piece first inside <PolyData>, FieldData after it, as in _piece (OVITO's format check)
    return (HEAD.format(kind="PolyData") + "<PolyData>\n" +
            f'<Piece NumberOfPoints="{3 * k}" NumberOfVerts="0" NumberOfLines="0" '
            f'NumberOfStrips="0" NumberOfPolys="{k}">\n' +
            "<CellData>\n" + arrays + "</CellData>\n" +
            "<Points>\n" + data_array("Points", tri.reshape(-1, 3), ascii_) + "</Points>\n" +
            _cells("Polys", 3, k, ascii_) + "</Piece>\n" + _field_data(frame) +
            "</PolyData>\n</VTKFile>\n").encode()


def vtm_text(blocks: list[tuple[str, str | None]]) -> bytes:
    """A multiblock file naming each block's file (relative to the ``.vtm``); a block
    without a file is an empty block."""
    rows = "".join(f'<DataSet index="{k}" name={xml_attr(name, "block name")}'
                   + (f" file={xml_attr(file, 'file name')}" if file else "") + "/>\n"
                   for k, (name, file) in enumerate(blocks))
    return (HEAD.format(kind="vtkMultiBlockDataSet") + "<vtkMultiBlockDataSet>\n" + rows +
            "</vtkMultiBlockDataSet>\n</VTKFile>\n").encode()


def pvd_text(entries: list[tuple[float, Path]]) -> bytes:
    rows = "".join(f'<DataSet timestep="{time_text(t)}" group="" part="0" '
                   f'file={xml_attr(p.name, "file name")}/>\n' for t, p in entries)
    return ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            "<Collection>\n" + rows + "</Collection>\n</VTKFile>\n").encode()


class VtkWriter(Writer):
    """``<base>.pvd`` and per frame ``<base>_NNNNNN.vtp`` (+ ``_bonds.vtp`` and ``.vtm`` when
    ``bonded``), all renamed into place by ``close``.  ``add`` takes a ``ViewerFrame`` or a
    LAMMPS dump ``Frame`` (its bonds: ``bonds``, atom-id pairs; its time: ITEM: TIME, else
    its step)."""

    format = "vtk"

    def __init__(self, base: Path, bonds: np.ndarray | None = None, ascii_: bool = False, *,
                 bonded: bool | None = None, force: bool = True):
        super().__init__(base, force=force)
        check_output_name(self.target)
        self.bonds = bonds
        self.bonded = bonded if bonded is not None else bonds is not None and len(bonds) > 0
        self.ascii = ascii_
        self.entries: list[tuple[float, Path]] = []
        self.wall_entries: list[tuple[float, Path]] = []
        self.stage(self.pvd_path)             # listed first, written at close

    @property
    def base(self) -> Path:
        return self.target

    @property
    def pvd_path(self) -> Path:
        return self.target.with_name(self.target.name + ".pvd")

    @property
    def walls_pvd_path(self) -> Path:
        return self.target.with_name(self.target.name + "_walls.pvd")

    def outputs(self) -> list[Path]:
        return [self.pvd_path, self.walls_pvd_path]

    def frame_path(self, index: int, suffix: str) -> Path:
        return self.target.with_name(f"{self.target.name}_{index:06d}{suffix}")

    def write(self, frame: ViewerFrame | Frame) -> None:
        if not isinstance(frame, ViewerFrame):
            frame = from_dump(frame, self.bonds)
        k = len(self.entries)
        particles = self.frame_path(k, ".vtp")
        self.write_file(particles, particles_vtp(frame, self.ascii))
        listed = particles
        if self.bonded:
            # a frame without bonds has an empty Bonds block and no bonds file: OVITO would
            # read an empty PolyData file as (no) particles
            lines = bonds_vtp(frame, self.ascii)
            bonds = self.frame_path(k, "_bonds.vtp") if lines is not None else None
            if bonds is not None:
                self.write_file(bonds, lines)
            listed = self.frame_path(k, ".vtm")
            self.write_file(listed, vtm_text([("Particles", particles.name),
                                              ("Bonds", bonds.name if bonds else None)]))
        self.entries.append((frame.time, listed))
        if frame.walls is not None and len(frame.walls):
            walls = self.frame_path(k, "_walls.vtp")
            self.write_file(walls, walls_vtp(frame, self.ascii))
            self.wall_entries.append((frame.time, walls))

    def finish(self) -> None:
        self.write_file(self.pvd_path, pvd_text(self.entries))
        if self.wall_entries:
            self.write_file(self.walls_pvd_path, pvd_text(self.wall_entries))
