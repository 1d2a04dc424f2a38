"""openCARP mesh reader and writer (``.pts``/``.elem`` text, ``.bpts``/``.belem`` binary).

Text: a count line, then ``x y z`` per node (µm); a count line, then ``TAG n0 n1 ... [region]``
per element (``Tt`` tetra, ``Hx`` hexahedron, ``Py`` pyramid, ``Pr`` prism, ``Qd`` quad, ``Tr``
triangle, ``Ln``/``Cx`` line).  Binary (meshtool): a 1024-byte NUL-padded ASCII header
``"<count> <endianness 0|1> 666"``, then float32 ``x y z`` per node, or per element int32
``type`` (0 Tt, 1 Hx, 2 Oc, 3 Py, 4 Pr, 5 Qd, 6 Tr, 7 Ln), its int32 nodes and int32 region.

Elements keep their file order (element indices are referenced by other openCARP files):
consecutive elements of one kind form one cell block.  Coordinates keep their µm values, so
a mesh read and written in one form is the same numbers (text: each double's shortest
exact form).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import ClassVar

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Reader, Writer
from fibrelmp.mesh.model import CELL_NODES, CellBlock, Mesh, MeshFormat

MICROMETRE = 1e-6
HEADER = 1024
TEXT_TAGS = {"Ln": "line", "Cx": "line", "Tr": "triangle", "Qd": "quad", "Tt": "tetra",
             "Py": "pyramid", "Pr": "wedge", "Hx": "hexahedron"}
WRITE_TAGS = {"line": "Ln", "triangle": "Tr", "quad": "Qd", "tetra": "Tt", "pyramid": "Py",
              "wedge": "Pr", "hexahedron": "Hx"}
BINARY_TYPES = {0: "tetra", 1: "hexahedron", 3: "pyramid", 4: "wedge", 5: "quad", 6: "triangle",
                7: "line"}
BINARY_CODES = {kind: code for code, kind in BINARY_TYPES.items()}
# region tags are C ints in openCARP and int32 in .belem files: larger ones are refused (a
# text tag of 1e23 digits must not overflow the int64 arrays)
TAG_RANGE = (-2 ** 31, 2 ** 31 - 1)


def mesh_files(path: str | os.PathLike) -> tuple[Path, Path, bool]:
    """(points file, elements file, binary) for a mesh named by either file or its base name;
    a base name prefers the binary files when both exist (as meshtool does)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".pts", ".elem"):
        return path.with_suffix(".pts"), path.with_suffix(".elem"), False
    if suffix in (".bpts", ".belem"):
        return path.with_suffix(".bpts"), path.with_suffix(".belem"), True
    binary = path.with_name(path.name + ".bpts").exists()
    ext = (".bpts", ".belem") if binary else (".pts", ".elem")
    return path.with_name(path.name + ext[0]), path.with_name(path.name + ext[1]), binary


class OpenCarpMeshReader(Reader):
    format: ClassVar[str] = "opencarp"
    what: ClassVar[str] = "openCARP mesh"

    def __init__(self, path: str | os.PathLike):
        self.points_file, self.elements_file, self.binary = mesh_files(path)
        super().__init__(self.points_file)
        from fibrelmp.registry import check_regular_file

        check_regular_file(self.elements_file, self.what)

    def read(self) -> Mesh:
        if self.binary:
            points = self._binary_points()
            kinds, nodes, tags = self._binary_elements(len(points))
        else:
            points = self._text_points()
            kinds, nodes, tags = self._text_elements(len(points))
        return Mesh(points, _blocks(kinds, nodes, tags), unit=MICROMETRE,
                    name=self.points_file.stem)

    # -- text ----------------------------------------------------------------------------
    def _lines(self, path: Path) -> list[str]:
        from fibrelmp.textio import read_text

        return read_text(path, self.what).splitlines()

    def _count(self, path: Path, lines: list[str]) -> int:
        try:
            n = int(lines[0].split()[0])
        except (IndexError, ValueError):
            raise InputError(path, 1, "expected the number of entries on the first line") from None
        if n < 0 or n > len(lines) - 1:
            raise InputError(path, 1, f"the file says {n} entries but has {len(lines) - 1} lines after it")
        return n

    def _text_points(self) -> np.ndarray:
        path = self.points_file
        lines = self._lines(path)
        n = self._count(path, lines)
        try:
            points = np.array([ln.split()[:3] for ln in lines[1:n + 1]], dtype=np.float64).reshape(n, 3)
        except ValueError:
            for i, ln in enumerate(lines[1:n + 1], 2):
                tok = ln.split()
                try:
                    if len(tok) < 3:
                        raise ValueError
                    [float(t) for t in tok[:3]]
                except ValueError:
                    raise InputError(path, i, f"expected x y z, got {ln.strip()!r}") from None
            raise
        if not np.isfinite(points).all():
            bad = int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])
            raise InputError(path, bad + 2, "coordinates must be finite")
        return points

    def _text_elements(self, npoints: int):
        path = self.elements_file
        lines = self._lines(path)
        n = self._count(path, lines)
        kinds, nodes, tags = [], [], []
        for i, ln in enumerate(lines[1:n + 1], 2):
            tok = ln.split()
            kind = TEXT_TAGS.get(tok[0]) if tok else None
            if kind is None:
                raise InputError(path, i, f"unknown element type {tok[0] if tok else ''!r} "
                                 f"(known: {', '.join(TEXT_TAGS)})")
            k = CELL_NODES[kind]
            if len(tok) not in (k + 1, k + 2):
                raise InputError(path, i, f"{tok[0]} needs {k} node indices and an optional region, "
                                 f"got {len(tok) - 1} values")
            try:
                values = [int(t) for t in tok[1:]]
            except ValueError:
                raise InputError(path, i, "node indices and the region must be integers") from None
            if min(values[:k]) < 0 or max(values[:k]) >= npoints:
                raise InputError(path, i, f"node index outside 0..{npoints - 1}")
            tag = values[k] if len(values) > k else 0
            if not TAG_RANGE[0] <= tag <= TAG_RANGE[1]:
                raise InputError(path, i, f"region tag {tag} outside the 32-bit range openCARP stores "
                                 f"({TAG_RANGE[0]}..{TAG_RANGE[1]})")
            kinds.append(kind)
            nodes.append(values[:k])
            tags.append(tag)
        return kinds, nodes, tags

    # -- binary --------------------------------------------------------------------------
    def _header_count(self, path: Path, data: bytes) -> int:
        if len(data) < HEADER:
            raise InputError(path, None, f"truncated: {len(data)} bytes, shorter than the "
                             f"{HEADER}-byte header")
        text = data[:HEADER].split(b"\0", 1)[0].decode("ascii", "replace").split()
        try:
            count = int(text[0])
            endian = int(text[1]) if len(text) > 1 else 0
        except (IndexError, ValueError):
            raise InputError(path, None, "the 1024-byte header does not start with the entry "
                             "count") from None
        if count < 0:
            raise InputError(path, None, f"the header says {count} entries (negative)")
        if endian not in (0, 1) or (endian == 1) != (sys.byteorder == "big"):
            raise InputError(path, None, f"written with byte order flag {endian}, which this "
                             "machine cannot read (meshtool writes native order)")
        return count

    def _binary_points(self) -> np.ndarray:
        path = self.points_file
        data = path.read_bytes()
        n = self._header_count(path, data)
        if len(data) != HEADER + 12 * n:
            raise InputError(path, None, f"the header says {n} points ({HEADER + 12 * n} bytes) "
                             f"but the file has {len(data)} bytes")
        points = np.frombuffer(data, np.float32, 3 * n, HEADER).reshape(n, 3).astype(np.float64)
        if not np.isfinite(points).all():
            bad = int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])
            raise InputError(path, None, f"point {bad}: coordinates must be finite")
        return points

    def _binary_elements(self, npoints: int):
        path = self.elements_file
        data = path.read_bytes()
        n = self._header_count(path, data)
        words = np.frombuffer(data, np.int32, (len(data) - HEADER) // 4, HEADER)
        kinds, nodes, tags = [], [], []
        at = 0
        for e in range(n):
            if at >= len(words):
                raise InputError(path, None, f"truncated: the header says {n} elements, the "
                                 f"file ends in element {e}")
            kind = BINARY_TYPES.get(int(words[at]))
            if kind is None:
                raise InputError(path, None, f"element {e}: unknown type code {int(words[at])}")
            k = CELL_NODES[kind]
            if at + k + 2 > len(words):
                raise InputError(path, None, f"truncated in element {e}")
            ids = words[at + 1:at + 1 + k]
            if ids.min() < 0 or ids.max() >= npoints:
                raise InputError(path, None, f"element {e}: node index outside 0..{npoints - 1}")
            kinds.append(kind)
            nodes.append(ids)
            tags.append(int(words[at + 1 + k]))
            at += k + 2
        if at != len(words) or (len(data) - HEADER) % 4:
            raise InputError(path, None, f"{len(data) - HEADER - 4 * at} bytes after the last of "
                             f"{n} elements")
        return kinds, nodes, tags


def _blocks(kinds: list[str], nodes: list, tags: list[int]) -> list[CellBlock]:
    """Consecutive elements of one kind as one block (file order kept)."""
    blocks, start = [], 0
    for i in range(1, len(kinds) + 1):
        if i == len(kinds) or kinds[i] != kinds[start]:
            blocks.append(CellBlock(kinds[start], np.array(nodes[start:i], np.int64),
                                    np.array(tags[start:i], np.int64)))
            start = i
    return blocks


class OpenCarpMeshWriter(Writer):
    """``add(mesh)`` once: ``<target>.pts`` + ``.elem`` (or ``.bpts`` + ``.belem`` with
    ``binary``); ``target`` is the base name (a given suffix is dropped)."""

    format: ClassVar[str] = "opencarp"

    def __init__(self, target: str | os.PathLike, binary: bool = False, *, force: bool = True):
        target = Path(target)
        if target.suffix.lower() in (".pts", ".elem", ".bpts", ".belem"):
            target = target.with_suffix("")
        self.binary = binary
        ext = (".bpts", ".belem") if binary else (".pts", ".elem")
        self.files = [target.with_name(target.name + e) for e in ext]
        super().__init__(target, force=force)

    def outputs(self) -> list[Path]:
        return list(self.files)

    def write(self, mesh: Mesh) -> None:
        points = mesh.in_unit(MICROMETRE)
        blocks = mesh.cells
        count = sum(len(b.nodes) for b in blocks)
        if self.binary:
            self.write_file(self.files[0], _header(len(points)) + points.astype("<f4").tobytes())
            parts = [_header(count)]
            for b in blocks:
                k = CELL_NODES[b.kind]
                rows = np.empty((len(b.nodes), k + 2), "<i4")
                rows[:, 0] = BINARY_CODES[b.kind]
                rows[:, 1:k + 1] = b.nodes
                rows[:, k + 1] = b.tags
                parts.append(rows.tobytes())
            self.write_file(self.files[1], b"".join(parts))
            return
        # repr: the shortest text that reads back as the same double
        text = [f"{len(points)}\n"] + [" ".join(map(repr, p)) + "\n" for p in points.tolist()]
        self.write_file(self.files[0], "".join(text).encode())
        lines = [f"{count}\n"]
        for b in blocks:
            tag = WRITE_TAGS[b.kind]
            lines += [f"{tag} {' '.join(map(str, row))} {t}\n"
                      for row, t in zip(b.nodes.tolist(), b.tags.tolist())]
        self.write_file(self.files[1], "".join(lines).encode())


def _header(count: int) -> bytes:
    return f"{count} {0 if sys.byteorder == 'little' else 1} 666".encode().ljust(HEADER, b"\0")





class OpenCarpMesh(MeshFormat):
    reader = OpenCarpMeshReader
    writer = OpenCarpMeshWriter
