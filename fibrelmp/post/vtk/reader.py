"""Reading back ParaView ``.vtu``/``.pvd`` files (tests; structure checks without VTK
installed)."""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class Vtu:
    points: np.ndarray
    point_data: dict[str, np.ndarray]
    connectivity: np.ndarray
    offsets: np.ndarray
    types: np.ndarray
    step: int | None


_NP = {"Float64": np.float64, "Float32": np.float32, "Int64": np.int64, "Int32": np.int32,
       "UInt8": np.uint8, "UInt64": np.uint64}


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


def read_vtu(path: str | Path) -> Vtu:
    root = ET.parse(path).getroot()
    if root.get("type") != "UnstructuredGrid":
        raise ValueError(f"{path}: not an UnstructuredGrid")
    header = np.uint64 if root.get("header_type") == "UInt64" else np.uint32
    piece = root.find("UnstructuredGrid/Piece")
    arrays = {}
    pd = {el.get("Name"): _decode_array(el, header) for el in piece.findall("PointData/DataArray")}
    for el in piece.findall("Cells/DataArray"):
        arrays[el.get("Name")] = _decode_array(el, header)
    pts = _decode_array(piece.find("Points/DataArray"), header).reshape(-1, 3)
    npts, ncells = int(piece.get("NumberOfPoints")), int(piece.get("NumberOfCells"))
    if len(pts) != npts or len(arrays["types"]) != ncells or len(arrays["offsets"]) != ncells:
        raise ValueError(f"{path}: array sizes do not match NumberOfPoints/NumberOfCells")
    step_el = root.find("UnstructuredGrid/FieldData/DataArray")
    step = int(_decode_array(step_el, header)[0]) if step_el is not None else None
    return Vtu(pts, pd, arrays["connectivity"], arrays["offsets"], arrays["types"], step)


def read_pvd(path: str | Path) -> list[tuple[float, Path]]:
    root = ET.parse(path).getroot()
    folder = Path(path).parent
    return [(float(ds.get("timestep")), folder / ds.get("file")) for ds in root.iter("DataSet")]
