"""The spheres' saved states of a MUSEN text result (plain or .gz), read with fibrelmp's
reader: what the drum and oblique metrics share."""

from __future__ import annotations

import gzip
import shutil
import tempfile
from pathlib import Path


def sphere_time_points(path: str | Path, tags: tuple[int, ...] = (12, 15, 16)):
    """``read_time_points`` of the spheres (object type 1) of ``path``: coordinates (12),
    velocities (15) and angular velocities (16) by default; a .gz file is unpacked first."""
    from fibrelmp.translate.musen.text import read_time_points

    path = Path(path)
    if path.suffix != ".gz":
        return read_time_points(path, types=(1,), tags=tags)
    with tempfile.TemporaryDirectory() as tmp:
        plain = Path(tmp) / path.stem
        with gzip.open(path, "rb") as src, open(plain, "wb") as dst:
            shutil.copyfileobj(src, dst)
        return read_time_points(plain, types=(1,), tags=tags)
