"""Completing dump frames for the targets: facts from ``--data``, atoms in id order, type
labels numbered, ``--types`` applied, positions checked."""

from __future__ import annotations

from typing import Callable

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.post.target import INTEGER_COLUMNS


class Completer:
    """Fill what writers need and the dump lacks; sort atoms by id; apply ``--types``."""

    def __init__(self, data, types: list[str] | None, names: dict[int, str], warnings: list,
                 target_units=None, check: Callable[..., None] | None = None):
        self.data = data
        self.names = names
        self.warnings = warnings
        self.target_units = target_units     # (format name, units.UnitSystem) of the output, if any
        self.check = check                   # DumpTarget.check_finite (inf/nan)
        self.warned: set[str] = set()
        self.labels = {v: k for k, v in names.items()}
        self.keep = self._types(types) if types else None
        self.kept_any = False            # --types: some frame had an atom of those types
        self.present: set[int] = set()   # types met until then (for the error if none is)

    def _types(self, tokens: list[str]) -> set[int]:
        out = set()
        for tok in (t.strip() for item in tokens for t in item.split(",")):
            if not tok:
                continue
            if tok.lstrip("-").isdigit():
                out.add(int(tok))
            elif tok in self.labels:
                out.add(self.labels[tok])
            else:
                known = ", ".join(f"{v}={k}" for k, v in sorted(self.names.items())) or "none (give --data)"
                raise InputError(None, None, f"--types: unknown type {tok!r} (type names: {known})")
        return out

    def _warn(self, key: str, text: str) -> None:
        if key not in self.warned:
            self.warned.add(key)
            self.warnings.append((key, text))

    def __call__(self, frame: Frame) -> Frame:
        if self.target_units is not None and frame.units is not None:
            from fibrelmp.units import mismatch_note

            note = mismatch_note(frame.units, self.target_units[1], self.target_units[0])
            if note is not None:
                self._warn("units", f"{frame.source}: {note}")
        if self.check is not None:
            # the frame as read: its rows are the file's (without --types all atoms are
            # written; with it, ids and types first, as sorting and selecting use them)
            self.check(frame, None, frame.atom_line, None if self.keep is None else INTEGER_COLUMNS)
        cols, rows = self._by_id(frame)
        self._facts(frame, cols)
        out = Frame(frame.step, frame.lo, frame.hi, frame.boundary, cols, frame.tilt, frame.time,
                    frame.line, frame.units, frame.source, frame.index)
        if self.keep is not None:
            codes = cols["type"].astype(np.int64)
            mask = np.isin(codes, list(self.keep))
            if not self.kept_any:
                self.kept_any = bool(mask.any())
                if not self.kept_any:
                    self.present.update(np.unique(codes).tolist())
            out, rows = out.select(mask), rows[mask]
            if self.check is not None:   # the atoms written, named by their lines in the file
                self.check(out, rows, frame.atom_line)
        self._positions(out)
        return out

    def _by_id(self, frame: Frame) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """The frame's columns with atoms in id order (numbered 1..N without ids), and the
        row in the file of each."""
        cols = dict(frame.columns)
        n = frame.count
        if "id" not in cols:
            cols["id"] = np.arange(1, n + 1, dtype=np.float64)
            self._warn("no ids", f"{frame.source}: the dump has no 'id' column; atoms are numbered "
                       "1..N in file order")
        ids = cols["id"]
        order = np.arange(n)
        if n > 1 and not bool(np.all(ids[1:] > ids[:-1])):
            order = np.argsort(ids, kind="stable")
            cols = {k: v[order] for k, v in cols.items()}
            ids = cols["id"]
            twice = np.flatnonzero(ids[1:] == ids[:-1])
            if len(twice):        # every writer keys atoms by id: two would be merged or doubled
                raise InputError(frame.source, frame.line, f"atom id {ids[twice[0]]:.0f} appears "
                                 f"twice in the frame of step {frame.step}")
        return cols, order

    def _facts(self, frame: Frame, cols: dict[str, np.ndarray]) -> None:
        """Types (numbered labels), radii and masses the dump lacks, from --data."""
        n, data = frame.count, self.data
        rows = data.rows(cols["id"], "--data facts") if data is not None and n else None
        if "type" not in cols:
            if rows is not None:
                cols["type"] = data.types[rows].astype(np.float64)
            else:
                cols["type"] = np.ones(n)
                self._warn("no types", f"{frame.source}: the dump has no 'type' column and no --data "
                           "was given; every atom is type 1")
        elif cols["type"].dtype.kind not in "fiu":       # type labels (dump_modify types labels)
            codes = np.empty(n)
            for k, lab in enumerate(cols["type"]):
                if lab not in self.labels:
                    self.labels[lab] = max(list(self.names) + [0]) + 1
                    self.names[self.labels[lab]] = lab
                codes[k] = self.labels[lab]
            cols["type"] = codes
        if "radius" not in cols:
            if "diameter" in cols:
                cols["radius"] = cols["diameter"] / 2
            elif rows is not None and data.radius is not None:
                cols["radius"] = data.radius[rows]
        if "mass" not in cols and rows is not None and data.mass is not None:
            cols["mass"] = data.mass[rows]

    @staticmethod
    def _positions(out: Frame) -> None:
        """Cartesian positions (x y z, else xu yu zu) in ``out``, all finite."""
        cols = out.columns
        if not out.has("x", "y", "z"):
            x = out.positions()
            if x is not None:
                cols.update(x=x[:, 0], y=x[:, 1], z=x[:, 2])
            elif not out.has("xu", "yu", "zu"):
                xu = out.unwrapped()
                if xu is None:
                    out.wrapped()                      # raises the "no positions" error
                cols.update(xu=xu[:, 0], yu=xu[:, 1], zu=xu[:, 2])
        for names in (("x", "y", "z"), ("xu", "yu", "zu")):
            if out.has(*names):
                bad = ~np.isfinite(out.vector(*names)).all(axis=1)
                if bad.any():     # a blown-up run: no output format can hold these
                    k = int(np.flatnonzero(bad)[0])
                    raise InputError(out.source, out.line, f"atom id {cols['id'][k]:.0f} has position "
                                     f"{out.vector(*names)[k].tolist()} in the frame of step "
                                     f"{out.step} (did the simulation blow up?)")

    def check_types(self, source) -> None:
        """``--types`` selecting no atom of any frame read is an error, not empty frames."""
        if self.keep is None or self.kept_any:
            return
        name = lambda t: f"{self.names[t]}={t}" if t in self.names else str(t)     # noqa: E731
        have = ", ".join(name(t) for t in sorted(self.present)) or "none (no atoms)"
        raise InputError(source, None, f"--types {', '.join(name(t) for t in sorted(self.keep))}: "
                         f"no atom of the selected frames has these types (types present: "
                         f"{have}); nothing written")
