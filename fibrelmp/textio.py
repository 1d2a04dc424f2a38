"""Small shared helpers for reading user text files with precise error locations."""

from __future__ import annotations

import errno
import math
import os
import stat
from pathlib import Path
from typing import Callable

import numpy as np

from fibrelmp.errors import InputError, RunError


# In-memory replacements of files, keyed by absolute path: ``collect_errors`` re-reads an
# input with its failing lines patched out without touching the user's files.  Empty (and
# so free) outside ``fibrelmp check``.
_OVERLAY: dict[str, str] = {}


def _overlay_key(path: str | os.PathLike) -> str:
    return os.path.realpath(path)


def patched_reading() -> bool:
    """Is ``collect_errors`` re-reading files with failing lines patched?  (Values derived
    from patched lines are placeholders: checks of them would report artifacts.)"""
    return bool(_OVERLAY)


def refuse_special_file(path: str | os.PathLike, what: str = "file") -> None:
    """An InputError unless ``path`` is a regular file or a folder (whose read says so):
    reading /dev/zero never ends, opening a FIFO blocks until someone writes to it.  The
    OSError of a path that cannot be examined propagates."""
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode) and not stat.S_ISDIR(mode):
        raise InputError(path, None, f"{what} is not a regular file (a device, FIFO or socket)")


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """Read a text file; every failure becomes an InputError naming the path.

    What went wrong comes from the read itself (not from checks made before it), so a
    directory is "is a directory", an unreadable file "cannot read" and only a path that
    does not exist "not found"."""
    p = Path(path)
    if _OVERLAY:
        patched = _OVERLAY.get(_overlay_key(p))
        if patched is not None:
            return patched
    try:
        refuse_special_file(p, what)
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(p, None, read_failure(exc, what)) from None
    except ValueError:                      # a NUL byte in the name: no such file
        raise InputError(p, None, f"{what} not found") from None
    except MemoryError:
        raise InputError(p, None, f"{what} does not fit in memory "
                         f"({p.stat().st_size / 1e9:.1f} GB)") from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        # about the whole file, so no line number
        raise InputError(p, None, f"{what} is UTF-16 encoded; save it as UTF-8 or ASCII text")
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    if b"\x00" in raw[:4096]:
        raise InputError(p, None, f"{what} looks binary (contains NUL bytes), expected text")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise InputError(p, line, f"{what} is not valid UTF-8 text (byte {exc.start})") from None


def read_failure(exc: OSError, what: str = "file") -> str:
    """The message for an OSError met opening or reading an input file."""
    if isinstance(exc, IsADirectoryError):
        return f"{what} is a directory, expected a file"
    if isinstance(exc, (FileNotFoundError, NotADirectoryError)):
        return f"{what} not found"
    return f"cannot read {what}: {exc.strerror or exc}"


def check_text_file(path: str | os.PathLike, what: str = "file") -> None:
    """The checks of ``read_text`` (regular file, UTF-8, not UTF-16, not binary) in 16 MB
    blocks, holding no decoded copy: for large files whose bytes are parsed directly."""
    import codecs

    p = Path(path)
    if _OVERLAY and _OVERLAY.get(_overlay_key(p)) is not None:
        return
    try:
        refuse_special_file(p, what)
        with open(p, "rb") as fh:
            decoder = codecs.getincrementaldecoder("utf-8")()
            first, offset, lines = True, 0, 1
            while True:
                block = fh.read(1 << 24)
                if first:
                    if block.startswith((b"\xff\xfe", b"\xfe\xff")):
                        raise InputError(p, None, f"{what} is UTF-16 encoded; save it as UTF-8 or ASCII text")
                    body = block[3:] if block.startswith(b"\xef\xbb\xbf") else block
                    if b"\x00" in body[:4096]:
                        raise InputError(p, None, f"{what} looks binary (contains NUL bytes), expected text")
                    first = False
                try:
                    decoder.decode(block, final=not block)
                except UnicodeDecodeError as exc:
                    line = lines + block[: max(exc.start, 0)].count(b"\n")
                    raise InputError(p, line, f"{what} is not valid UTF-8 text (byte "
                                     f"{offset + max(exc.start, 0)})") from None
                if not block:
                    return
                offset += len(block)
                lines += block.count(b"\n")
    except OSError as exc:
        raise InputError(p, None, read_failure(exc, what)) from None


def read_checked_bytes(path: str | os.PathLike, what: str = "file") -> bytes:
    """The bytes of a file after the checks of ``check_text_file`` (its overlay text while
    checking).  A pure-ASCII file (the usual case) is checked in memory, read once; any
    other goes through ``check_text_file``, which locates the problem."""
    p = Path(path)
    if _OVERLAY and _OVERLAY.get(_overlay_key(p)) is not None:
        return read_bytes(p)
    try:
        refuse_special_file(p, what)
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(p, None, read_failure(exc, what)) from None
    if not raw.isascii():                   # UTF-8, UTF-16 or binary: the detailed checks
        check_text_file(p, what)
    elif b"\x00" in raw[:4096]:
        raise InputError(p, None, f"{what} looks binary (contains NUL bytes), expected text")
    return raw


def read_bytes(path: str | os.PathLike) -> bytes:
    """The bytes of a file ``read_text`` has accepted (its overlay text while checking)."""
    if _OVERLAY:
        patched = _OVERLAY.get(_overlay_key(path))
        if patched is not None:
            return patched.encode("utf-8")
    return Path(path).read_bytes()


MAX_INTEGER = 2 ** 53           # integers read through floats stay exact up to here


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
        value = int(token)
    except ValueError:
        raise InputError(path, line, f"{name}: expected an integer, got {token!r}") from None
    if abs(value) > 2 ** 63 - 1:            # numpy and LAMMPS hold integers in 64 bits
        raise InputError(path, line, f"{name}: integer {token} is out of range (64 bits)")
    return value


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
    huge = np.abs(column) > MAX_INTEGER
    if huge.any():
        row = int(np.flatnonzero(huge)[0])
        raise InputError(path, line_numbers[row], f"{what} column {col + 1}: integer "
                         f"{table[row, col]} is out of range (at most 2^53 in magnitude)")
    return column.astype(np.int64)


# errors that mean the output path itself is wrong (exit 2, as bad input); any other
# failure while writing -- a full disk, a quota, an I/O error -- is the machine's (exit 1)
_PATH_ERRNOS = {errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOTDIR, errno.ENOENT,
                errno.EISDIR, errno.ENAMETOOLONG, errno.ELOOP}


def write_failure(path: str | os.PathLike, exc: OSError) -> InputError | RunError:
    """The error to raise when writing the output ``path`` failed with ``exc``: it names
    the output (not a temp file) and the reason, e.g. ``out.xyz: cannot write output: No
    space left on device``."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    if exc.errno in _PATH_ERRNOS:
        return InputError(path, None, f"cannot write output: {reason}")
    return RunError(f"{path}: cannot write output: {reason}")


def discard(tmp: str | os.PathLike, fh=None) -> None:
    """Close ``fh`` (its buffered data may fail to flush on a full disk: ignored) and remove
    the temp file ``tmp``; never raises."""
    if fh is not None:
        try:
            fh.close()
        except OSError:
            pass
    try:
        os.unlink(tmp)
    except OSError:
        pass


def temp_name(path: str | os.PathLike) -> Path:
    """The temp file beside ``path`` an atomic write goes through."""
    p = Path(path)
    return p.with_name(f".{p.name}.tmp{os.getpid()}")


def atomic_write(path: str | os.PathLike, data: str | bytes | list) -> None:
    """Write a file through a temp file + rename so no half-written output is left; ``data``
    may be a list of bytes-like parts (written in turn: no joined copy).

    On any failure the temp file is removed and the error names ``path`` (write_failure)."""
    p = Path(path)
    tmp = temp_name(p)
    parts = data if isinstance(data, list) else [data]
    mode = "w" if isinstance(data, str) else "wb"
    fh = None
    try:
        fh = open(tmp, mode)
        for part in parts:
            fh.write(part)
        fh.close()
        os.replace(tmp, p)
    except OSError as exc:
        discard(tmp, fh)
        raise write_failure(p, exc) from None
    except BaseException:
        discard(tmp, fh)
        raise


def format_rows(fmt_row: str, columns: list) -> str:
    """Format rows with one C-level % operation over all values (no per-row Python loop)."""
    n = len(columns[0])
    if n == 0:
        return ""
    flat = np.empty((n, len(columns)), dtype=object)
    for c, col in enumerate(columns):
        flat[:, c] = col.tolist() if isinstance(col, np.ndarray) else col
    return (fmt_row * n) % tuple(flat.ravel().tolist())


# --------------------------------------------------------------------------- fibrelmp check
# patch(error, text of its line or None for an error about the whole file, attempt) -> the
# replacement line (for a file error: a line to append to the file), or None to stop
Patch = Callable[[InputError, "str | None", int], "str | None"]
MAX_ERRORS = 50


def blank_patch(err: InputError, line: str | None, attempt: int) -> str | None:
    """Default: a failing line is blanked (every line format skips blank lines); give up
    when the blanked line still fails, and at errors about the whole file."""
    return "" if line is not None and attempt == 0 else None


def _lines_of(path: str) -> list[str] | None:
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None                   # a device or FIFO: never read it
        raw = Path(path).read_bytes()
    except (OSError, MemoryError):
        return None
    return raw.removeprefix(b"\xef\xbb\xbf").decode("utf-8", "replace").splitlines(keepends=True)


def collect_errors(read: Callable[[], object], first: InputError, patch: Patch = blank_patch,
                   limit: int = MAX_ERRORS) -> list[InputError]:
    """Every problem ``read`` meets, for ``fibrelmp check``.  After each error the failing line
    is replaced in memory by ``patch``'s text (or, for an error about the whole file such as a
    missing keyword, ``patch``'s line is appended) and ``read`` runs again, until it succeeds.

    Readers stay single-error, so the normal path is not slower; only ``check`` pays for the
    re-reads.  An error without a line that names the keyword of a patched line ('step') is a
    consequence of the patch and is not reported.  At most ``limit`` errors."""
    errors = [first]
    texts: dict[str, list[str]] = {}          # patched files, as lines with their endings
    attempts: dict[tuple[str, int], int] = {}
    appended: set[tuple[str, str]] = set()
    patched_words: set[str] = set()
    err = first
    try:
        while len(errors) < limit and err.path is not None:
            key = _overlay_key(err.path)
            if key not in texts:
                lines = _lines_of(err.path)
                if lines is None:
                    break
                texts[key] = lines
            lines = texts[key]
            if err.line is None:
                new = patch(err, None, 0)
                if new is None or (key, new) in appended:
                    break
                appended.add((key, new))
                if lines and not lines[-1].endswith(("\n", "\r")):
                    lines[-1] += "\n"
                lines.append(new + "\n")
            else:
                if not 1 <= err.line <= len(lines):
                    break
                attempt = attempts.get((key, err.line), 0)
                old = lines[err.line - 1]
                body = old.rstrip("\r\n")
                new = patch(err, body, attempt)
                if new is None:
                    break
                attempts[(key, err.line)] = attempt + 1
                if body.split():
                    patched_words.add(body.split()[0])
                lines[err.line - 1] = new + old[len(body):]
            _OVERLAY[key] = "".join(lines)
            try:
                read()
                break
            except InputError as exc:
                err = exc
            if err.path is not None and err.line is not None:
                if (_overlay_key(err.path), err.line) not in attempts:
                    errors.append(err)      # else: the patched line still fails, unsaid
            elif not any(f"'{w}'" in err.message for w in patched_words):
                errors.append(err)
    finally:
        _OVERLAY.clear()
    return errors
