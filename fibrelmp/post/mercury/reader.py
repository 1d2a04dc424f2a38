"""Reading MercuryDPM ``.data`` / ``.ene`` / ``.fstat`` files (tests, and checking files
against MercuryDPM's own); the layouts are described in post/mercury/writer.py."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.textio import read_text


@dataclass
class DataFrame:
    count: int
    time: float
    box: np.ndarray          # (4,) 2D or (6,) 3D
    rows: np.ndarray         # (count, 8 | 14)


def read_data_file(path: str | Path, dim: int | None = None) -> list[DataFrame]:
    """Frames of a ``.data`` file; the dimension comes from the first header's length."""
    path = Path(path)
    lines = read_text(path, "MercuryDPM .data file").splitlines()
    frames, k = [], 0
    while k < len(lines):
        head = lines[k].split()
        if not head:
            k += 1
            continue
        if dim is None:
            if len(head) not in (6, 8):
                raise InputError(path, k + 1, f"header needs 6 (2D) or 8 (3D) values, found {len(head)}")
            dim = 2 if len(head) == 6 else 3
        if len(head) != (6 if dim == 2 else 8):
            raise InputError(path, k + 1, f"{dim}D header needs {6 if dim == 2 else 8} values, found {len(head)}")
        n = int(head[0])
        ncol = 8 if dim == 2 else 14
        body = lines[k + 1:k + 1 + n]
        if len(body) < n:
            raise InputError(path, k + 2 + len(body), f"frame has {len(body)} of {n} particle lines")
        rows = np.array(" ".join(body).split(), dtype=float)
        if rows.size != n * ncol:
            bad = next(b for b, ln in enumerate(body) if len(ln.split()) != ncol)
            raise InputError(path, k + 2 + bad, f"particle line needs {ncol} values")
        frames.append(DataFrame(n, float(head[1]), np.array(head[2:], float), rows.reshape(n, ncol)))
        k += 1 + n
    return frames


def read_ene(path: str | Path) -> tuple[list[str], np.ndarray]:
    path = Path(path)
    lines = [ln for ln in read_text(path, "MercuryDPM .ene file").splitlines() if ln.strip()]
    if not lines:
        raise InputError(path, None, "empty .ene file")
    labels = lines[0].split()
    rows = np.array([ln.split() for ln in lines[1:]], dtype=float).reshape(len(lines) - 1, -1)
    if rows.size and rows.shape[1] != len(labels):
        raise InputError(path, 2, f"rows have {rows.shape[1]} values, header {len(labels)} labels")
    return labels, rows


@dataclass
class FstatFrame:
    time: float
    version: int
    box: np.ndarray          # (6,)
    radii: np.ndarray        # (6,) rmin rmax 0 0 0 0
    rows: np.ndarray         # (m, 16)


def read_fstat(path: str | Path) -> list[FstatFrame]:
    path = Path(path)
    lines = read_text(path, "MercuryDPM .fstat file").splitlines()
    frames: list[FstatFrame] = []
    k = 0
    while k < len(lines):
        if not lines[k].startswith("#"):
            raise InputError(path, k + 1, "expected the '# time version' line of a frame")
        if k + 2 >= len(lines) or not (lines[k + 1].startswith("#") and lines[k + 2].startswith("#")):
            raise InputError(path, k + 1, "a frame starts with three '#' lines")
        t = lines[k][1:].split()
        body = []
        j = k + 3
        while j < len(lines) and not lines[j].startswith("#"):
            if lines[j].strip():
                body.append(lines[j])
            j += 1
        rows = np.array(" ".join(body).split(), dtype=float)
        if rows.size % 16:
            bad = next(b for b, ln in enumerate(body) if len(ln.split()) != 16)
            raise InputError(path, k + 4 + bad, "contact line needs 16 values")
        frames.append(FstatFrame(float(t[0]), int(t[1]), np.array(lines[k + 1][1:].split(), float),
                                 np.array(lines[k + 2][1:].split(), float), rows.reshape(-1, 16)))
        k = j
    return frames
