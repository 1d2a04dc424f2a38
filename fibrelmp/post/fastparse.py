"""Optional C fast paths for dump parsing and xyz formatting (``_fastparse.c``).

The C source is compiled at first use with the system C compiler into a per-user cache
(``$XDG_CACHE_HOME/fibrelmp`` or ``~/.cache/fibrelmp``, keyed by a hash of the source) and
loaded with ctypes.  If anything fails (no compiler, read-only cache, load error) every
function here returns None and callers keep their numpy paths, which give identical results.
Set ``FIBRELMP_NO_C=1`` to disable the C paths.

Both C functions decline (return None here) on anything unusual -- text, inf/nan, bad token
counts, huge values -- so errors and edge cases are always handled by the numpy code.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import subprocess
import sys
import sysconfig
import tempfile
import threading
from pathlib import Path

import numpy as np

_SRC = Path(__file__).with_name("_fastparse.c")
_lock = threading.Lock()
_lib = None
_tried = False


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "fibrelmp"


def _build() -> ctypes.CDLL | None:
    src = _SRC.read_bytes()
    cc = (os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc").split()
    flags = ["-O3", "-shared", "-fPIC", "-fno-fast-math", "-ffp-contract=off"]
    key = hashlib.sha256(src + " ".join(cc + flags).encode() + sys.platform.encode()).hexdigest()[:16]
    folder = _cache_dir()
    lib = folder / f"fastparse-{key}.so"
    if not lib.exists():
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(suffix=".so", dir=folder)
        os.close(fd)
        try:
            subprocess.run(cc + flags + ["-o", tmp, str(_SRC), "-lm"], check=True,
                           stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, timeout=120)
            os.replace(tmp, lib)            # atomic: concurrent builders are harmless
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    dll = ctypes.CDLL(str(lib))
    i64, ptr = ctypes.c_int64, ctypes.c_void_p
    dll.fp_parse_block.argtypes = [ptr, i64, ptr, i64, i64]
    dll.fp_parse_block.restype = ctypes.c_int
    dll.fp_format_xyz.argtypes = [ptr, ptr, i64, ctypes.c_char_p, i64, i64, ctypes.c_int, ptr, i64]
    dll.fp_format_xyz.restype = i64
    dll.fp_count_lines.argtypes = [ptr, i64]
    dll.fp_count_lines.restype = i64
    dll.fp_nth_newline.argtypes = [ptr, i64, i64, ctypes.POINTER(i64)]
    dll.fp_nth_newline.restype = i64
    # self-check against Python's correctly rounded conversions before trusting it
    probe = b"0.1 -2.5e-3 1.7976931348623157e308 123456789012345678901 4.9e-324 -0\n"
    out = np.empty(6)
    praw = np.frombuffer(probe, np.uint8)
    if dll.fp_parse_block(praw.ctypes.data, len(probe), out.ctypes.data, 1, 6) != 0 or \
            out.tobytes() != np.array([float(t) for t in probe.split()]).tobytes():
        return None
    return dll


def library() -> ctypes.CDLL | None:
    """The loaded C helpers, or None (built once per process; failures are silent)."""
    global _lib, _tried
    if _tried:
        return _lib
    with _lock:
        if not _tried:
            try:
                _lib = None if os.environ.get("FIBRELMP_NO_C") else _build()
            except Exception:
                _lib = None
            _tried = True
    return _lib


# blocks / frames at least this large are split across two threads (ctypes drops the GIL)
SPLIT_BYTES = 1 << 20
_pool = None
_pool_pid = None


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _helper():
    """A one-thread pool for the second half of large calls, or None on one core."""
    global _pool, _pool_pid
    if _pool is None or _pool_pid != os.getpid():       # a forked child has no worker thread
        with _lock:
            if _pool is None or _pool_pid != os.getpid():
                from concurrent.futures import ThreadPoolExecutor

                _pool = ThreadPoolExecutor(1, thread_name_prefix="fibrelmp-fast") if _cores() > 1 else False
                _pool_pid = os.getpid()
    return _pool or None


def nth_newline(buf: bytearray, start: int, stop: int, need: int) -> tuple[int, int] | None:
    """(newlines found in buf[start:stop] up to ``need``, offset from start of the need-th or -1),
    or None without the C library."""
    lib = library()
    if lib is None or need < 1 or stop <= start:
        return None
    view = np.frombuffer(buf, np.uint8, count=stop - start, offset=start)
    found = ctypes.c_int64(0)
    try:
        k = lib.fp_nth_newline(view.ctypes.data, stop - start, need, ctypes.byref(found))
    finally:
        del view                        # release the export: the bytearray may grow later
    return found.value, k


def parse_numbers(block: bytes, nrows: int, ncols: int) -> np.ndarray | None:
    """(nrows, ncols) float64 array of a block of plain decimal numbers, or None."""
    lib = library()
    if lib is None or nrows <= 0 or ncols <= 0:
        return None
    out = np.empty((nrows, ncols), np.float64)
    raw = np.frombuffer(block, np.uint8)         # keeps ``block`` alive; .ctypes.data: no copy
    base = raw.ctypes.data
    pool = _helper() if len(block) >= SPLIT_BYTES and nrows >= 2 else None
    if pool is not None:
        mid = block.find(b"\n", len(block) // 2)
        if 0 <= mid < len(block) - 1:
            first = lib.fp_count_lines(base, mid + 1)           # rows in [0, mid]
            if 0 < first < nrows:
                job = pool.submit(lib.fp_parse_block, base + mid + 1, len(block) - mid - 1,
                                  out[first:].ctypes.data, nrows - first, ncols)
                ok = lib.fp_parse_block(base, mid + 1, out.ctypes.data, first, ncols) == 0
                ok = job.result() == 0 and ok
                return out if ok else None
    if lib.fp_parse_block(base, len(block), out.ctypes.data, nrows, ncols) != 0:
        return None
    return out


def _format_rows(lib, codes, values, n, names, nnames, w, decimals) -> np.ndarray | None:
    cap = n * (w + 3 * (28 + decimals) + 4) + 1
    buf = np.empty(cap, np.uint8)
    got = lib.fp_format_xyz(codes.ctypes.data, values.ctypes.data, n, names, nnames, w, decimals,
                            buf.ctypes.data, cap)
    return None if got < 0 else buf[:got]


def format_xyz_parts(codes: np.ndarray, table: list[str], values: np.ndarray,
                     decimals: int = 5) -> list[np.ndarray] | None:
    """Rows ``table[codes[i]]\\t%.{d}f\\t%.{d}f\\t%.{d}f\\n`` (printf-identical) as uint8 chunks, or None."""
    lib = library()
    n = len(codes)
    if lib is None or n == 0 or values.shape != (n, 3):
        return None
    enc = [t.encode() for t in table]
    if not enc or any(b"\0" in e for e in enc):
        return None
    w = max(1, max(len(e) for e in enc))
    names = b"".join(e.ljust(w, b"\0") for e in enc)
    codes = np.ascontiguousarray(codes, np.int64)
    values = np.ascontiguousarray(values, np.float64)
    pool = _helper() if n * 30 >= SPLIT_BYTES else None
    if pool is not None:
        h = n // 2
        job = pool.submit(_format_rows, lib, codes[h:], values[h:], n - h, names, len(enc), w, decimals)
        a = _format_rows(lib, codes[:h], values[:h], h, names, len(enc), w, decimals)
        b = job.result()
        return None if a is None or b is None else [a, b]
    a = _format_rows(lib, codes, values, n, names, len(enc), w, decimals)
    return None if a is None else [a]


def format_xyz(codes: np.ndarray, table: list[str], values: np.ndarray, decimals: int = 5) -> bytes | None:
    """As format_xyz_parts, joined into bytes."""
    parts = format_xyz_parts(codes, table, values, decimals)
    return None if parts is None else b"".join(p.tobytes() for p in parts)
