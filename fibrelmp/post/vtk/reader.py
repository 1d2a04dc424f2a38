"""Reading back the VTK XML files fibrelmp writes (``.pvd``, ``.vtm``, ``.vtp``, ``.vtu``):
structure checks in tests and ``VtkTarget.read_back``, without VTK installed.  Inline arrays
only (ascii or base64 ``binary``), as the writer makes them."""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

_NP = {"Float64": np.float64, "Float32": np.float32, "Int64": np.int64, "Int32": np.int32,
       "UInt8": np.uint8, "UInt64": np.uint64}


@dataclass
class Piece:
    """The first piece of a PolyData or UnstructuredGrid file."""

    kind: str                                         # "PolyData" | "UnstructuredGrid"
    points: np.ndarray                                # (n,3)
    point_data: dict[str, np.ndarray]
    cell_data: dict[str, np.ndarray]
    field_data: dict[str, np.ndarray]
    # per cell kind ("Verts", "Lines"; "Cells" of a grid): connectivity, offsets (and types)
    cells: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    attributes: dict[str, str] = field(default_factory=dict)     # of <Piece>

    @property
    def time(self) -> float | None:
        t = self.field_data.get("TimeValue")
        return None if t is None else float(t[0])

    @property
    def step(self) -> int | None:
        s = self.field_data.get("TimeStep")
        return None if s is None else int(s[0])


def _decode_array(el: ET.Element, header: type) -> np.ndarray:
    dtype = np.dtype(_NP[el.get("type")]).newbyteorder("<")
    ncomp = int(el.get("NumberOfComponents", "1"))
    text = (el.text or "").strip()
    if el.get("format") == "ascii":
        data = np.array(text.split(), dtype=dtype) if text else np.zeros(0, dtype)
    else:
        raw = base64.b64decode(text)
        hsize = np.dtype(header).itemsize
        nbytes = int(np.frombuffer(raw[:hsize], header)[0])
        if nbytes != len(raw) - hsize:
            raise ValueError(f"DataArray {el.get('Name')}: header says {nbytes} bytes, has {len(raw) - hsize}")
        data = np.frombuffer(raw[hsize:], dtype)
    return data.reshape(-1, ncomp) if ncomp > 1 else data


def read_piece(path: str | Path) -> Piece:
    root = ET.parse(path).getroot()
    kind = root.get("type")
    if kind not in ("PolyData", "UnstructuredGrid"):
        raise ValueError(f"{path}: not PolyData or an UnstructuredGrid ({kind})")
    header = np.uint64 if root.get("header_type") == "UInt64" else np.uint32
    dataset = root.find(kind)
    piece = dataset.find("Piece")

    def arrays(where: ET.Element | None) -> dict[str, np.ndarray]:
        return {} if where is None else {el.get("Name"): _decode_array(el, header)
                                         for el in where.findall("DataArray")}
    cells = {tag: arrays(piece.find(tag)) for tag in ("Verts", "Lines", "Strips", "Polys", "Cells")
             if piece.find(tag) is not None}
    out = Piece(kind, arrays(piece.find("Points"))["Points"].reshape(-1, 3),
                arrays(piece.find("PointData")), arrays(piece.find("CellData")),
                arrays(dataset.find("FieldData")), cells, dict(piece.attrib))
    if len(out.points) != int(piece.get("NumberOfPoints")):
        raise ValueError(f"{path}: {len(out.points)} points, NumberOfPoints says {piece.get('NumberOfPoints')}")
    for tag, count in (("Verts", "NumberOfVerts"), ("Lines", "NumberOfLines"), ("Polys", "NumberOfPolys"),
                       ("Cells", "NumberOfCells")):
        if tag in cells and len(cells[tag]["offsets"]) != int(piece.get(count, "0")):
            raise ValueError(f"{path}: {tag} sizes do not match {count}")
    return out


def read_vtm(path: str | Path) -> dict[str, Path]:
    """Block name -> file of a multiblock file (empty blocks, without a file, left out)."""
    root = ET.parse(path).getroot()
    folder = Path(path).parent
    return {ds.get("name"): folder / ds.get("file") for ds in root.iter("DataSet") if ds.get("file")}


def read_frame(path: str | Path) -> dict[str, Piece]:
    """The blocks of one frame of a ``.pvd``: a ``.vtm``'s, or a single file's as
    ``{"Particles": piece}``."""
    path = Path(path)
    if path.suffix == ".vtm":
        return {name: read_piece(file) for name, file in read_vtm(path).items()}
    return {"Particles": read_piece(path)}


def read_pvd(path: str | Path) -> list[tuple[float, Path]]:
    root = ET.parse(path).getroot()
    folder = Path(path).parent
    return [(float(ds.get("timestep")), folder / ds.get("file")) for ds in root.iter("DataSet")]
