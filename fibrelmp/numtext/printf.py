"""Vectorised text formatting that is byte-identical to C/Python ``printf`` conversions.

``fixed_chars`` reproduces ``"%.Nf" % x`` for whole arrays without per-value Python code:
the value times 10^N is split into an exact sum p + e (Dekker's error-free product), so the
rounding decision -- including exact ties, which printf breaks to even -- is made on the
exact decimal value, as glibc and CPython's dtoa do.  Values it cannot do exactly (nan, inf,
|x| 10^N >= 2^51) make it return None and callers fall back to ``%``.

Padding is NUL (0) so that rows of fields can be assembled in a fixed-width uint8 matrix and
the padding removed in one C pass with ``bytes.translate(None, b"\\0")``.
"""

from __future__ import annotations

import numpy as np

_SPLIT = 134217729.0          # 2^27 + 1, Veltkamp splitter for doubles
_LIMIT = 2.0 ** 51            # below this p - floor(p) is exact and ulp(p) <= 0.25


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = _SPLIT * a
    hi = c - (c - a)
    return hi, a - hi


def round_scaled(x: np.ndarray, decimals: int) -> np.ndarray | None:
    """round(|x| * 10^decimals) as int64, rounded like printf (exact value, ties to even)."""
    a = np.abs(x)
    scale = 10.0 ** decimals                  # exact for decimals <= 22
    if not np.isfinite(a).all() or (a.size and float(a.max()) * scale >= _LIMIT):
        return None
    p = a * scale
    ah, al = _split(a)
    bh, bl = _split(np.float64(scale))
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl     # p + e == a * scale exactly
    s = np.floor(p)
    f = p - s                                             # exact (p < 2^51)
    m = s.astype(np.int64)
    m += f > 0.5
    tie = np.flatnonzero(f == 0.5)                        # p is exactly halfway: e decides
    if tie.size:
        et = e[tie]
        m[tie] += (et > 0) | ((et == 0) & (m[tie] % 2 == 1))
    return m


def _lut(width: int) -> np.ndarray:
    """uint32 per value 0..10^width-1: its zero-filled digits, first digit in the low byte."""
    v = np.arange(10 ** width)
    out = np.zeros(10 ** width, np.uint32)
    for k in range(width):
        out |= ((v // 10 ** (width - 1 - k)) % 10 + 48).astype(np.uint32) << (8 * k)
    return out


_DIGITS = {g: _lut(g) for g in (1, 2, 3)}


def _int_lut() -> np.ndarray:
    """uint32 per (negative, 0..999): right-aligned text in 4 bytes, NUL padding."""
    out = np.zeros(2000, np.uint32)
    for neg in (0, 1):
        for v in range(1000):
            text = (b"-" if neg else b"") + str(v).encode()
            out[neg * 1000 + v] = int.from_bytes(text.rjust(4, b"\0"), "little")
    return out


_INT4 = _int_lut()


def _fast(m: np.ndarray, ip: np.ndarray, neg: np.ndarray, decimals: int) -> np.ndarray:
    """Values with |integer part| < 1000 and <= 7 decimals: whole fields from tables."""
    n = m.shape[0]
    rec = np.zeros(n, dtype=[("i", "<u4"), ("f", "<u8")])
    rec["i"] = np.take(_INT4, ip + 1000 * neg)
    if decimals:
        r = m - ip * 10 ** decimals
        packed = np.full(n, 46, np.uint64)                 # '.'
        shift, left = 8, decimals
        while left:
            g = left % 3 or 3                              # leftmost group first
            left -= g
            group = (r // 10 ** left) % 10 ** g if left else r % 10 ** g
            packed |= np.take(_DIGITS[g], group).astype(np.uint64) << np.uint64(shift)
            shift += 8 * g
        rec["f"] = packed
    return rec.view(np.uint8).reshape(n, 12)[:, :4 + (decimals + 1 if decimals else 0)]


def fixed_chars(x: np.ndarray, decimals: int) -> np.ndarray | None:
    """``"%.{decimals}f" % v`` for each v in the 1-D array x, as an (n, w) uint8 matrix.

    Each row holds the text right-aligned, NUL-padded on the left.  None if some value
    needs the slow path (non-finite or too large for exact int64 arithmetic).
    """
    x = np.asarray(x, np.float64).ravel()
    m = round_scaled(x, decimals)
    if m is None:
        return None
    n = x.shape[0]
    neg = np.signbit(x)                                   # printf keeps the sign of -0.0
    unit = 10 ** decimals
    ip = m // unit
    big = int(ip.max(initial=0))
    if big < 1000 and decimals <= 7:
        return _fast(m, ip, neg, decimals)
    wi = len(str(big))
    sign_w = 1 if neg.any() else 0
    width = sign_w + wi + (decimals + 1 if decimals else 0)
    # built column-major (one contiguous row per character position), transposed at the end
    out = np.zeros((width, n), np.uint8)
    if decimals:
        r = m - ip * unit
        for j in range(width - 1, width - 1 - decimals, -1):
            r, d = np.divmod(r, 10)
            out[j] = d
            out[j] += 48
        out[width - 1 - decimals] = 46                    # '.'
    j = sign_w + wi - 1                                   # units digit: always printed
    r, d = np.divmod(ip, 10)
    out[j] = d
    out[j] += 48
    for j in range(j - 1, -1, -1):
        printed = r > 0
        r, d = np.divmod(r, 10)
        # digits while something is left; then '-' right after the last printed digit
        sign_here = neg & ~printed
        out[j] = np.where(printed, d + 48, np.where(sign_here, 45, 0))
        neg = neg & printed
    return out.T


def join_fields(fields: list[np.ndarray | bytes], n: int) -> bytes:
    """Concatenate per-row fields into text: each field is an (n, w) uint8 matrix (NUL
    padding is dropped) or a literal separator (bytes) repeated on every row."""
    parts = []
    for f in fields:
        if isinstance(f, bytes):
            parts.append(np.broadcast_to(np.frombuffer(f, np.uint8), (n, len(f))))
        else:
            parts.append(f)
    if n == 0:
        return b""
    return np.hstack(parts).tobytes().translate(None, b"\0")


def name_chars(codes: np.ndarray, table: list[str]) -> np.ndarray:
    """(n, w) NUL-padded text of ``table[codes[i]]``."""
    enc = [t.encode() for t in table] or [b""]
    w = max(1, max(len(e) for e in enc))
    lut = np.zeros((len(enc), w), np.uint8)
    for k, e in enumerate(enc):
        lut[k, :len(e)] = np.frombuffer(e, np.uint8)
    return lut[codes]
