"""Vectorised ASCII formatting of numeric columns (no per-value Python code).

Floats are written in the shortest fixed-point form (<= 9 decimals) that reads back to the
identical double; columns that need more digits return None so callers fall back to %.17g.
"""

from __future__ import annotations

import numpy as np

_POW10 = 10 ** np.arange(19, dtype=np.int64)


def _fixed(s: np.ndarray, k: int) -> np.ndarray:
    """Text of s / 10^k (s int64) with exactly k decimals, right-aligned: (n, w) uint8."""
    neg = s < 0
    mag = np.abs(s)
    ndig = np.maximum(np.searchsorted(_POW10, mag, side="right"), k + 1)   # digits printed
    w = int(ndig.max(initial=1))
    d = np.empty((len(s), w), np.uint8)
    r = mag.copy()
    for j in range(w - 1, -1, -1):          # w vectorised passes, one per digit position
        r, digit = np.divmod(r, 10)
        d[:, j] = digit
    d += 48
    first = w - ndig                        # column of the first printed digit
    d[np.arange(w)[None, :] < first[:, None]] = 32
    if neg.any():
        d = np.hstack([np.full((len(s), 1), 32, np.uint8), d])
        rows = np.flatnonzero(neg)
        d[rows, first[rows]] = 45           # '-' just before the first digit
    if k:
        d = np.hstack([d[:, :-k], np.full((len(s), 1), 46, np.uint8), d[:, -k:]])
    return d


def scaled(x: np.ndarray, max_decimals: int = 9) -> tuple[np.ndarray, int] | None:
    """(s, k): the fewest decimals k <= max_decimals with x == s / 10^k exactly (s int64),
    or None when some value needs more (or is not finite).

    round(x 10^k) / 10^k == x means the k-decimal string is the correctly rounded decimal
    of x (integer / power of ten is correctly rounded in IEEE arithmetic), so float() or
    LAMMPS's strtod reads back the very same double.
    """
    x = np.asarray(x, np.float64)
    if not np.isfinite(x).all():
        return None
    big = float(np.abs(x).max(initial=0.0))
    first = 0
    if len(x) > 8192:       # a sample needs at most as many decimals as the column: start there
        found = scaled(x[:: len(x) // 1024], max_decimals)
        if found is None:
            return None
        first = found[1]
    for k in range(first, max_decimals + 1):
        scale = 10.0 ** k
        if big * scale >= 2.0 ** 53:
            return None
        s = np.round(x * scale)
        if (s / scale == x).all():
            return s.astype(np.int64), k
    return None


def float_text(x: np.ndarray, max_decimals: int = 9) -> np.ndarray | None:
    """Fixed-point text that parses back to exactly x, or None (caller falls back to repr);
    see ``scaled``."""
    found = scaled(x, max_decimals)
    return None if found is None else _fixed(*found)


def _width(s: np.ndarray, k: int) -> int:
    """The column width _fixed(s, k) gives: digits, a '-' column if any s < 0, a '.'."""
    mag = int(np.abs(s).max(initial=0))
    ndig = max(int(np.searchsorted(_POW10, mag, side="right")), k + 1)
    return ndig + bool((s < 0).any()) + (k > 0)


def _rows_text_c(columns: list) -> bytes | None:
    """rows_text through the C helper (the same bytes), or None when it cannot."""
    from fibrelmp.numtext import fast

    if fast.library() is None:
        return None
    n = len(columns[0])
    cols, decimals, widths = [], [], []
    for col in columns:
        if isinstance(col, str):
            if not col.isdigit() or str(int(col)) != col:
                return None
            s, k = np.full(n, int(col), np.int64), 0
        else:
            col = np.asarray(col)
            if col.dtype.kind in "iub":
                s, k = col.astype(np.int64), 0
            else:
                found = scaled(col)
                if found is None:
                    return None
                s, k = found
        if len(s) and int(s.min()) == np.iinfo(np.int64).min:
            return None
        cols.append(s)
        decimals.append(k)
        widths.append(_width(s, k))
    return fast.format_fixed_rows(np.column_stack(cols), np.array(decimals), np.array(widths))


def rows_text(columns: list) -> bytes | None:
    """Space-separated rows of int/float columns, or None if a float column needs repr."""
    n = len(columns[0])
    if n:
        text = _rows_text_c(columns)
        if text is not None:
            return text
    parts = []
    for col in columns:
        if isinstance(col, str):                    # literal text in every row
            parts += [np.frombuffer(col.encode() * n, np.uint8).reshape(n, -1),
                      np.full((n, 1), 32, np.uint8)]
            continue
        col = np.asarray(col)
        f = _fixed(col.astype(np.int64), 0) if col.dtype.kind in "iub" else float_text(col)
        if f is None:
            return None
        parts += [f, np.full((n, 1), 32, np.uint8)]
    parts[-1] = np.full((n, 1), 10, np.uint8)
    return np.hstack(parts).tobytes()
