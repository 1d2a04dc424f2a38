"""FibreNet output formats: ``_coord/_vel/_force.xyz`` frames and ``_restart.res``.

Formats as FibreNet's DumpData / DumpRestartData write them (std::fixed 5 decimals for the
xyz files, default ostream precision -- 6 significant digits -- for the restart file).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.textio import (atomic_write, discard, format_rows, parse_table, read_text, temp_name,
                      write_failure)
from fibrelmp.numtext.fast import format_xyz_parts
from fibrelmp.numtext.printf import fixed_chars, join_fields, name_chars

XYZ_SUFFIX = {"position": "_coord.xyz", "velocity": "_vel.xyz", "force": "_force.xyz"}
RESTART_SUFFIX = "_restart.res"


def _rows(fmt_row: str, names: np.ndarray, values: np.ndarray) -> str:
    return format_rows(fmt_row, [names] + [values[:, c] for c in range(values.shape[1])])


def _xyz_head(n: int, step: int, dt: float, lengths: np.ndarray) -> str:
    return f"{n}\nFRAME\t{step}\t{dt:.5f}\t{lengths[0]:.5f}\t{lengths[1]:.5f}\t{lengths[2]:.5f}\n"


def xyz_frame_parts(step: int, dt: float, lengths: np.ndarray, codes: np.ndarray, table: list[str],
                    values: np.ndarray) -> list:
    """One xyz frame as buffers to write in turn (see xyz_frame_bytes)."""
    n = len(codes)
    head = _xyz_head(n, step, dt, lengths).encode()
    fast = format_xyz_parts(codes, table, values, 5) if n else None     # optional C path
    if fast is not None:
        return [head] + fast
    chars = fixed_chars(values.ravel(), 5) if n else None
    if chars is None:
        names = np.array(table, dtype=object)[codes] if n else np.zeros(0, object)
        return [head + _rows("%s\t%.5f\t%.5f\t%.5f\n", names, values).encode()]
    chars = chars.reshape(n, 3, -1)
    return [head + join_fields([name_chars(codes, table), b"\t", chars[:, 0], b"\t", chars[:, 1],
                                b"\t", chars[:, 2], b"\n"], n)]


def xyz_frame_bytes(step: int, dt: float, lengths: np.ndarray, codes: np.ndarray, table: list[str],
                    values: np.ndarray) -> bytes:
    """One xyz frame; row i is ``table[codes[i]]`` and values[i] ("%s\t%.5f\t%.5f\t%.5f").

    Formatted in C when available (fastparse), else with array operations (textfmt); both
    byte-identical to ``%.5f``; values that need it (nan, inf, huge) take the ``%`` path.
    """
    parts = xyz_frame_parts(step, dt, lengths, codes, table, values)
    return parts[0] if len(parts) == 1 else b"".join(bytes(p) for p in parts)


def xyz_frame(step: int, dt: float, lengths: np.ndarray, names: np.ndarray, values: np.ndarray) -> str:
    table, codes = np.unique(np.asarray(names, dtype=str), return_inverse=True)
    return xyz_frame_bytes(step, dt, lengths, codes.ravel(), list(table), values).decode()


class XyzWriter:
    """Append frames to a temp file; ``close`` renames it into place (no half outputs).

    Any OSError (a full disk...) removes the temp file and raises ``write_failure``'s
    error naming the output."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.tmp = temp_name(self.path)
        self.fh = None
        try:
            self.fh = open(self.tmp, "wb")
        except OSError as exc:
            self._fail(exc)

    def _fail(self, exc: OSError):
        self.abort()
        raise write_failure(self.path, exc) from None

    def write(self, step: int, dt: float, lengths: np.ndarray, names: np.ndarray, values: np.ndarray) -> None:
        try:
            self.fh.write(xyz_frame(step, dt, lengths, names, values).encode())
        except OSError as exc:
            self._fail(exc)

    def write_codes(self, step: int, dt: float, lengths: np.ndarray, codes: np.ndarray, table: list[str],
                    values: np.ndarray) -> None:
        try:
            for part in xyz_frame_parts(step, dt, lengths, codes, table, values):
                self.fh.write(part)
        except OSError as exc:
            self._fail(exc)

    def close(self) -> None:
        try:
            self.fh.close()
            os.replace(self.tmp, self.path)
        except OSError as exc:
            self._fail(exc)

    def abort(self) -> None:
        discard(self.tmp, self.fh)


def _g(x: float) -> str:
    return f"{x:g}"


def restart_text(step: int, dt: float, lengths: np.ndarray, names: np.ndarray, x: np.ndarray,
                 unwrapped: np.ndarray, v_tilde: np.ndarray, force: np.ndarray) -> str:
    head = (f"{len(names)}\nFRAME\t{step}\t{_g(dt)}\t{_g(lengths[0])}\t{_g(lengths[1])}\t"
            f"{_g(lengths[2])}\n")
    values = np.hstack([x, unwrapped, v_tilde, force])
    return head + _rows("\t%s" + "\t%g" * 12 + "\n", names, values)


def write_restart(path: str | Path, *args) -> None:
    atomic_write(path, restart_text(*args))


@dataclass
class XyzFrame:
    step: int
    dt: float
    lengths: np.ndarray
    names: list[str]
    values: np.ndarray


def read_xyz(path: str | Path) -> list[XyzFrame]:
    """Read every frame of a FibreNet xyz file."""
    path = Path(path)
    lines = read_text(path, "FibreNet xyz file").splitlines()
    frames, i = [], 0
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        try:
            n = int(lines[i])
        except ValueError:
            raise InputError(path, i + 1, f"expected a bead count, got {lines[i]!r}") from None
        head = lines[i + 1].split() if i + 1 < len(lines) else []
        if len(head) != 6 or head[0] != "FRAME":
            raise InputError(path, i + 2, "expected 'FRAME step dt Lx Ly Lz'")
        body = lines[i + 2:i + 2 + n]
        if len(body) < n:
            raise InputError(path, i + 3 + len(body), f"frame has {len(body)} of {n} rows")
        table, val = parse_table(body, list(range(i + 3, i + 3 + n)), 4, path, "xyz", text_cols=(0,))
        frames.append(XyzFrame(int(head[1]), float(head[2]), np.array(head[3:], float),
                               list(table[:, 0]), val[:, 1:4]))
        i += 2 + n
    return frames


def read_restart(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Bead rows of a FibreNet restart file: types and (n,12) x, ix, v~, F.

    As FibreNet does, only lines of exactly 13 tokens count as bead rows.
    """
    path = Path(path)
    raw = read_text(path, "FibreNet restart file").splitlines()
    keep = [(k + 1, ln) for k, ln in enumerate(raw) if len(ln.split()) == 13]
    if not keep:
        raise InputError(path, None, "no bead rows (lines of 13 tokens: type x y z ix iy iz vx vy vz fx fy fz)")
    numbers, lines = [k for k, _ in keep], [ln for _, ln in keep]
    table, val = parse_table(lines, numbers, 13, path, "restart row", text_cols=(0,))
    return list(table[:, 0]), val[:, 1:]
