"""What every ``fibrelmp post --to`` target shares: ``DumpTarget``, a ``Writer`` of completed
LAMMPS dump frames, and the ``PostContext`` it gets from the command line.

A target is one class (registered with ``registry.register_format(..., {TARGET: ...})``):
``files(base)`` names what a conversion to ``base`` writes, ``write_frame`` writes one frame
(``start`` first sees the first ``lookahead`` frames, e.g. to find the time step), ``end``
writes what comes last, and ``read_back(files)`` reads the output back (the conformance
tests, tests/conformance/).  Class attributes tell the conversion (post/convert.py)
what it needs: ``units`` (for the unit-mismatch warning), ``last_frame_by_default``,
``uses_local``.  Files are staged and renamed into place by ``close`` (formatbase.Writer).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Iterator, Mapping

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.post.lammps_dump.reader import Frame


class TypeNames(Mapping):
    """Type number -> name, looked up in live tables (labels met later in the stream are
    added to them), first table first; ``names[t]`` of a type without a name is its number,
    ``names.get(t, default)`` the default."""

    def __init__(self, *live: dict[int, str]):
        self.live = live

    def _find(self, key: int) -> str | None:
        for table in self.live:
            if key in table:
                return table[key]
        return None

    def __getitem__(self, key: int) -> str:
        name = self._find(key)
        return str(key) if name is None else name

    def get(self, key: int, default: Any = None) -> Any:
        name = self._find(key)
        return default if name is None else name

    def __contains__(self, key: object) -> bool:
        return any(key in table for table in self.live)

    def __iter__(self) -> Iterator[int]:
        return iter(dict.fromkeys(k for table in self.live for k in table))

    def __len__(self) -> int:
        return sum(1 for _ in self)


@dataclass
class PostContext:
    """What a target may use besides the frames (from ``fibrelmp post``'s options)."""

    source: Path                                   # the trajectory (for messages)
    datafile: Any = None                           # --data (lammps_data.reader.DataFile)
    type_names: Mapping[int, str] = field(default_factory=TypeNames)
    local: Path | None = None                      # --local contact dump
    gravity: tuple[float, float, float] | None = None
    warnings: list[tuple[str, str]] = field(default_factory=list)
    precision: int | None = None                   # --precision (targets that take it)
    target_name: str | None = None                 # the --to name (messages)

    @property
    def facts(self):
        """The job facts of a fibrelmp work folder's data file (``translate.work_facts``), or None."""
        return getattr(self.datafile, "facts", None)

    def warn(self, kind: str, text: str) -> None:
        """One warning per kind."""
        if kind not in {k for k, _ in self.warnings}:
            self.warnings.append((kind, text))


@dataclass
class ReadBack:
    """One frame of a target's output as read back (conformance tests): positions in dump
    atom-id order, to within ``rtol``/``atol`` (the format's printed precision); ``values``
    other per-atom vectors it keeps (dump column names -> (n, k)), to within ``value_tol``
    ((rtol, atol); None: the positions')."""

    positions: np.ndarray
    rtol: float = 0.0
    atol: float = 0.0
    values: dict[tuple[str, ...], np.ndarray] = field(default_factory=dict)
    value_tol: tuple[float, float] | None = None


# integer fields: no target can hold an inf or nan in them (an id of inf is no atom)
INTEGER_COLUMNS = frozenset({"id", "type", "ix", "iy", "iz"})
# every spelling of a position a target may take its positions from
POSITION_COLUMNS = frozenset({"x", "y", "z", "xs", "ys", "zs", "xu", "yu", "zu", "xsu", "ysu", "zsu"})


def first_nonfinite(frame: Frame, names: frozenset[str] | None) -> tuple[str, int] | None:
    """(column, row) of the first inf/nan among the frame's numeric columns ``names`` (None:
    all of them), or None."""
    cols = [(name, col) for name, col in frame.columns.items()
            if (names is None or name in names) and col.dtype.kind == "f"]
    # A parsed block is one (n, k) array and its columns are strided views: one pass over
    # the whole array (a finite sum means no inf/nan: they propagate) costs what one column
    # costs, and only an array that fails is looked at column by column.
    bases = {id(col.base): col.base for _, col in cols
             if isinstance(col.base, np.ndarray) and col.base.dtype.kind == "f"}
    clean = {key for key, base in bases.items() if np.isfinite(base.sum())}
    for name, col in cols:
        if id(col.base) in clean or np.isfinite(col.sum()):
            continue
        finite = np.isfinite(col)
        if not finite.all():
            return name, int(np.argmin(finite))
    return None


class DumpTarget(Writer):
    """A ``post --to`` output, written from completed dump frames (``add(frame)``)."""

    units: ClassVar[tuple[str, Any] | None] = None    # (format title, units.UnitSystem) of its numbers
    last_frame_by_default: ClassVar[bool] = False     # without --frames: the last frame only
    uses_local: ClassVar[bool] = False                # reads --local contact dumps
    takes_precision: ClassVar[bool] = False           # writes text with --precision digits
    lookahead: ClassVar[int] = 1                      # frames ``start`` sees
    replaces_earlier: ClassVar[bool] = True           # --force: old frame files go too
    # the dump columns the target writes, none of which may be inf or nan (None: every
    # numeric column); an inf/nan there is an input error naming frame, atom and column
    finite_columns: ClassVar[frozenset[str] | None] = None
    # a target that can hold inf/nan in its other columns writes them with a warning
    writes_nonfinite: ClassVar[bool] = False

    def __init__(self, base: str | Path, context: PostContext | None = None, *,
                 force: bool = True):
        self.context = context if context is not None else PostContext(Path(base))
        self._head: list[Frame] | None = []
        super().__init__(base, force=force)

    @property
    def base(self) -> Path:
        return self.target

    # -- what targets implement -------------------------------------------------------------
    @classmethod
    def files(cls, base: Path) -> list[Path]:
        """The files a conversion to ``base`` writes (and ``--force`` replaces)."""
        return [base]

    def start(self, first: list[Frame]) -> None:
        """See the first ``lookahead`` frames (fewer if the dump has fewer) before any is written."""

    def write_frame(self, frame: Frame) -> None:
        raise NotImplementedError

    def end(self) -> None:
        """Write what comes after the last frame."""

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        """The frames of a written output (tests/conformance/)."""
        raise NotImplementedError

    # -- shared ------------------------------------------------------------------------------
    def check_finite(self, frame: Frame, file_rows: np.ndarray | None = None,
                     first_line: int | None = None, only: frozenset[str] | None = None) -> None:
        """Refuse an inf or nan (a dump's ``inf``/``nan``, or ``1e400``) this target cannot
        write: ``path:line`` of the atom, the frame, the atom id and the column.  ``file_rows``:
        each row's row in the file (None: as in the file), ``first_line`` the line of the
        file's first atom row; ``only``: check just these columns (and warn of nothing)."""
        must = INTEGER_COLUMNS | POSITION_COLUMNS | (self.finite_columns or frozenset())
        names = must if self.writes_nonfinite or self.finite_columns else None
        if only is not None:
            names = only if names is None else names & only
        hit = first_nonfinite(frame, names)
        if hit is not None:
            name, row = hit
            in_file = row if file_rows is None else int(file_rows[row])
            raise InputError(frame.source, None if first_line is None else first_line + in_file,
                             f"{self._where(frame, row)}: {name} is {frame.columns[name][row]}: "
                             f"--to {self.context.target_name or self.format or type(self).__name__} cannot write inf or "
                             "nan (did the simulation blow up?); nothing written")
        if self.writes_nonfinite and only is None:
            hit = first_nonfinite(frame, None)
            if hit is not None:
                name, row = hit
                self.context.warn("inf/nan", f"{frame.source}: {self._where(frame, row)}: {name} is "
                                  f"{frame.columns[name][row]}; written as is (the first of such "
                                  "values; did the simulation blow up?)")

    @staticmethod
    def _where(frame: Frame, row: int) -> str:
        ids = frame.columns.get("id")
        atom = f"atom id {ids[row]:.0f}" if ids is not None and np.isfinite(ids[row]) else f"atom {row + 1}"
        index = "" if frame.index is None else f"frame {frame.index} "
        return f"{index}(step {frame.step}), {atom}"

    def outputs(self) -> list[Path]:
        return self.files(self.target)

    def write(self, frame: Frame) -> None:
        if self._head is None:
            self.write_frame(frame)
            return
        self._head.append(frame)
        if len(self._head) >= self.lookahead:
            self._release()

    def _release(self) -> None:
        head, self._head = self._head, None
        self.start(head)
        for frame in head:
            self.write_frame(frame)

    def finish(self) -> None:
        if self._head:
            self._release()
        self.end()

    def time_of(self, frame: Frame) -> float:
        """The frame's time: as the run computed it when ``--data`` has fibrelmp's job facts
        (``ITEM: TIME`` is LAMMPS's running sum, printed with 16 digits), else ITEM: TIME,
        else its step, with a warning."""
        facts = self.context.facts
        if facts is not None:
            exact = facts.time(frame.step)
            scale = max(abs(exact), abs(facts.time_step) * max(1, abs(frame.step)))
            if frame.time is None or abs(frame.time - exact) <= 1e-9 * scale:
                return exact
            self.context.warn("data facts", f"{facts.path}: the job's times (start "
                              f"{facts.time_start!r}, {facts.time_step!r} per step) do not match the "
                              f"dump's ITEM: TIME ({frame.time!r} at step {frame.step}): is --data from "
                              "another run? the dump's times are used")
        if frame.time is not None:
            return frame.time
        self.context.warn("no times", f"{frame.source}: no ITEM: TIME in the dump (dump_modify time "
                          "yes); the step number is written as the time")
        return float(frame.step)
