"""FibreNet output formats: ``_coord/_vel/_force.xyz`` frames and ``_restart.res``.

Formats as FibreNet's DumpData / DumpRestartData write them (std::fixed 5 decimals for the
xyz files, default ostream precision -- 6 significant digits -- for the restart file).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, NamedTuple, Sequence

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.textio import check_text_file, format_rows, parse_table, read_text
from fibrelmp.numtext.fast import format_g_rows, format_xyz_parts
from fibrelmp.numtext.printf import fixed_chars, join_fields, name_chars
# FibreNet's result names: defined with the bead-spring job, whose fix fibrenet/output writes them
from fibrelmp.translate.lammps_job import RESTART_SUFFIX, XYZ_SUFFIX


def _rows(fmt_row: str, names: np.ndarray, values: np.ndarray) -> str:
    return format_rows(fmt_row, [names] + [values[:, c] for c in range(values.shape[1])])


def _xyz_head(n: int, step: int, dt: float, lengths: np.ndarray) -> str:
    return f"{n}\nFRAME\t{step}\t{dt:.5f}\t{lengths[0]:.5f}\t{lengths[1]:.5f}\t{lengths[2]:.5f}\n"


def xyz_frame_parts(step: int, dt: float, lengths: np.ndarray, codes: np.ndarray, table: list[str],
                    values: np.ndarray) -> list:
    """One xyz frame as buffers to write in turn (see xyz_frame_bytes)."""
    n = len(codes)
    head = _xyz_head(n, step, dt, lengths).encode()
    fast = format_xyz_parts(codes, table, values, 5) if n else None     # optional C path
    if fast is not None:
        return [head] + fast
    chars = fixed_chars(values.ravel(), 5) if n else None
    if chars is None:
        names = np.array(table, dtype=object)[codes] if n else np.zeros(0, object)
        return [head + _rows("%s\t%.5f\t%.5f\t%.5f\n", names, values).encode()]
    chars = chars.reshape(n, 3, -1)
    return [head + join_fields([name_chars(codes, table), b"\t", chars[:, 0], b"\t", chars[:, 1],
                                b"\t", chars[:, 2], b"\n"], n)]


def xyz_frame_bytes(step: int, dt: float, lengths: np.ndarray, codes: np.ndarray, table: list[str],
                    values: np.ndarray) -> bytes:
    """One xyz frame; row i is ``table[codes[i]]`` and values[i] ("%s\t%.5f\t%.5f\t%.5f").

    Formatted in C when available (fastparse), else with array operations (textfmt); both
    byte-identical to ``%.5f``; values that need it (nan, inf, huge) take the ``%`` path.
    """
    parts = xyz_frame_parts(step, dt, lengths, codes, table, values)
    return parts[0] if len(parts) == 1 else b"".join(bytes(p) for p in parts)


def xyz_frame(step: int, dt: float, lengths: np.ndarray, names: np.ndarray, values: np.ndarray) -> str:
    table, codes = np.unique(np.asarray(names, dtype=str), return_inverse=True)
    return xyz_frame_bytes(step, dt, lengths, codes.ravel(), list(table), values).decode()


class XyzRows(NamedTuple):
    """One frame for ``XyzWriter``: row i is ``table[codes[i]]`` and, per field, its values."""
    step: int
    dt: float
    lengths: np.ndarray
    codes: np.ndarray
    table: list[str]
    values: dict[str, np.ndarray]          # field ("position", "velocity", "force") -> (n, 3)


class XyzWriter(Writer):
    """FibreNet trajectories ``<base>_coord.xyz`` / ``_vel.xyz`` / ``_force.xyz``, one file
    per field in ``fields``, every frame added (``XyzRows``, or an ``XyzFrame`` of names and
    values for a one-field writer)."""

    format = "xyz"

    def __init__(self, base: str | Path, fields: Sequence[str] = tuple(XYZ_SUFFIX), *,
                 force: bool = True):
        self.fields = tuple(fields)
        super().__init__(base, force=force)
        for f in self.fields:               # the files exist (empty) even without frames
            self.open(self.file(f))

    @property
    def path(self) -> Path:
        return self.target

    def file(self, field: str) -> Path:
        return self.target.with_name(self.target.name + XYZ_SUFFIX[field])

    def outputs(self) -> list[Path]:
        return [self.file(f) for f in self.fields]

    def write(self, frame: "XyzRows | XyzFrame") -> None:
        if isinstance(frame, XyzFrame):
            table, codes = np.unique(np.asarray(frame.names, dtype=str), return_inverse=True)
            frame = XyzRows(frame.step, frame.dt, frame.lengths, codes.ravel(), list(table),
                            {f: frame.values for f in self.fields})
        for f in self.fields:
            self.put(self.file(f), *xyz_frame_parts(frame.step, frame.dt, frame.lengths, frame.codes,
                                                    frame.table, frame.values[f]))


def _g(x: float) -> str:
    return f"{x:g}"


def _restart_head(n: int, step: int, dt: float, lengths: np.ndarray) -> str:
    return (f"{n}\nFRAME\t{step}\t{_g(dt)}\t{_g(lengths[0])}\t{_g(lengths[1])}\t"
            f"{_g(lengths[2])}\n")


def restart_text(step: int, dt: float, lengths: np.ndarray, names: np.ndarray, x: np.ndarray,
                 unwrapped: np.ndarray, v_tilde: np.ndarray, force: np.ndarray) -> str:
    values = np.hstack([x, unwrapped, v_tilde, force])
    return _restart_head(len(names), step, dt, lengths) + _rows("\t%s" + "\t%g" * 12 + "\n", names, values)


def restart_bytes(s: "RestartState") -> bytes:
    """The restart file of ``s``: formatted in C when available (fastparse), else by
    ``restart_text``; the same bytes."""
    values = np.hstack([s.x, s.unwrapped, s.v_tilde, s.force])
    rows = format_g_rows(s.codes, s.table, values)
    if rows is not None:
        return _restart_head(len(s.codes), s.step, s.dt, s.lengths).encode() + rows
    names = np.array(s.table, dtype=object)[s.codes]
    return restart_text(s.step, s.dt, s.lengths, names, s.x, s.unwrapped, s.v_tilde, s.force).encode()


class RestartState(NamedTuple):
    """One frame for ``RestartWriter``: bead i has type ``table[codes[i]]``, wrapped and
    unwrapped positions, v~ and F."""
    step: int
    dt: float
    lengths: np.ndarray
    codes: np.ndarray
    table: list[str]
    x: np.ndarray
    unwrapped: np.ndarray
    v_tilde: np.ndarray
    force: np.ndarray


class RestartWriter(Writer):
    """A FibreNet restart ``_restart.res`` (the path given) of the last frame added."""

    format = "res"

    def __init__(self, path: str | Path, *, force: bool = True):
        super().__init__(path, force=force)
        self.last: RestartState | None = None

    def write(self, frame: RestartState) -> None:
        self.last = frame                 # only the last frame is written, at close

    def finish(self) -> None:
        if self.last is not None:
            self.put(self.target, restart_bytes(self.last))


def write_restart(path: str | Path, step: int, dt: float, lengths: np.ndarray, names: np.ndarray,
                  x: np.ndarray, unwrapped: np.ndarray, v_tilde: np.ndarray, force: np.ndarray) -> None:
    """Write one restart file (atomically)."""
    table, codes = np.unique(np.asarray(names, dtype=str), return_inverse=True)
    with RestartWriter(path) as w:
        w.add(RestartState(step, dt, lengths, codes.ravel(), list(table), x, unwrapped, v_tilde, force))


class FibreNetWriter(Writer):
    """What a FibreNet run writes: the xyz trajectories of ``fields`` and (``restart``) the
    restart file of the last frame, all renamed into place together.  Frames are
    ``(XyzRows, RestartState)`` pairs."""

    def __init__(self, base: str | Path, fields: Sequence[str], restart: bool = True, *,
                 force: bool = True):
        self.fields, self.restart = tuple(fields), restart
        super().__init__(base, force=force)
        self.xyz = self.adopt(XyzWriter(base, self.fields))
        self.res = self.adopt(RestartWriter(self.restart_path)) if restart else None

    @property
    def restart_path(self) -> Path:
        return self.target.with_name(self.target.name + RESTART_SUFFIX)

    def outputs(self) -> list[Path]:
        xyz = [self.target.with_name(self.target.name + XYZ_SUFFIX[f]) for f in self.fields]
        return xyz + ([self.restart_path] if self.restart else [])

    def write(self, frame: tuple[XyzRows, RestartState]) -> None:
        rows, state = frame
        self.xyz.add(rows)
        if self.res is not None:
            self.res.add(state)


@dataclass
class XyzFrame:
    step: int
    dt: float
    lengths: np.ndarray
    names: list[str]
    values: np.ndarray


def read_xyz(path: str | Path) -> list[XyzFrame]:
    """Read every frame of a FibreNet xyz file."""
    return list(iter_xyz(path))


def iter_xyz(path: str | Path) -> Iterator[XyzFrame]:
    """The frames of a FibreNet xyz file, one at a time (memory holds one frame)."""
    path = Path(path)
    check_text_file(path, "FibreNet xyz file")       # exists, regular, UTF-8 text (in blocks)
    with open(path, encoding="utf-8-sig") as fh:
        number = 0

        def line() -> str | None:
            nonlocal number
            text = fh.readline()
            if not text:
                return None
            number += 1
            return text

        while True:
            first = line()
            if first is None:
                return
            if not first.strip():
                continue
            try:
                n = int(first)
            except ValueError:
                raise InputError(path, number, f"expected a bead count, got {first.strip()!r}") from None
            head_text = line()
            head = head_text.split() if head_text is not None else []
            if len(head) != 6 or head[0] != "FRAME":
                raise InputError(path, number + (head_text is None), "expected 'FRAME step dt Lx Ly Lz'")
            start = number + 1
            body = []
            for _ in range(n):
                text = line()
                if text is None:
                    break
                body.append(text)
            if len(body) < n:
                raise InputError(path, start + len(body), f"frame has {len(body)} of {n} rows")
            table, val = parse_table(body, list(range(start, start + n)), 4, path, "xyz", text_cols=(0,))
            yield XyzFrame(int(head[1]), float(head[2]), np.array(head[3:], float),
                           list(table[:, 0]), val[:, 1:4])


def read_restart(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Bead rows of a FibreNet restart file: types and (n,12) x, ix, v~, F.

    As FibreNet does, only lines of exactly 13 tokens count as bead rows.
    """
    path = Path(path)
    raw = read_text(path, "FibreNet restart file").splitlines()
    keep = [(k + 1, ln) for k, ln in enumerate(raw) if len(ln.split()) == 13]
    if not keep:
        raise InputError(path, None, "no bead rows (lines of 13 tokens: type x y z ix iy iz vx vy vz fx fy fz)")
    numbers, lines = [k for k, _ in keep], [ln for _, ln in keep]
    table, val = parse_table(lines, numbers, 13, path, "restart row", text_cols=(0,))
    return list(table[:, 0]), val[:, 1:]
