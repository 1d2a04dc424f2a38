"""Streaming reader for LAMMPS text dumps (``dump custom`` / ``write_dump``).

Frames are found from the ``ITEM: TIMESTEP`` markers; each atom block is parsed in one
vectorised call.  Memory holds one frame at a time.
"""

from __future__ import annotations

import gzip
from dataclasses import dataclass
from itertools import islice
from pathlib import Path
from typing import Iterator

import numpy as np

from ..errors import InputError


@dataclass
class Frame:
    step: int
    lo: np.ndarray              # (3,)
    hi: np.ndarray              # (3,)
    boundary: tuple[str, ...]   # e.g. ("pp", "mm", "mm")
    columns: dict[str, np.ndarray]

    @property
    def count(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    @property
    def periodic(self) -> np.ndarray:
        return np.array([b == "pp" for b in self.boundary])

    def column(self, name: str) -> np.ndarray:
        return self.columns[name]


def _open(path: Path):
    if path.suffix == ".gz":
        return gzip.open(path, "rb")
    return open(path, "rb")


def iter_frames(path: str | Path, warnings: list[tuple[str, str]] | None = None) -> Iterator[Frame]:
    """Yield frames of a text dump; a truncated last frame is dropped with a warning."""
    path = Path(path)
    if not path.exists():
        raise InputError(path, None, "dump file not found")
    line_no = 0
    with _open(path) as fh:
        while True:
            line = fh.readline()
            line_no += 1
            if not line:
                return
            if not line.strip():
                continue
            if not line.startswith(b"ITEM: TIMESTEP"):
                raise InputError(path, line_no, "expected 'ITEM: TIMESTEP' (is this a LAMMPS text dump?)")
            header = list(islice(fh, 8))
            if len(header) < 8 or not header[7].startswith(b"ITEM: ATOMS"):
                if warnings is not None:
                    warnings.append(("truncated dump", f"{path}:{line_no}: last frame is incomplete; ignored"))
                return
            try:
                step = int(header[0])
                natoms = int(header[2])
                box_words = header[3].split()[3:]
                bounds = np.array([np.array(header[4 + k].split()[:2], dtype=float) for k in range(3)])
            except (ValueError, IndexError):
                raise InputError(path, line_no + 1, "malformed dump header") from None
            names = [w.decode() for w in header[7].split()[2:]]
            rows = list(islice(fh, natoms))
            if len(rows) < natoms:
                if warnings is not None:
                    warnings.append(("truncated dump", f"{path}:{line_no}: last frame has {len(rows)} "
                                     f"of {natoms} atom lines; ignored"))
                return
            try:
                data = np.array(b" ".join(rows).split(), dtype=np.float64)
                data = data.reshape(natoms, len(names))
            except ValueError:
                raise InputError(path, line_no + 9, "atom block does not match its column header") from None
            line_no += 8 + natoms
            cols = {name: data[:, k] for k, name in enumerate(names)}
            yield Frame(step, bounds[:, 0].copy(), bounds[:, 1].copy(),
                        tuple(w.decode() for w in box_words), cols)
