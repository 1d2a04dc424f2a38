"""Streaming reader for LAMMPS text dumps (``dump custom`` / ``dump local`` / ``write_dump``).

A frame is the items from ``ITEM: UNITS`` / ``ITEM: TIME`` / ``ITEM: TIMESTEP`` to the end
of its ``ITEM: ATOMS`` (or ``ITEM: ENTRIES``) block; the block's length is the frame's own
``NUMBER OF ATOMS`` (so the atom count may change between frames).  Each block is parsed
by one C-level call (the optional C parser of ``fastparse``, else ``np.loadtxt``); memory holds one frame at a time, read in chunks, so
a 10 GB dump converts frame by frame.  ``.gz`` dumps are read through gzip.  No line may be
longer than ``MAX_LINE`` (1 MiB, plain or gzip): a hostile line (a few MB of gzip can expand
to gigabytes without a newline) is an error after at most that much, so memory stays within
one frame plus a read chunk plus ``MAX_LINE``.

Only the real end of the file truncates: a last frame cut there is dropped with a warning;
a gzip stream cut short (LAMMPS still writing) ends the file there too, with a warning.
Every other defect -- among them a ``NUMBER OF ATOMS`` that does not match the atom lines of
its frame, wherever the frame is -- is an InputError ``path:line: message`` naming the frame.
"""

from __future__ import annotations

import gzip
import io
import warnings as _warnings
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.numtext.fast import nth_newline, parse_numbers

# columns that may hold text (type labels with ``dump_modify types labels``, element names)
TEXT_COLUMNS = {"type", "element"}
CHUNK = 1 << 24
# the longest line accepted (header or atom line; a dump custom line of 1000 columns is
# about 25 kB): memory for a line without a newline stops here, not at the end of the file
MAX_LINE = 1 << 20


@dataclass
class Frame:
    step: int
    lo: np.ndarray              # (3,) box origin (for triclinic boxes: xlo ylo zlo, not the bounds)
    hi: np.ndarray              # (3,) lo + edge lengths
    boundary: tuple[str, ...]   # e.g. ("pp", "mm", "mm")
    columns: dict[str, np.ndarray]
    tilt: np.ndarray | None = None      # (xy, xz, yz) for triclinic boxes
    time: float | None = None           # ITEM: TIME (dump_modify time yes)
    line: int | None = None             # line of the frame's first ITEM in the file
    units: str | None = None            # ITEM: UNITS (dump_modify units yes)
    source: str | None = None           # file the frame came from (error messages)
    index: int | None = None            # frame index in the file, from 0 (as --frames counts)
    atom_line: int | None = None        # line of the first atom line (atom rows in file order)

    @property
    def count(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    @property
    def periodic(self) -> np.ndarray:
        return np.array([b == "pp" for b in self.boundary])

    @property
    def lengths(self) -> np.ndarray:
        return self.hi - self.lo

    @property
    def triclinic(self) -> bool:
        return self.tilt is not None

    def has(self, *names: str) -> bool:
        return all(n in self.columns for n in names)

    def column(self, name: str) -> np.ndarray:
        try:
            return self.columns[name]
        except KeyError:
            where = f" (frame at line {self.line})" if self.line else ""
            raise InputError(self.source, None, f"the dump has no column {name!r}{where}; "
                             f"columns: {' '.join(self.columns) or '(none)'}") from None

    def vector(self, *names: str) -> np.ndarray:
        """(n, k) float array of the named columns (a copy)."""
        return np.column_stack([np.asarray(self.column(c), np.float64) for c in names])

    def block(self, *names: str) -> np.ndarray:
        """(n, k) float array of the named columns: a read-only view of the parsed table when
        they are adjacent in it (no copy: the x y z of a 256k-atom frame cost 4 ms to
        gather), else a copy."""
        cols = [self.column(c) for c in names]
        base = cols[0].base
        if (isinstance(base, np.ndarray) and base.ndim == 2 and base.dtype == np.float64
                and base.flags.c_contiguous and all(c.base is base and c.dtype == np.float64
                                                    and c.strides == (base.strides[0],) for c in cols)):
            first = (cols[0].ctypes.data - base.ctypes.data) // base.itemsize
            if all(c.ctypes.data == cols[0].ctypes.data + k * base.itemsize for k, c in enumerate(cols)) \
                    and first + len(cols) <= base.shape[1]:
                view = base[:, first:first + len(cols)]
                view.flags.writeable = False
                return view
        return np.column_stack([np.asarray(c, np.float64) for c in cols])

    # -- coordinates -------------------------------------------------------------------
    @property
    def cell(self) -> np.ndarray:
        """Edge vectors as columns: x = lo + cell @ s for scaled coordinates s."""
        lx, ly, lz = self.lengths
        xy, xz, yz = self.tilt if self.tilt is not None else (0.0, 0.0, 0.0)
        return np.array([[lx, xy, xz], [0.0, ly, yz], [0.0, 0.0, lz]])

    def _cartesian(self, names: tuple[str, str, str]) -> np.ndarray:
        s = self.vector(*names)
        with np.errstate(all="ignore"):     # inf in a dump: reported where it matters, no warning
            return self.lo + s @ self.cell.T

    def positions(self) -> np.ndarray | None:
        """Positions as dumped (``x y z``, else scaled ``xs ys zs``), or None."""
        if self.has("x", "y", "z"):
            return self.vector("x", "y", "z")
        if self.has("xs", "ys", "zs"):
            return self._cartesian(("xs", "ys", "zs"))
        return None

    def unwrapped(self) -> np.ndarray | None:
        """Unwrapped positions when derivable (xu/xsu, or x/xs plus image flags)."""
        if self.has("xu", "yu", "zu"):
            return self.vector("xu", "yu", "zu")
        if self.has("xsu", "ysu", "zsu"):
            return self._cartesian(("xsu", "ysu", "zsu"))
        x = self.positions()
        if x is not None and self.has("ix", "iy", "iz"):
            with np.errstate(all="ignore"):
                return x + self.vector("ix", "iy", "iz") @ self.cell.T
        return None

    def wrapped(self) -> np.ndarray:
        """Positions inside the box on periodic axes (x y z as dumped are already so)."""
        x = self.positions()
        if x is not None:
            return x
        xu = self.unwrapped()
        if xu is None:
            raise InputError(self.source, self.line, "the dump has no positions: needs x y z, xs ys zs, "
                             f"xu yu zu or xsu ysu zsu; columns: {' '.join(self.columns)}")
        per = self.periodic
        with np.errstate(all="ignore"):     # the header check keeps the cell invertible
            s = np.linalg.solve(self.cell, (xu - self.lo).T).T
            s[:, per] -= np.floor(s[:, per])
            return self.lo + s @ self.cell.T

    def select(self, rows: np.ndarray | slice) -> "Frame":
        """A frame with only the given atom rows (a mask, index array or slice)."""
        cols = {k: v[rows] for k, v in self.columns.items()}
        return Frame(self.step, self.lo, self.hi, self.boundary, cols, self.tilt, self.time,
                     self.line, self.units, self.source, self.index)


@dataclass
class Header:
    """What a frame's ITEM lines say, before its atom block is parsed."""

    step: int
    count: int
    lo: np.ndarray
    hi: np.ndarray
    boundary: tuple[str, ...]
    names: list[str]
    line: int
    time: float | None = None
    units: str | None = None
    tilt: np.ndarray | None = None
    kind: str = "ATOMS"          # "ATOMS" or "ENTRIES" (dump local)
    extra: dict = field(default_factory=dict)


def _open(path: Path):
    with open(path, "rb") as fh:
        magic = fh.read(2)
    if magic == b"\x1f\x8b":
        return gzip.open(path, "rb")
    return open(path, "rb")


class _Stream:
    """Line and block access over a file read in large chunks (no per-line objects)."""

    def __init__(self, fh, path: Path, warnings: list | None = None):
        self.fh = fh
        self.path = path
        self.warnings = warnings
        self.buf = bytearray()
        self.pos = 0
        self.line = 0              # lines consumed so far
        self.line_bytes = 100.0    # mean atom-line length of the last block
        # read1: a gzip stream cut short raises EOFError on the read after the last data,
        # whereas read(CHUNK) would drop everything it had decompressed in that call
        self.gzip = isinstance(fh, gzip.GzipFile)
        self.cut_warned = False

    def _more(self) -> bool:
        # no latch on EOF: a dump LAMMPS is still writing may grow (fibrelmp run)
        try:
            data = self.fh.read1(CHUNK) if self.gzip else self.fh.read(CHUNK)
        except EOFError:
            # a gzip stream without its end (LAMMPS still writing, a copy cut short): the end
            # of the file, as for a plain dump; the frame it cuts is dropped by the caller
            if not self.cut_warned and self.warnings is not None:
                self.cut_warned = True
                self.warnings.append(("truncated dump", f"{self.path}: the gzip stream ends "
                                      "early (cut short, or LAMMPS still writing it); the "
                                      "frames before the cut are kept"))
            return False
        except (OSError, zlib.error) as exc:     # gzip.BadGzipFile (a CRC error) is an OSError
            raise InputError(self.path, self.line + 1,
                             f"cannot read the dump: {exc}") from None
        if not data:
            return False
        self.buf += data
        return True

    def _too_long(self, line: int) -> InputError:
        return InputError(self.path, line, f"line longer than {MAX_LINE >> 20} MiB, the longest a "
                          "dump line may be (docs/post.md; not a LAMMPS text dump?)")

    def _compact(self) -> None:
        # drop consumed bytes (only between lines, so no caller holds an offset)
        if self.pos > CHUNK:
            del self.buf[:self.pos]
            self.pos = 0

    def readline(self) -> bytes | None:
        """Next line without its newline; None at the end of the file."""
        self._compact()
        scan = self.pos
        while True:
            k = self.buf.find(b"\n", scan)
            if (k if k >= 0 else len(self.buf)) - self.pos > MAX_LINE:
                raise self._too_long(self.line + 1)
            if k < 0:
                scan = len(self.buf)
            if k >= 0:
                out = bytes(self.buf[self.pos:k])
                self.pos = k + 1
                self.line += 1
                return out
            if not self._more():
                if self.pos < len(self.buf):
                    out = bytes(self.buf[self.pos:])
                    self.pos = len(self.buf)
                    self.line += 1
                    return out
                return None

    def lines(self, n: int) -> tuple[bytes, int]:
        """The next ``n`` lines as one bytes object, and how many there were (< n at EOF)."""
        if n <= 0:
            return b"", 0
        self._compact()
        start = scan = line_start = self.pos
        need = n
        while True:
            end = len(self.buf)
            # search a window sized from the line length seen so far, not the whole buffer
            # (many small frames would otherwise rescan a 16 MB buffer each)
            stop = min(end, scan + max(1 << 16, int(need * self.line_bytes * 1.25)))
            fast = nth_newline(self.buf, scan, stop, need)     # optional C search
            if fast is not None:
                c, rel = fast
            elif stop > scan:
                view = np.frombuffer(self.buf, np.uint8, count=stop - scan, offset=scan)
                nl = np.flatnonzero(view == 10)
                del view                  # release the export before the buffer grows
                c = len(nl)
                rel = int(nl[need - 1]) if c >= need else -1
            else:
                c, rel = 0, -1
            if c >= need:
                k = scan + rel
                with memoryview(self.buf) as mv:    # one copy (a bytearray slice would be two)
                    out = bytes(mv[start:k + 1])
                self.pos = k + 1
                self.line += n
                self.line_bytes = max(1.0, len(out) / n)
                return out, n
            if c:
                line_start = self.buf.rfind(b"\n", scan, stop) + 1
            need -= c
            scan = stop
            if stop - line_start > MAX_LINE:
                raise self._too_long(self.line + n - need + 1)
            if stop < end:
                continue
            if not self._more():
                out = bytes(self.buf[start:])
                self.pos = len(self.buf)
                got = n - need + (1 if out and not out.endswith(b"\n") else 0)
                self.line += got
                return out, got


def _decode(raw: bytes) -> str:
    return raw.decode("utf-8", "replace").strip()


def _frame_name(index: int, head: Header) -> str:
    """How messages name a frame: its index (from 0, as ``--frames`` counts), step and first
    line."""
    return f"frame {index}: step {head.step}, from line {head.line}"


def _miscount(rows: int, head: Header) -> str:
    """The message for an 'ITEM:' line met after ``rows`` atom lines of the frame ``head``."""
    frame = (_frame_name(head.extra["index"], head) if "index" in head.extra
             else f"step {head.step}, from line {head.line}")
    return f"frame has {rows} atom lines but NUMBER OF {head.kind} says {head.count} ({frame})"


def _item_row(block: bytes) -> int | None:
    """Row (from 0) of the first line of ``block`` that starts with 'ITEM:', or None."""
    if block.startswith(b"ITEM:"):
        return 0
    k = block.find(b"\nITEM:")
    return None if k < 0 else block.count(b"\n", 0, k + 1)


def _not_an_item(text: str, is_first: bool, prev: tuple[int, Header] | None) -> str:
    """Why a line where an ITEM line belongs is wrong (the frame's first line, or a later one)."""
    if not is_first:
        return f"expected an 'ITEM:' line, got {text[:60]!r}"
    if prev is None:
        return f"not a LAMMPS text dump: expected 'ITEM: TIMESTEP', got {text[:60]!r}"
    i, ph = prev
    return (f"expected 'ITEM: TIMESTEP' starting the next frame, got {text[:60]!r} "
            f"(more atom lines than NUMBER OF {ph.kind} {ph.count} of "
            f"{_frame_name(i, ph)}?)")


def _box_bounds(path: Path, st: _Stream, item: str, values: list[str]
                ) -> tuple[tuple[np.ndarray, np.ndarray, tuple[str, ...]], np.ndarray | None]:
    """((lo, hi, boundary flags), tilt or None) of an ITEM: BOX BOUNDS and its three lines;
    a ValueError for numbers that are not finite (the caller names the item)."""
    words = item.split()[2:]
    tilt = None
    if "abc" in words or "origin" in words:
        raise InputError(path, st.line - 3, "general triclinic boxes (BOX BOUNDS abc origin) "
                         "are not supported; dump with dump_modify triclinic/general no")
    nums = np.array([v.split()[:3] for v in values], dtype=float) if "xy" in words else \
        np.array([v.split()[:2] for v in values], dtype=float)
    if not np.isfinite(nums).all():
        raise ValueError
    bnd = tuple(w for w in words if w not in ("xy", "xz", "yz"))[-3:]
    if len(bnd) != 3:
        bnd = ("pp", "pp", "pp")
    if "xy" in words:
        xy, xz, yz = nums[:, 2]
        tilt = np.array([xy, xz, yz])
        # the dump holds the bounding box; the box itself is inside it
        lo = nums[:, 0] - np.array([min(0.0, xy, xz, xy + xz), min(0.0, yz), 0.0])
        hi = nums[:, 1] - np.array([max(0.0, xy, xz, xy + xz), max(0.0, yz), 0.0])
    else:
        lo, hi = nums[:, 0].copy(), nums[:, 1].copy()
    if not (hi > lo).all():
        raise InputError(path, st.line - 2, f"ITEM: {item}: the box has no volume "
                         f"(lo {' '.join(map(str, lo))}, hi {' '.join(map(str, hi))})")
    return (lo, hi, bnd), tilt


def _read_header(st: _Stream, path: Path, first: bytes, warnings: list | None,
                 prev: tuple[int, Header] | None = None) -> Header | None:
    """Parse the ITEM lines of one frame, ``first`` being its first (already read) line;
    ``prev`` is (index, header) of the frame before it."""
    start = st.line
    step = count = None
    time = units = tilt = None
    box = None
    line = first
    seen: set[str] = set()
    while True:
        text = _decode(line)
        if not text.startswith("ITEM:"):
            raise InputError(path, st.line, _not_an_item(text, line is first, prev))
        item = text[5:].strip()
        # an item twice in one header: a frame cut before its atom block (else the next
        # frame's items would silently replace this one's)
        key = "NUMBER OF" if item.startswith("NUMBER OF") else (item.split() or [""])[0]
        if key in seen:
            raise InputError(path, st.line, f"ITEM: {key} again before an ITEM: ATOMS (or ENTRIES) "
                             f"block: the frame starting at line {start} has none")
        seen.add(key)
        if item.startswith(("ATOMS", "ENTRIES")):
            kind = "ATOMS" if item.startswith("ATOMS") else "ENTRIES"
            missing = [w for w, v in (("TIMESTEP", step), ("NUMBER OF " + kind, count)) if v is None]
            if missing:
                raise InputError(path, st.line, f"frame has no ITEM: {missing[0]} before ITEM: {kind}")
            names = item.split()[1:]
            if len(set(names)) != len(names):
                raise InputError(path, st.line, f"repeated column name in ITEM: {kind}")
            lo, hi, bnd = box or (np.zeros(3), np.zeros(3), ("pp", "pp", "pp"))
            return Header(step, count, lo, hi, bnd, names, start, time, units, tilt, kind)
        values = []
        nvalues = 3 if item.startswith("BOX BOUNDS") else 1
        for _ in range(nvalues):
            raw = st.readline()
            if raw is None:
                if warnings is not None:
                    warnings.append(("truncated dump", f"{path}:{start}: last frame is incomplete "
                                     f"(ends inside ITEM: {item}); ignored"))
                return None
            values.append(_decode(raw))
        try:
            if item == "TIMESTEP":
                step = int(values[0])
            elif item == "TIME":
                time = float(values[0])
                if not np.isfinite(time):
                    raise ValueError
            elif item == "UNITS":
                units = values[0]
            elif item.startswith("NUMBER OF"):
                count = int(values[0])
                if count < 0:
                    raise ValueError
            elif item.startswith("BOX BOUNDS"):
                box, box_tilt = _box_bounds(path, st, item, values)
                tilt = box_tilt if box_tilt is not None else tilt
            else:
                raise InputError(path, st.line - nvalues, f"unknown dump item 'ITEM: {item}'")
        except (ValueError, IndexError):
            raise InputError(path, st.line - nvalues + 1,
                             f"ITEM: {item}: malformed value {' / '.join(values)[:80]!r}") from None
        line = st.readline()
        if line is None:
            if warnings is not None:
                warnings.append(("truncated dump", f"{path}:{start}: last frame is incomplete "
                                 "(no ITEM: ATOMS block); ignored"))
            return None


def parse_block(block: bytes, head: Header, path: Path | str | None) -> dict[str, np.ndarray]:
    """Columns of an atom block: one C-level parse; a slow path finds and names any defect."""
    names, n = head.names, head.count
    if n == 0:
        return {c: np.zeros(0) for c in names}
    data = parse_numbers(block, n, len(names))      # optional C parser; None: numpy path
    if data is not None:
        return {c: data[:, k] for k, c in enumerate(names)}
    try:
        with _warnings.catch_warnings():
            _warnings.simplefilter("ignore")
            data = np.loadtxt(io.BytesIO(block), dtype=np.float64, comments=None, ndmin=2)
        if data.shape == (n, len(names)):
            return {c: data[:, k] for k, c in enumerate(names)}
    except ValueError:
        pass
    return _parse_slow(block, head, path)


def _parse_slow(block: bytes, head: Header, path) -> dict[str, np.ndarray]:
    first = head.line + (head.extra.get("header_lines") or 0)
    rows = block.decode("utf-8", "replace").split("\n")[:head.count]
    ncol = len(head.names)
    for k, row in enumerate(rows):
        if row.startswith("ITEM:"):
            raise InputError(path, first + k, _miscount(k, head))
        got = len(row.split())
        if got != ncol:
            raise InputError(path, first + k, f"atom line has {got} values; ITEM: {head.kind} "
                             f"names {ncol} columns ({' '.join(head.names)})")
    table = np.array(" ".join(rows).split(), dtype=object).reshape(len(rows), ncol)
    cols: dict[str, np.ndarray] = {}
    for c, name in enumerate(head.names):
        try:
            cols[name] = table[:, c].astype(np.float64)
        except ValueError:
            if name in TEXT_COLUMNS:
                cols[name] = table[:, c].astype(str)
                continue
            for k, tok in enumerate(table[:, c]):
                try:
                    float(tok)
                except ValueError:
                    raise InputError(path, first + k, f"column {name!r}: expected a number, "
                                     f"got {tok[:40]!r}") from None
    return cols


Selector = Callable[[int, "Header"], bool]


def iter_headers(path: str | Path, warnings: list[tuple[str, str]] | None = None,
                 want: Selector | None = None,
                 parsed: bool = False) -> Iterator[tuple[Header, bytes | None]]:
    """Yield (header, atom block bytes or None if ``want(index, header)`` is False).

    ``parsed``: the caller parses every block it gets (``frame_from``), which reports an
    'ITEM:' line among the atom lines itself; the blocks are then not scanned for one here.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(path, None, "dump file not found")
    if path.is_dir():
        raise InputError(path, None, "is a directory, expected a LAMMPS dump file")
    try:
        fh = _open(path)
    except OSError as exc:
        raise InputError(path, None, f"cannot read the dump: {exc.strerror or exc}") from None
    with fh:
        st = _Stream(fh, path, warnings)
        index = 0
        seen_any = False
        prev = None
        while True:
            line = st.readline()
            if line is None:
                if not seen_any:
                    raise InputError(path, None, "empty dump file (no frames)")
                return
            if b"\0" in line:
                raise InputError(path, st.line, "binary data where a LAMMPS text dump line was "
                                 "expected (binary dumps are not supported)")
            if not line.strip():
                continue
            head = _read_header(st, path, line, warnings, prev)
            if head is None:
                return
            seen_any = True
            head.extra["header_lines"] = st.line - head.line + 1
            head.extra["index"] = index
            block, got = st.lines(head.count)
            wanted = want is None or want(index, head)
            if not (parsed and wanted) or got < head.count or not block.endswith(b"\n"):
                # The next frame beginning inside this one's atom block is a wrong NUMBER OF
                # ATOMS, not a truncated file (only the end of the file truncates).  A block
                # that is parsed finds this itself (_parse_slow): no second scan for it.
                row = _item_row(block)
                if row is not None:
                    raise InputError(path, head.line + head.extra["header_lines"] + row,
                                     _miscount(row, head))
            if got < head.count:
                if warnings is not None:
                    warnings.append(("truncated dump", f"{path}:{head.line}: last frame has {got} "
                                     f"of {head.count} atom lines; ignored"))
                return
            if not block.endswith(b"\n") and head.count:
                # at the end of the file without a newline: a cut last line is truncation
                tail = block[block.rfind(b"\n") + 1:]
                if len(tail.split()) != len(head.names):
                    if warnings is not None:
                        warnings.append(("truncated dump", f"{path}:{head.line}: last frame ends "
                                         "inside an atom line; ignored"))
                    return
            yield head, (block if wanted else None)
            prev = (index, head)
            index += 1


def frame_from(head: Header, block: bytes, path: Path | str | None) -> Frame:
    cols = parse_block(block, head, path)
    return Frame(head.step, head.lo, head.hi, head.boundary, cols, head.tilt, head.time,
                 head.line, head.units, None if path is None else str(path), head.extra.get("index"),
                 head.line + head.extra["header_lines"] if "header_lines" in head.extra else None)


def iter_frames(path: str | Path, warnings: list[tuple[str, str]] | None = None,
                want: Selector | None = None) -> Iterator[Frame]:
    """Yield frames of a text dump; a truncated last frame is dropped with a warning.

    ``want(index, header)`` (optional) skips frames without parsing their atom blocks.
    """
    for head, block in iter_headers(path, warnings, want, parsed=True):
        if block is not None:
            yield frame_from(head, block, path)

