"""Every trajectory format MDAnalysis reads (DCD, XTC, TRR, H5MD, ...) as dump Frames.

Values stay in MDAnalysis's base units (length in Angstrom, time in ps, velocity in
Angstrom/ps, force in kJ/(mol Angstrom)); types are the topology's type strings (numbers
when they all are, else labels numbered in order of appearance).
"""

from __future__ import annotations

import math
import os
import warnings as _warnings
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Reader
from fibrelmp.post.lammps_dump.reader import Frame


def box_from_dimensions(dim) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """lo, hi, tilt (None if orthogonal) of an MDAnalysis [a b c alpha beta gamma] box."""
    a, b, c, alpha, beta, gamma = (float(v) for v in dim)
    if np.allclose([alpha, beta, gamma], 90.0):
        return np.zeros(3), np.array([a, b, c]), None
    ca, cb, cg = (math.cos(math.radians(v)) for v in (alpha, beta, gamma))
    xy, xz = b * cg, c * cb
    ly = math.sqrt(b * b - xy * xy)
    yz = (b * c * ca - xy * xz) / ly
    lz = math.sqrt(max(c * c - xz * xz - yz * yz, 0.0))
    return np.zeros(3), np.array([a, ly, lz]), np.array([xy, xz, yz])


def _types(atoms) -> tuple[np.ndarray, dict[int, str]]:
    try:
        raw = np.asarray(atoms.types).astype(str)
    except Exception:                   # topology without types
        return np.ones(len(atoms)), {}
    try:
        return raw.astype(np.float64), {}
    except ValueError:
        names: dict[str, int] = {}
        codes = np.array([names.setdefault(t, len(names) + 1) for t in raw], np.float64)
        return codes, {v: k for k, v in names.items()}


def open_universe(trajectory: Path, topology: Path | None):
    try:
        import MDAnalysis as mda
    except ImportError:
        raise InputError(trajectory, None, "not a LAMMPS text dump, and MDAnalysis (needed for other "
                         "trajectory formats) is not installed") from None
    for p in (trajectory, topology):
        if p is not None and not Path(p).exists():
            raise InputError(p, None, "file not found")
    try:
        with _warnings.catch_warnings():
            _warnings.simplefilter("ignore")
            if topology is None:
                return mda.Universe(str(trajectory))
            return mda.Universe(str(topology), str(trajectory))
    except Exception as exc:            # MDAnalysis raises many kinds; all mean "cannot read"
        hint = "" if topology is not None else " (give --topology for formats without one)"
        raise InputError(trajectory, None, f"MDAnalysis cannot read it{hint}: "
                         f"{type(exc).__name__}: {exc}") from None


def iter_mda_frames(trajectory: Path, topology: Path | None, type_names: dict[int, str],
                    want: Callable[[int, object], bool] | None = None) -> Iterator[Frame]:
    """Frames of an MDAnalysis trajectory; fills ``type_names`` for label types."""
    u = open_universe(trajectory, topology)
    atoms = u.atoms
    ids = np.asarray(getattr(atoms, "ids", np.arange(1, len(atoms) + 1)), np.float64)
    types, names = _types(atoms)
    type_names.update(names)
    static = {}
    for attr, col in (("masses", "mass"), ("radii", "radius")):
        try:
            static[col] = np.asarray(getattr(atoms, attr), np.float64)
        except Exception:               # NoDataError and friends: the topology lacks it
            pass
    try:
        for index, ts in enumerate(u.trajectory):
            if want is not None and not want(index, ts):
                continue
            cols = {"id": ids, "type": types, **static}
            x = np.asarray(ts.positions, np.float64)
            cols.update(x=x[:, 0].copy(), y=x[:, 1].copy(), z=x[:, 2].copy())
            for has, attr, names3 in (("has_velocities", "velocities", ("vx", "vy", "vz")),
                                      ("has_forces", "forces", ("fx", "fy", "fz"))):
                if getattr(ts, has, False):
                    v = np.asarray(getattr(ts, attr), np.float64)
                    cols.update({n: v[:, k].copy() for k, n in enumerate(names3)})
            if ts.dimensions is not None:
                lo, hi, tilt = box_from_dimensions(ts.dimensions)
                bnd = ("pp", "pp", "pp")
            else:
                lo, hi, tilt = (x.min(axis=0), x.max(axis=0), None) if len(x) else (np.zeros(3), np.zeros(3), None)
                bnd = ("ff", "ff", "ff")
            step = int(ts.data.get("step", ts.frame)) if hasattr(ts, "data") else int(ts.frame)
            yield Frame(step, lo, hi, bnd, cols, tilt, float(ts.time), None, None, str(trajectory), index)
    except InputError:
        raise
    except Exception as exc:
        raise InputError(trajectory, None, f"MDAnalysis failed reading a frame: {type(exc).__name__}: {exc}") from None


def mda_format(path: Path) -> bool:
    """Does MDAnalysis have a reader for the file's extension (other than LAMMPS dumps)?"""
    try:
        from MDAnalysis import _READERS
    except ImportError:
        return False
    ext = path.suffix.lstrip(".").upper()
    return bool(ext) and ext in _READERS and ext not in ("LAMMPSDUMP", "LAMMPSTRJ")


class UniverseReader(Reader):
    """Frames of any trajectory MDAnalysis reads (``topology`` for formats without one)."""

    format = "mdanalysis"
    what = "trajectory"

    def __init__(self, path: str | os.PathLike, topology: Path | None = None,
                 warnings: list[tuple[str, str]] | None = None):
        self.path = Path(path)
        self.topology = topology
        self.warnings = warnings if warnings is not None else []
        self.type_names: dict[int, str] = {}     # filled with label types while reading

    @classmethod
    def claims(cls, path: Path, topology: Path | None) -> bool:
        return topology is not None or mda_format(path)

    def count(self) -> int:
        return len(open_universe(self.path, self.topology).trajectory)

    def frames(self, want: Callable[[int], bool] | None = None,
               stop: int | None = None) -> Iterator[Frame]:
        return iter_mda_frames(self.path, self.topology, self.type_names,
                               want=None if want is None else (lambda i, ts: want(i)))

    def last(self) -> Frame | None:
        last = None
        for last in self.frames():
            pass
        return last

    def __iter__(self) -> Iterator[Frame]:
        return self.frames()

    def describe(self) -> list[str]:
        return describe_universe(self.path, self.topology)


def describe_universe(path: Path, topology: Path | None) -> list[str]:
    """``fibrelmp post --info`` of a trajectory MDAnalysis reads."""
    u = open_universe(path, topology)
    ts = u.trajectory.ts
    fmt = type(u.trajectory).__name__
    out = [f"file       {path} (MDAnalysis {fmt}{', topology ' + str(topology) if topology else ''})",
           f"frames     {len(u.trajectory)}",
           f"atoms      {len(u.atoms)}",
           "fields     positions" + (", velocities" if ts.has_velocities else "") +
           (", forces" if ts.has_forces else "")]
    if ts.dimensions is not None:
        out.append("box        " + " ".join(f"{v:g}" for v in ts.dimensions) + " (a b c alpha beta gamma)")
    out.append(f"time       {u.trajectory[0].time:g} .. {u.trajectory[-1].time:g} ps")
    return out
