"""Small shared helpers for reading user text files with precise error locations."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from .errors import InputError


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """Read a text file; every failure becomes an InputError naming the path."""
    p = Path(path)
    if not p.exists():
        raise InputError(p, None, f"{what} not found")
    if p.is_dir():
        raise InputError(p, None, f"{what} is a directory, expected a text file")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(p, None, f"cannot read {what}: {exc.strerror or exc}") from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError(p, 1, f"{what} is UTF-16 encoded; save it as UTF-8 or ASCII text")
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    if b"\x00" in raw[:4096]:
        raise InputError(p, None, f"{what} looks binary (contains NUL bytes), expected text")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise InputError(p, line, f"{what} is not valid UTF-8 text (byte {exc.start})") from None


def to_float(token: str, path: Path, line: int, name: str) -> float:
    try:
        value = float(token)
    except ValueError:
        raise InputError(path, line, f"{name}: expected a number, got {token!r}") from None
    if not math.isfinite(value):
        raise InputError(path, line, f"{name}: value must be finite, got {token!r}")
    return value


def to_int(token: str, path: Path, line: int, name: str) -> int:
    try:
        return int(token)
    except ValueError:
        raise InputError(path, line, f"{name}: expected an integer, got {token!r}") from None


def parse_table(lines: list[str], line_numbers: list[int], ncols: int, path: Path,
                what: str, text_cols: tuple[int, ...] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Parse whitespace-separated rows of exactly ``ncols`` tokens, vectorised.

    Returns (strings (n, ncols) array, floats (n, ncols) array with nan in text columns).
    On any problem the offending line is located and reported.
    """
    n = len(lines)
    tokens = " ".join(lines).split()
    if len(tokens) != n * ncols:
        for ln, text in zip(line_numbers, lines):
            got = len(text.split())
            if got != ncols:
                raise InputError(path, ln, f"{what} line needs {ncols} tokens, found {got}")
    table = np.array(tokens, dtype=object).reshape(n, ncols) if n else np.zeros((0, ncols), object)
    numeric_cols = [c for c in range(ncols) if c not in text_cols]
    values = np.full((n, ncols), np.nan)
    if n:
        try:
            values[:, numeric_cols] = table[:, numeric_cols].astype(np.float64)
        except ValueError:
            for row in range(n):
                for c in numeric_cols:
                    to_float(table[row, c], path, line_numbers[row], f"{what} column {c + 1}")
        bad = ~np.isfinite(values[:, numeric_cols])
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise InputError(path, line_numbers[row],
                             f"{what} column {numeric_cols[col] + 1}: value must be finite, "
                             f"got {table[row, numeric_cols[col]]!r}")
    return table, values


def integer_column(values: np.ndarray, table: np.ndarray, col: int, path: Path,
                   line_numbers: list[int], what: str) -> np.ndarray:
    """Check a parsed float column holds integers and return it as int64."""
    column = values[:, col]
    bad = column != np.round(column)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise InputError(path, line_numbers[row],
                         f"{what} column {col + 1}: expected an integer, got {table[row, col]!r}")
    return column.astype(np.int64)


def atomic_write(path: str | os.PathLike, data: str | bytes) -> None:
    """Write a file through a temp file + rename so no half-written output is left."""
    p = Path(path)
    tmp = p.with_name(f".{p.name}.tmp{os.getpid()}")
    mode = "wb" if isinstance(data, bytes) else "w"
    try:
        with open(tmp, mode) as fh:
            fh.write(data)
        os.replace(tmp, p)
    except OSError as exc:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise InputError(p, None, f"cannot write output: {exc.strerror or exc}") from None


def format_rows(fmt_row: str, columns: list) -> str:
    """Format rows with one C-level % operation over all values (no per-row Python loop)."""
    n = len(columns[0])
    if n == 0:
        return ""
    flat = np.empty((n, len(columns)), dtype=object)
    for c, col in enumerate(columns):
        flat[:, c] = col.tolist() if isinstance(col, np.ndarray) else col
    return (fmt_row * n) % tuple(flat.ravel().tolist())
