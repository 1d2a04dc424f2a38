"""Optional C fast paths for dump parsing, xyz formatting and MUSEN ``.mdem`` time points
(``_fastparse.c``).

The C source is normally compiled when fibrelmp is installed (``setup.py``: an optional
build step that never fails the installation) into ``_fastparse_c<EXT_SUFFIX>`` next to this
file, and loaded with ctypes.  The library is looked for in this order:

1. the one built at install time, inside the package;
2. else (a source checkout, or no compiler at install time) the source is compiled at first
   use with the system C compiler into a per-user cache (``$XDG_CACHE_HOME/fibrelmp`` or
   ``~/.cache/fibrelmp``, keyed by a hash of the source and flags); a lock file makes
   concurrent processes (MPI ranks) wait for one compiler instead of each running their own;
3. else every function here returns None and callers keep their numpy paths, which give
   identical results (several times slower).

Each library is self-checked against Python's conversions before it is trusted.  Set
``FIBRELMP_NO_C=1`` to disable the C paths.  ``active_path()`` (printed by
``fibrelmp --version``) says which path is in use and why.

Both C functions decline (return None here) on anything unusual -- text, inf/nan, bad token
counts, huge values -- so errors and edge cases are always handled by the numpy code.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import os
import subprocess
import sys
import sysconfig
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np

_SRC = Path(__file__).with_name("_fastparse.c")
# built by setup.py (Extension "fibrelmp.numtext._fastparse_c"); loaded with ctypes, never imported
_INSTALLED = Path(__file__).with_name("_fastparse_c" + (sysconfig.get_config_var("EXT_SUFFIX") or ".so"))
_FLAGS = ["-O3", "-shared", "-fPIC", "-fno-fast-math", "-ffp-contract=off"]
_lock = threading.Lock()
_lib = None
_tried = False
_path = "not loaded yet"


class _Unavailable(Exception):
    """The C library could not be built or loaded; str() says why, in a few words."""


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "fibrelmp"


def _first_line(text: str) -> str:
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    hits = [ln for ln in lines if "error" in ln.lower()]
    line = (hits or lines or [""])[0]
    return line if len(line) <= 200 else line[:197] + "..."


def _locked(path: Path):
    """An exclusive lock file (released when the returned file is closed), or None when the
    file system cannot lock: os.replace keeps unlocked concurrent builds harmless anyway."""
    try:
        import fcntl

        handle = open(path, "a")
    except (ImportError, OSError):
        return None
    try:
        fcntl.flock(handle, fcntl.LOCK_EX)
    except OSError:
        handle.close()
        return None
    return handle


def _compile() -> Path:
    """Compile _fastparse.c into the cache once (per source, compiler and flags); its path."""
    src = _SRC.read_bytes()
    cc = (os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc").split()
    key = hashlib.sha256(src + " ".join(cc + _FLAGS).encode() + sys.platform.encode()).hexdigest()[:16]
    folder = _cache_dir()
    lib = folder / f"fastparse-{key}.so"
    if lib.exists():
        return lib
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _Unavailable(f"cannot create the cache folder {folder}: {exc.strerror or exc}") from exc
    lock = _locked(folder / f"fastparse-{key}.lock")
    try:
        if lib.exists():                    # another process built it while we waited
            return lib
        try:
            fd, tmp = tempfile.mkstemp(suffix=".so", dir=folder)
        except OSError as exc:
            raise _Unavailable(f"cannot write to the cache folder {folder}: {exc.strerror or exc}") from exc
        os.close(fd)
        try:
            proc = subprocess.run(cc + _FLAGS + ["-o", tmp, str(_SRC), "-lm"], stdin=subprocess.DEVNULL,
                                  capture_output=True, text=True, errors="replace", timeout=120)
            if proc.returncode != 0:
                why = _first_line(proc.stderr + proc.stdout) or f"exit status {proc.returncode}"
                raise _Unavailable(f"no C compiler: {' '.join(cc)} failed: {why}")
            os.replace(tmp, lib)            # atomic: concurrent builders are harmless
        except FileNotFoundError as exc:
            raise _Unavailable(f"no C compiler: {cc[0]!r} not found") from exc
        except subprocess.TimeoutExpired as exc:
            raise _Unavailable(f"no C compiler: {' '.join(cc)} timed out") from exc
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    finally:
        if lock is not None:
            lock.close()
    return lib


def _open(lib: Path) -> ctypes.CDLL:
    """Load the library, declare its functions and self-check it (else _Unavailable)."""
    try:
        dll = ctypes.CDLL(str(lib))
        i64, ptr = ctypes.c_int64, ctypes.c_void_p
        dll.fp_parse_block.argtypes = [ptr, i64, ptr, i64, i64]
        dll.fp_parse_block.restype = ctypes.c_int
        dll.fp_format_xyz.argtypes = [ptr, ptr, i64, ctypes.c_char_p, i64, i64, ctypes.c_int, ptr, i64]
        dll.fp_format_xyz.restype = i64
        dll.fp_parse_tagged.argtypes = [ptr, i64, ctypes.c_char_p, i64, ctypes.c_char_p, i64, i64,
                                         ptr, i64, i64, i64]
        dll.fp_parse_tagged.restype = ctypes.c_int
        dll.fp_format_fixed_rows.argtypes = [ptr, i64, i64, ptr, ptr, ptr, i64]
        dll.fp_format_fixed_rows.restype = i64
        dll.fp_format_g_rows.argtypes = [ptr, ptr, i64, i64, ctypes.c_char_p, i64, i64, ptr, i64]
        dll.fp_format_g_rows.restype = i64
        dll.fp_format_g_template.argtypes = [ptr, i64, i64, ctypes.c_char_p, i64, i64, ptr, i64]
        dll.fp_format_g_template.restype = i64
        dll.fp_count_lines.argtypes = [ptr, i64]
        dll.fp_count_lines.restype = i64
        dll.fp_nth_newline.argtypes = [ptr, i64, i64, ctypes.POINTER(i64)]
        dll.fp_nth_newline.restype = i64
        dll.fp_mdem_count.argtypes = [ptr, i64]
        dll.fp_mdem_count.restype = i64
        dll.fp_mdem_decode.argtypes = [ptr, i64, ptr, ptr, ptr, i64]
        dll.fp_mdem_decode.restype = ctypes.c_int
        dll.fp_mdem_encode.argtypes = [ctypes.c_double, ptr, ptr, i64, ptr, i64]
        dll.fp_mdem_encode.restype = i64
        dll.fp_mdem_blocks.argtypes = [ptr, i64, ptr, ptr, i64, ptr, ptr]
        dll.fp_mdem_blocks.restype = i64
        dll.fp_mdem_put_blocks.argtypes = [ptr, ptr, ptr, ptr, i64, i64, ptr, i64]
        dll.fp_mdem_put_blocks.restype = i64
        dll.fp_principal_stresses.argtypes = [ptr, i64, ptr]
        dll.fp_principal_stresses.restype = None
    except (OSError, AttributeError) as exc:
        raise _Unavailable(f"cannot load: {exc}") from exc
    # self-check against Python's correctly rounded conversions before trusting it
    probe = (b"0.1 -2.5e-3 1.7976931348623157e308 123456789012345678901 4.9e-324 -0 "
             b"43.549386012345678 9007199254740993 0.30000000000000004 -1.2345678901234567e-25\n")
    out = np.empty(10)
    praw = np.frombuffer(probe, np.uint8)
    if dll.fp_parse_block(praw.ctypes.data, len(probe), out.ctypes.data, 1, 10) != 0 or \
            out.tobytes() != np.array([float(t) for t in probe.split()]).tobytes():
        raise _Unavailable(f"{lib} failed its self-check")
    return dll


def _load() -> tuple[ctypes.CDLL | None, str]:
    """(library or None, description of the path in use) -- see active_path()."""
    if os.environ.get("FIBRELMP_NO_C"):
        return None, f"numpy (FIBRELMP_NO_C={os.environ['FIBRELMP_NO_C']})"
    if _INSTALLED.exists():
        try:
            return _open(_INSTALLED), f"C (installed: {_INSTALLED})"
        except Exception as exc:            # e.g. built for another machine, or corrupted
            installed = f"installed library unusable: {exc}"
    else:
        installed = "not built at install time"
    try:
        lib = _compile()
        return _open(lib), f"C (compiled at first use: {lib}; {installed})"
    except _Unavailable as exc:
        return None, f"numpy ({exc}; {installed})"
    except Exception as exc:                # never let the optional path break a conversion
        return None, f"numpy (C build failed: {type(exc).__name__}: {exc}; {installed})"


def library() -> ctypes.CDLL | None:
    """The loaded C helpers, or None (loaded once per process; failures are silent)."""
    global _lib, _tried, _path
    if _tried:
        return _lib
    with _lock:
        if not _tried:
            _lib, _path = _load()
            _tried = True
    return _lib


def active_path() -> str:
    """Which implementation the post fast paths use, e.g. ``C (installed: /path/lib.so)``,
    ``C (compiled at first use: ...)``, ``numpy (FIBRELMP_NO_C=1)`` or
    ``numpy (no C compiler: ...)``.  Loads the library first if needed."""
    library()
    return _path


# blocks / frames at least this large are split across two threads (ctypes drops the GIL)
SPLIT_BYTES = 1 << 20
_pool = None
_pool_pid = None


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


_cores_taken = 0         # cores this process keeps busy otherwise (LAMMPS during a run)


@contextlib.contextmanager
def cores_taken(n: int = 1):
    """While this is open, ``n`` cores are busy with other work of this process (a LAMMPS run
    that frames are converted beside): large calls split across threads only if a core is
    still free, so the conversion does not take cores from LAMMPS.  ``n = -1`` gives one back
    (the run is known to be over before its context ends)."""
    global _cores_taken
    with _lock:
        _cores_taken += n
    try:
        yield
    finally:
        with _lock:
            _cores_taken -= n


def _helper():
    """A one-thread pool for the second half of large calls, or None on one (free) core."""
    global _pool, _pool_pid
    if _cores() - _cores_taken < 2:
        return None
    if _pool is None or _pool_pid != os.getpid():       # a forked child has no worker thread
        with _lock:
            if _pool is None or _pool_pid != os.getpid():
                from concurrent.futures import ThreadPoolExecutor

                _pool = ThreadPoolExecutor(1, thread_name_prefix="fibrelmp-fast") if _cores() > 1 else False
                _pool_pid = os.getpid()
    return _pool or None


def helper_pool():
    """The one-thread pool that takes the second half of large calls (ctypes, zlib and file
    I/O release the GIL), or None when no core is free (one core, or LAMMPS running beside)."""
    return _helper()


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


def parse_tagged(block: bytes | memoryview, key: str, names: list[str], ncols: int) -> np.ndarray | None:
    """(ncols, nrows) float64 array -- one contiguous row per column -- of a FibreNet model
    block whose lines read ``key name number ...`` (ncols tokens): column 0 is 0, column 1
    the index of ``name`` in ``names``; None without the C library or for anything unusual
    (see fp_parse_tagged)."""
    lib = library()
    if lib is None or not len(block) or not names:
        return None
    enc = [n.encode() for n in names]
    if any(not e or b"\0" in e for e in enc) or b"\0" in key.encode():
        return None
    w = max(len(e) for e in enc)
    table = b"".join(e.ljust(w, b"\0") for e in enc)
    kb = key.encode()
    raw = np.frombuffer(block, np.uint8)         # no copy; keeps ``block`` alive
    base, size = raw.ctypes.data, len(raw)
    nrows = lib.fp_count_lines(base, size) + (0 if raw[-1] == 10 else 1)
    out = np.empty((ncols, nrows), np.float64)
    item = out.itemsize

    def part(start: int, stop: int, row0: int, rows: int) -> bool:
        return lib.fp_parse_tagged(base + start, stop - start, kb, len(kb), table, len(enc), w,
                                   out.ctypes.data + row0 * item, rows, ncols, nrows) == 0

    pool = _helper() if size >= SPLIT_BYTES and nrows >= 2 else None
    if pool is not None:
        found = np.flatnonzero(raw[size // 2:size // 2 + 4096] == 10)     # a '\n' near the middle
        mid = size // 2 + int(found[0]) if len(found) else -1
        if 0 <= mid < size - 1:
            first = lib.fp_count_lines(base, mid + 1)           # rows in [0, mid]
            if 0 < first < nrows:
                job = pool.submit(part, mid + 1, size, first, nrows - first)
                ok = part(0, mid + 1, 0, first)
                ok = job.result() and ok
                return out if ok else None
    return out if part(0, size, 0, nrows) else None


def format_fixed_rows(values: np.ndarray, decimals: np.ndarray, widths: np.ndarray) -> bytes | None:
    """Rows of (nrows, ncols) int64 ``values``, column c printed as value / 10^decimals[c]
    right-aligned in widths[c], one space between columns (see fp_format_fixed_rows); None
    without the C library or if a field does not fit its width."""
    lib = library()
    if lib is None or values.ndim != 2 or not values.size:
        return None
    values = np.ascontiguousarray(values, np.int64)
    k = np.ascontiguousarray(decimals, np.int64)
    w = np.ascontiguousarray(widths, np.int64)
    n, ncols = values.shape
    if len(k) != ncols or len(w) != ncols:
        return None
    row = int(w.sum()) + ncols              # every row has exactly this many bytes
    buf = np.empty(n * row, np.uint8)

    def part(a: int, b: int) -> bool:
        return lib.fp_format_fixed_rows(values[a:].ctypes.data, b - a, ncols, k.ctypes.data,
                                        w.ctypes.data, buf[a * row:].ctypes.data,
                                        (b - a) * row) == (b - a) * row
    pool = _helper() if n * row >= SPLIT_BYTES and n >= 2 else None
    if pool is not None:
        job = pool.submit(part, n // 2, n)
        ok = part(0, n // 2)
        ok = job.result() and ok
    else:
        ok = part(0, n)
    return buf.tobytes() if ok else None


def _joined_halves(part: Callable[[int, int], np.ndarray | None], n: int, large: bool) -> bytes | None:
    """``part(0, n)`` as bytes; when ``large`` and a core is free, ``part(n // 2, n)`` on the
    helper thread beside ``part(0, n // 2)``, joined in order.  None if a part is None."""
    pool = _helper() if large else None
    if pool is not None:
        job = pool.submit(part, n // 2, n)
        parts = [part(0, n // 2), job.result()]
    else:
        parts = [part(0, n)]
    if any(p is None for p in parts):
        return None
    return b"".join(p.tobytes() for p in parts)


def format_g_rows(codes: np.ndarray, table: list[str], values: np.ndarray) -> bytes | None:
    """Rows ``\t table[codes[i]]`` + ``\t%g`` per value + ``\n`` (printf-identical to
    Python's % formatting), or None without the C library or for non-finite values."""
    lib = library()
    n = len(codes)
    if lib is None or n == 0 or values.ndim != 2 or len(values) != n:
        return None
    enc = [t.encode() for t in table]
    if not enc or any(not e or b"\0" in e for e in enc):
        return None
    w = max(len(e) for e in enc)
    names = b"".join(e.ljust(w, b"\0") for e in enc)
    codes = np.ascontiguousarray(codes, np.int64)
    values = np.ascontiguousarray(values, np.float64)
    ncols = values.shape[1]
    row_cap = 1 + w + ncols * 32 + 1

    def part(a: int, b: int) -> np.ndarray | None:
        buf = np.empty((b - a) * row_cap, np.uint8)
        got = lib.fp_format_g_rows(codes[a:].ctypes.data, values[a:].ctypes.data, b - a, ncols,
                                   names, len(enc), w, buf.ctypes.data, len(buf))
        return None if got < 0 else buf[:got]
    return _joined_halves(part, n, n >= 4096)


def principal_stresses(tensors: np.ndarray) -> np.ndarray | None:
    """MUSEN's principal stresses of (n, 9) row-major tensors (``fp_principal_stresses``), or
    None without the C library."""
    lib = library()
    if lib is None:
        return None
    tensors = np.ascontiguousarray(tensors, np.float64).reshape(-1, 9)
    out = np.empty((len(tensors), 3))
    if len(tensors):
        lib.fp_principal_stresses(tensors.ctypes.data, len(tensors), out.ctypes.data)
    return out


def format_g_template(values: np.ndarray, prefixes: list[str], per_line: int) -> bytes | None:
    """Rows of ``values`` (nrows, len(prefixes)): each value ``prefixes[k]`` + ``%g`` + a space,
    a newline after every ``per_line`` rows (printf-identical to Python's % formatting); None
    without the C library or for non-finite values."""
    lib = library()
    if lib is None or values.ndim != 2 or values.shape[1] != len(prefixes) or per_line < 1 \
            or len(values) % per_line or not len(values) or not prefixes:
        return None
    enc = [t.encode() for t in prefixes]
    if any(b"\0" in e for e in enc):
        return None
    w = max(1, max(len(e) for e in enc))
    table = b"".join(e.ljust(w, b"\0") for e in enc)
    values = np.ascontiguousarray(values, np.float64)
    ncols = values.shape[1]
    lines = len(values) // per_line

    def part(a: int, b: int) -> np.ndarray | None:          # lines a..b
        rows = (b - a) * per_line
        buf = np.empty(rows * ncols * (w + 33) + (b - a) + 1, np.uint8)
        got = lib.fp_format_g_template(values[a * per_line:].ctypes.data, rows, ncols, table, w,
                                       per_line, buf.ctypes.data, len(buf))
        return None if got < 0 else buf[:got]
    return _joined_halves(part, lines, values.size >= 1 << 16 and lines >= 2)


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


# -- MUSEN .mdem time points (protobuf wire format) -----------------------------------------
MDEM_COLUMNS = 34       # the columns of fp_mdem_decode (see _fastparse.c)


def mdem_decode(raw: bytes, most: int | None = None) -> tuple[float, np.ndarray, np.ndarray] | None:
    """A serialized ``ProtoTimePoint``: (time, values (n, 34), field masks (n,) uint32);
    None without the C library; ValueError if malformed."""
    lib = library()
    if lib is None or sys.byteorder != "little":
        return None
    buf = np.frombuffer(raw, np.uint8)
    if not buf.size:
        buf = np.zeros(1, np.uint8)
    n = lib.fp_mdem_count(buf.ctypes.data, len(raw))
    if n < 0:
        raise ValueError("malformed time point")
    if most is not None and n > most:
        raise ValueError(f"{n} objects in a time point of a scene of {most}")
    values = np.zeros((n, MDEM_COLUMNS))
    masks = np.zeros(n, np.uint32)
    time = ctypes.c_double(0.0)
    if lib.fp_mdem_decode(buf.ctypes.data, len(raw), ctypes.addressof(time), values.ctypes.data,
                          masks.ctypes.data, n) != 0:
        raise ValueError("malformed time point")
    return time.value, values, masks


def mdem_encode(time: float, values: np.ndarray, masks: np.ndarray) -> bytes | None:
    """The ``ProtoTimePoint`` protobuf would serialize (see fp_mdem_encode); None without C."""
    lib = library()
    if lib is None or sys.byteorder != "little":
        return None
    values = np.ascontiguousarray(values, dtype=np.float64)
    masks = np.ascontiguousarray(masks, dtype=np.uint32)
    n = len(masks)
    cap = 16 + n * 512
    out = np.empty(cap, np.uint8)
    size = lib.fp_mdem_encode(float(time), values.ctypes.data, masks.ctypes.data, n,
                              out.ctypes.data, cap)
    if size < 0:
        raise ValueError("time point buffer too small")
    return out[:size].tobytes()


def mdem_blocks(raw: bytes, most: int) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The block descriptors (field 3) of a serialized ``ProtoSimulationStorage``, as protobuf
    reads them: (start times (k,), integers (4, k): offsets, sizes, uncompressed sizes, formats;
    byte spans (m, 2) of the descriptor records in ``raw``).  None without the C library or
    when the message holds anything unusual (see fp_mdem_blocks): then parse it with protobuf.
    OverflowError, before anything is allocated, if there are more than ``most``."""
    lib = library()
    if lib is None or sys.byteorder != "little":
        return None
    buf = np.frombuffer(raw, np.uint8)
    if not buf.size:
        buf = np.zeros(1, np.uint8)
    nspans = ctypes.c_int64(0)
    n = lib.fp_mdem_blocks(buf.ctypes.data, len(raw), None, None, 0, None, ctypes.addressof(nspans))
    if n < 0:
        return None
    if n > most:
        raise OverflowError(f"{n} block descriptors, more than {most}")
    start = np.zeros(max(n, 1))
    ints = np.zeros((4, max(n, 1)), np.int64)
    spans = np.zeros((max(nspans.value, 1), 2), np.int64)
    if n and lib.fp_mdem_blocks(buf.ctypes.data, len(raw), start.ctypes.data, ints.ctypes.data, n,
                                spans.ctypes.data, ctypes.addressof(nspans)) != n:
        return None
    return start[:n], ints[:, :n], spans[:nspans.value]


def mdem_put_blocks(start: np.ndarray, offset: np.ndarray, size: np.ndarray, raw: np.ndarray,
                    fmt: int) -> bytes | None:
    """Block descriptors (all of format ``fmt``) serialized as the field-3 records of a
    ``ProtoSimulationStorage``, as protobuf writes them; None without the C library."""
    lib = library()
    if lib is None or sys.byteorder != "little":
        return None
    start = np.ascontiguousarray(start, np.float64)
    offset, size, raw = (np.ascontiguousarray(a, np.int64) for a in (offset, size, raw))
    n = len(start)
    cap = 56 * n + 1
    out = np.empty(cap, np.uint8)
    written = lib.fp_mdem_put_blocks(start.ctypes.data, offset.ctypes.data, size.ctypes.data,
                                     raw.ctypes.data, int(fmt), n, out.ctypes.data, cap)
    if written < 0:
        raise ValueError("descriptor buffer too small")
    return out[:written].tobytes()
