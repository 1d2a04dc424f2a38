"""Fast path for FibreNet model files in the usual FibreGen layout (BEAD, SPRING, ANGLE blocks).

Each block is parsed by the C helper of ``numtext.fast`` (two threads for large blocks) or,
without it, by one np.loadtxt call; both give the same doubles.  Anything unusual (other layouts, HR_FL springs,
extra tokens, bad values) returns None and the line-by-line reader in fibrenet.py runs instead,
so error messages keep their exact line numbers.
"""

from __future__ import annotations

import io

import numpy as np

from fibrelmp.model import Angles, Particles
from fibrelmp.numtext import fast

_NCOLS = {"BEAD": 18, "SPRING": 7, "ANGLE": 10}
# bytes that str.splitlines()/str.split() treat as line breaks / whitespace but loadtxt may not
_ODD = (b"\x0b", b"\x0c", b"\x1c", b"\x1d", b"\x1e", b"\x1f")
_BLANK = frozenset(b" \t\r\n")


def _line_start(raw: bytes, key: bytes, probe: bytes, start: int = 0) -> int:
    """Offset of the first line at or after ``start`` that begins with ``key``, or -1.
    ``probe`` is a letter of ``key`` that lines before it rarely hold (no 'P' or 'A' in
    BEAD lines), so a few single-byte searches (memchr) usually find it; after 16 misses
    (e.g. type names with that letter) the general search takes over."""
    if raw.startswith(key, start) and (start == 0 or raw[start - 1] == 10):
        return start
    at = key.index(probe)
    i = raw.find(probe, start + at + 1)
    for _ in range(16):
        if i < 0:
            return -1
        j = i - at                              # where the key would start
        if raw[j - 1] == 10 and raw.startswith(key, j):
            return j
        i = raw.find(probe, i + 1)
    j = raw.find(b"\n" + key, max(i - at - 1, start)) if i >= 0 else -1
    return -1 if j < 0 else j + 1


def model_blocks(raw: bytes) -> dict[str, memoryview] | None:
    """FibreGen layout (all BEAD lines, then SPRING lines, then ANGLE lines): {kind: its
    lines (ASCII, a view into ``raw``)}; None for any other layout or unusual bytes (use the
    slow path, which reports errors with line numbers)."""
    if not raw.isascii() or any(c in raw for c in _ODD):
        return None
    if b"\r" in raw and raw.count(b"\r") != raw.count(b"\r\n"):
        return None
    at = {"BEAD": 0 if raw.startswith(b"BEAD") else -1,
          "SPRING": _line_start(raw, b"SPRING", b"P")}
    # ANGLE lines come after the springs (a file with them elsewhere makes a block's parse
    # fail, and the line reader takes over)
    at["ANGLE"] = _line_start(raw, b"ANGLE", b"A", max(at["SPRING"], 0))
    if at["BEAD"] != 0:
        return None
    order = [k for k in _NCOLS if at[k] >= 0]
    if [at[k] for k in order] != sorted(at[k] for k in order):
        return None
    view = memoryview(raw)
    out = {k: view[0:0] for k in _NCOLS}
    bounds = [at[k] for k in order] + [len(raw)]
    for k, a, b in zip(order, bounds[:-1], bounds[1:]):
        out[k] = view[a:b]
    return out


def table(text: memoryview, kind: str, col1: dict) -> np.ndarray | None:
    """(ncols, n) floats of one block, one contiguous row per column; column 0 must be the
    keyword on every non-blank line, column 1 (type name / spring kind) is mapped through
    col1."""
    if not len(text):
        return np.zeros((_NCOLS[kind], 0))
    names = list(col1)
    # blank lines after the last row (before the next block) are what loadtxt skips as well
    end = len(text)
    while end and text[end - 1] in _BLANK:
        end -= 1
    val = fast.parse_tagged(text[:end], kind, names, _NCOLS[kind])
    if val is not None:
        val[1] = np.array([col1[n] for n in names], np.float64)[val[1].astype(np.int64)]
    else:
        val = _loadtxt(bytes(text).decode("ascii"), kind, col1)
        if val is None or val.shape[1] != _NCOLS[kind]:
            return None
        val = np.ascontiguousarray(val.T)
    if val.shape[0] != _NCOLS[kind] or not np.isfinite(val).all():
        return None
    return val


def _loadtxt(text: str, kind: str, col1: dict) -> np.ndarray | None:
    try:
        return np.loadtxt(io.StringIO(text), converters={0: {kind: 0.0}.__getitem__,
                                                        1: col1.__getitem__},
                         comments=None, ndmin=2, dtype=np.float64)
    except Exception:        # other lines, wrong column count, unknown name, bad number
        return None


def ints(col: np.ndarray) -> np.ndarray | None:
    # huge values go to the slow reader, which names them (the cast would wrap them)
    ok = (col == np.round(col)).all() and (np.abs(col) <= 2 ** 53).all()
    return col.astype(np.int64) if ok else None



def fast_read_model(raw: bytes, type_index: dict[str, int], type_names: list[str],
                    size: np.ndarray, springs_factory):
    """(particles, springs, angles) or None when the slow reader must handle the file."""
    blocks = model_blocks(raw[3:] if raw.startswith(b"\xef\xbb\xbf") else raw)
    if blocks is None:
        return None
    btext = blocks["BEAD"]
    if not len(btext):
        return None
    col = table(btext, "BEAD", {k: float(v) for k, v in type_index.items()})
    if col is None:
        return None
    n = col.shape[1]
    types, tags, loc = ints(col[1]), ints(col[2]), ints(col[3])
    if tags is None or loc is None:
        return None
    radius, mass = col[4], col[5]

    def xyz(k: int) -> np.ndarray:                  # (n, 3) of columns k, k+1, k+2
        return np.ascontiguousarray(col[k:k + 3].T)
    pos, vel, force, image = xyz(6), xyz(9), xyz(12), xyz(15)
    if (radius < 0).any() or (mass < 0).any() or ((pos < 0) | (pos > size)).any():
        return None
    v_old = np.repeat(vel[:, :1], 3, axis=1)       # FibreNet's (vx, vx, vx) quirk
    particles = Particles(list(type_names), types, pos, image, v_old, mass.copy(),
                          radius.copy(), tags, loc, force, vel.copy())
    stext = blocks["SPRING"]
    scol = table(stext, "SPRING", {"HR": 0.0})
    if scol is None:
        return None
    s = springs_factory(scol.shape[1])
    st, a0, a1 = ints(scol[2]), ints(scol[3]), ints(scol[4])
    if st is None or a0 is None or a1 is None:
        return None
    s.tags, s.atoms = st, np.column_stack([a0, a1]).reshape(-1, 2)
    s.r0, s.k = scol[5].copy(), scol[6].copy()
    if ((s.atoms < 0) | (s.atoms >= n)).any() or (s.r0 < 0).any() or (s.k < 0).any() \
            or (s.atoms[:, 0] == s.atoms[:, 1]).any():
        return None
    atext = blocks["ANGLE"]
    if not len(atext):
        return particles, s, Angles.empty()
    acol = table(atext, "ANGLE", {"HR": 0.0, "HR_FL": 1.0})
    if acol is None:
        return None
    cols = [ints(acol[c]) for c in (3, 4, 5)]
    if any(c is None for c in cols):
        return None
    atoms = np.column_stack(cols)
    if ((atoms < 0) | (atoms >= n)).any() or (atoms[:, 0] == atoms[:, 1]).any() \
            or (atoms[:, 1] == atoms[:, 2]).any() or (atoms[:, 0] == atoms[:, 2]).any():
        return None
    # theta0 is read with std::stof in FibreNet: float precision
    return particles, s, Angles(atoms, acol[9].copy(), acol[8].astype(np.float32).astype(np.float64))
