"""The abstract Reader and Writer every format derives from (see docs/architecture.md).

What all formats share is implemented here once:

* ``Reader``: the file it reads is checked first (exists, a regular file: a FIFO or
  /dev/zero would block or never end), and every error it raises is ``path:line: message``
  through ``Reader.error`` (one exception type, ``InputError``).
* ``Writer``: streaming ``add(frame)`` ... ``close()`` (or ``abort()``); every file goes to a
  temp name beside its final name and is renamed into place only by ``close``, so a failure
  at any point leaves no half-written output and earlier outputs untouched; existing outputs
  are replaced only with ``force``; an ``OSError`` (a full disk...) becomes an error naming
  the output, never the temp file.  ``with Writer(...) as w:`` closes on success and aborts
  on an exception.

A derived reader implements ``read`` (whole-file formats) or ``__iter__`` (frame formats);
a derived writer implements ``write(frame)`` and, if it writes at the end, ``finish``; it
writes through ``open``/``put`` (files written frame by frame) or ``write_file`` (a file per
frame), and may ``adopt`` other writers whose files belong to the same output.
(Modelled on MDAnalysis's ReaderBase/WriterBase and meshio's one reader/writer per format.)
"""

from __future__ import annotations

import os
import threading
from abc import ABC, abstractmethod
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any, ClassVar, Iterable, Iterator

from .errors import InputError
from .textio import discard, temp_name, write_failure


class Replacement:
    """Files renamed into place, each earlier file of the same name kept aside (a hidden
    ``.<name>.tmp<pid>.old`` beside it) until ``keep``; ``undo`` removes the new files and
    puts the earlier ones back.  So a set of outputs is replaced completely or not at all:
    a writer's own files (``Writer.close``), or every output of a run (``replacing``)."""

    def __init__(self) -> None:
        self._placed: dict[Path, Path | None] = {}      # final -> the earlier file, kept aside

    def place(self, tmp: Path, final: Path) -> None:
        """Rename ``tmp`` to ``final`` (an OSError leaves ``final`` as it was)."""
        final = Path(final)
        if _same_file(tmp, final):       # already in place (a FibreNet job writing its results there)
            return
        first = final not in self._placed
        backup = None
        if first and os.path.lexists(final) and not os.path.isdir(final):
            backup = final.with_name(f".{final.name}.tmp{os.getpid()}.old")
            os.replace(final, backup)
        try:
            os.replace(tmp, final)
        except OSError:
            if backup is not None:
                os.replace(backup, final)
            raise
        if first:
            self._placed[final] = backup

    def undo(self) -> None:
        """Remove the files placed, put the earlier ones back; never raises."""
        for final, backup in reversed(list(self._placed.items())):
            try:
                if backup is not None:
                    os.replace(backup, final)
                else:
                    os.unlink(final)
            except OSError:
                pass
        self._placed.clear()

    def keep(self) -> None:
        """The new files stay: drop the earlier ones."""
        for backup in self._placed.values():
            if backup is not None:
                try:
                    os.unlink(backup)
                except OSError:
                    pass
        self._placed.clear()


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


# the replacements of the runs under way, by the folders they write (a run locks its
# folders, so each folder belongs to one run at a time; runs may be in other threads)
_replacing: dict[Path, Replacement] = {}
_replacing_lock = threading.Lock()


@contextmanager
def replacing(folders: Iterable[Path]) -> Iterator[Replacement]:
    """Every file a ``Writer`` renames into ``folders`` meanwhile is placed through one
    ``Replacement``: kept when the block succeeds, undone (the earlier outputs back, the new
    ones removed) when it raises."""
    journal = Replacement()
    keys = {Path(f).resolve() for f in folders}
    with _replacing_lock:
        taken = keys & _replacing.keys()
        if taken:
            raise RuntimeError(f"{sorted(taken)[0]}: already written by another run")
        for key in keys:
            _replacing[key] = journal
    try:
        yield journal
    except BaseException:
        journal.undo()
        raise
    else:
        journal.keep()
    finally:
        with _replacing_lock:
            for key in keys:
                _replacing.pop(key, None)


def replacement_for(final: Path) -> Replacement | None:
    """The run replacement that ``final``'s folder belongs to, if any."""
    with _replacing_lock:
        if not _replacing:
            return None
        return _replacing.get(Path(final).parent.resolve())


def place(tmp: Path, final: Path) -> None:
    """Rename ``tmp`` to ``final``: through the run's replacement when a run writes there
    (undone if the run fails later), else at once."""
    journal = replacement_for(final)
    if journal is not None:
        journal.place(tmp, final)
    else:
        os.replace(tmp, final)


class Reader(ABC):
    """Reads one file of one format."""

    format: ClassVar[str] = ""           # the registry name (fibrelmp.registry)
    what: ClassVar[str] = "input"        # how messages call the file

    def __init__(self, path: str | os.PathLike):
        from .registry import check_regular_file

        self.path = Path(path)
        check_regular_file(self.path, self.what)

    def error(self, line: int | None, message: str) -> InputError:
        """The error to raise for a problem at ``line`` (1-based, or None) of this file."""
        return InputError(self.path, line, message)

    def read(self) -> Any:
        """The whole file as the format's neutral object (model, table...)."""
        raise NotImplementedError(f"{type(self).__name__} reads frames: iterate over it")

    def __iter__(self) -> Iterator[Any]:
        """Frames, one at a time (memory does not grow with their number)."""
        raise NotImplementedError(f"{type(self).__name__} is not a frame format: call read()")


class DocumentFormat(ABC):
    """The ``document`` hook of a format: whole scene/result files ``fibrelmp convert``
    reads (``open``: a document object the other forms' writers take) and writes
    (``writer``: a ``Writer`` whose one ``add`` is the document)."""

    suffixes: ClassVar[tuple[str, ...]] = ()       # output names that mean this format
    takes_precision: ClassVar[bool] = False        # written as text with chosen digits

    @staticmethod
    @abstractmethod
    def open(path: Path) -> Any:
        """The document in ``path`` (has ``close()``)."""

    @staticmethod
    @abstractmethod
    def writer(target: Path, precision: int | None = None, *, force: bool = False) -> "Writer":
        """The writer of a document at ``target``."""


class Writer(ABC):
    """Writes one output (one or several files) from a stream of frames."""

    format: ClassVar[str] = ""
    # after a successful close, remove files of an earlier output that this one did not
    # write again (a conversion with fewer frames leaves no old frame files behind); run
    # results leave this to fibrelmp.outputs, which knows every writer of the run
    replaces_earlier: ClassVar[bool] = False

    def __init__(self, target: str | os.PathLike, *, force: bool = True):
        """``target``: the output's path (or base name, for multi-file formats).  Without
        ``force`` an existing output (any file ``outputs()`` names) is an error, raised here,
        before anything is written."""
        self.target = Path(target)
        self.count = 0                      # frames added
        self.closed = False
        self._staged: dict[Path, Path] = {}        # final path -> temp path
        self._handles: dict[Path, IO] = {}         # final path -> open temp file
        self._parts: list[Writer] = []             # writers whose files belong to this output
        self._settled = False                      # prepare() wrote everything already
        existing = [p for p in self.outputs() if p.exists()]
        if existing and not force:
            raise InputError(existing[0], None, "output exists; use --force to overwrite")
        self._earlier = [p for p in existing if p.is_file()] if self.replaces_earlier else []

    # -- what derived writers implement ------------------------------------------------
    def outputs(self) -> list[Path]:
        """The files this output consists of (what ``force`` protects); default the target."""
        return [self.target]

    @abstractmethod
    def write(self, frame: Any) -> None:
        """Write (or stage) one frame."""

    def finish(self) -> None:
        """Write what comes at the end (an index file, a header that needs every frame...)."""

    def discard(self) -> None:
        """Drop the writer's own scratch data (spools...) on abort and after close."""

    # -- shared machinery ---------------------------------------------------------------
    def stage(self, final: str | os.PathLike) -> Path:
        """The temp path a file is written to until ``close`` renames it to ``final``."""
        final = Path(final)
        if final not in self._staged:
            self._staged[final] = temp_name(final)
        return self._staged[final]

    def open(self, final: str | os.PathLike, mode: str = "wb", **kwargs) -> IO:
        """An open temp file for ``final`` (kept open until close/abort; opened once)."""
        final = Path(final)
        fh = self._handles.get(final)
        if fh is None:
            try:
                fh = open(self.stage(final), mode, **kwargs)
            except OSError as exc:
                self.abort()
                raise write_failure(final, exc) from None
            self._handles[final] = fh
        return fh

    def put(self, final: str | os.PathLike, *chunks: bytes) -> None:
        """Append ``chunks`` to the staged ``final`` (a failure names ``final``)."""
        fh = self.open(final)
        try:
            for chunk in chunks:
                fh.write(chunk)
        except OSError as exc:
            exc.output = Path(final)
            raise

    def write_file(self, final: str | os.PathLike, data: bytes) -> None:
        """Stage the whole file ``final`` now, closed at once (formats with a file per
        frame: no open file per frame until ``close``); a failure names ``final``."""
        tmp = self.stage(final)
        try:
            with open(tmp, "wb") as fh:
                fh.write(data)
        except OSError as exc:
            exc.output = Path(final)
            raise

    def adopt(self, part: "Writer") -> "Writer":
        """A writer whose files belong to this output: its files are renamed into place with
        this writer's (after every file of both was written), and aborted with it."""
        self._parts.append(part)
        return part

    @contextmanager
    def _aborting(self) -> Iterator[None]:
        """Abort on any failure; an OSError becomes an error naming the output (the file it
        names, else the target: ``finish`` names no file)."""
        try:
            yield
        except OSError as exc:
            self.abort()
            raise write_failure(getattr(exc, "output", None) or self.target, exc) from None
        except BaseException:
            self.abort()
            raise

    def add(self, frame: Any) -> None:
        if self.closed:
            raise ValueError(f"{type(self).__name__} for {self.target} is closed")
        with self._aborting():
            self.write(frame)
        self.count += 1

    def prepare(self) -> None:
        """Write everything still to come (``finish``) and close the temp files, renaming
        nothing yet: ``close`` then only renames.  A run prepares all its writers before
        closing any, so that a failure in one leaves no output of the others in place."""
        if self.closed or self._settled:
            return
        with self._aborting():
            self._settle()
        self._settled = True

    def close(self) -> list[Path]:
        """Finish, then rename every staged file into place; returns the final paths."""
        if self.closed:
            return []
        with self._aborting():
            if not self._settled:
                self._settle()
            done = self._commit()
        self._closed()
        for old in self._earlier:          # only now: a failed close keeps the earlier output
            if old not in done:
                try:
                    old.unlink(missing_ok=True)
                except OSError as exc:
                    raise InputError(old, None, f"cannot remove old output: {exc.strerror or exc}") from None
        return done

    def _settle(self) -> None:
        """Write everything (finish) and close the temp files, parts first."""
        self.finish()
        for part in self._parts:
            part._settle()
        for final, fh in list(self._handles.items()):
            try:
                fh.close()
            except OSError as exc:
                raise write_failure(final, exc) from None
            del self._handles[final]

    def _pending(self) -> list[tuple[Path, Path]]:
        """(final, temp) of every staged file, the parts' first."""
        pairs = [pair for part in self._parts for pair in part._pending()]
        return pairs + list(self._staged.items())

    def _forget_staged(self) -> None:
        for part in self._parts:
            part._forget_staged()
        self._staged.clear()

    def _commit(self) -> list[Path]:
        """Rename every staged file into place, all or none: a failing rename puts back
        the files this writer had replaced already (inside a run, the run's replacement
        does that when the run fails: ``replacing``)."""
        own = Replacement()
        done = []
        for final, tmp in self._pending():
            try:
                (replacement_for(final) or own).place(tmp, final)
            except OSError as exc:
                own.undo()
                raise write_failure(final, exc) from None
            done.append(final)
        own.keep()
        self._forget_staged()
        return done

    def _closed(self) -> None:
        for part in self._parts:
            part._closed()
        self.closed = True
        self.discard()

    def abort(self) -> None:
        """Remove everything not yet in place; never raises."""
        for part in self._parts:
            part.abort()
        for final, tmp in list(self._staged.items()):
            discard(tmp, self._handles.pop(final, None))
        self._staged.clear()
        self._handles.clear()
        self.closed = True
        try:
            self.discard()
        except OSError:
            pass

    def __enter__(self) -> "Writer":
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if kind is None:
            self.close()
        else:
            self.abort()
