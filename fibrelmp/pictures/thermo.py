"""The thermo table of a LAMMPS log (``log.lammps``), as one series per column.

LAMMPS prints a header line (``Step Time KinEng ...``) and then one row per thermo output
for every ``run`` command; fibrelmp's jobs are many short runs, so the table comes in many
sections whose first row repeats the previous section's last step.  ``read_thermo`` joins the
sections, keeps one row per repeated step (the later: commands between the runs may have
changed the state), keeps rows of a run cut short (a log of a run that failed or
is still going has no ``Loop time`` line for its last section) and skips the other lines
LAMMPS mixes in (warnings, commands).  Only the default one-line thermo style is read
(``thermo_style multi`` / ``yaml`` logs are refused with that reason).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError


@dataclass
class Thermo:
    path: Path
    columns: dict[str, np.ndarray]    # column name (as in the header) -> values, row order
    sections: int                     # thermo tables joined (one per ``run`` with output)
    units: str | None = None          # the log's ``units`` command, if it has one
    per_atom: bool = False            # extensive values divided by the atom count (norm yes)

    @property
    def rows(self) -> int:
        return len(self.columns["Step"])


def _numbers(words: list[str]) -> list[float] | None:
    try:
        values = [float(w) for w in words]
    except ValueError:
        return None
    return values


def read_thermo(path: str | Path) -> Thermo:
    """Every thermo row of the log at ``path``; an InputError if it has none."""
    from fibrelmp.registry import check_regular_file

    path = Path(path)
    check_regular_file(path, "LAMMPS log")
    columns: dict[str, list[float]] = {}
    header: list[str] | None = None
    sections, rows, units, norm = 0, 0, None, None
    last_step: float | None = None
    first_of_section = False
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            words = line.split()
            if not words:
                continue
            if words[0] == "Step" and len(words) > 1:
                header, first_of_section = words, True
                sections += 1
                continue
            if words[0] == "units" and len(words) == 2:
                units = words[1]
            if words[0] == "thermo_modify" and "norm" in words[:-1]:
                norm = words[words.index("norm") + 1] == "yes"
            if words[0].startswith("-----") and "Step" in words:
                raise InputError(path, None, "thermo in 'multi' style; fibrelmp reads the default "
                                 "one-line style (thermo_style custom/one)")
            if words[0] == "keywords:":
                raise InputError(path, None, "thermo in 'yaml' style; fibrelmp reads the default "
                                 "one-line style (thermo_style custom/one)")
            if header is None:
                continue
            if words[0] == "Loop":          # "Loop time of ...": the section ends
                header = None
                continue
            values = _numbers(words) if len(words) == len(header) else None
            if values is None:
                continue                    # a warning or command line inside the section
            step = values[0]
            if first_of_section and last_step is not None and step == last_step:
                # the previous run's last step again; the new row wins: commands between the
                # runs (a FibreNet start sets the velocities) may have changed the state
                first_of_section = False
                for name, value in zip(header, values):
                    if name not in columns:
                        columns[name] = [math.nan] * rows
                    columns[name][-1] = value
                continue
            first_of_section = False
            for name in header:
                if name not in columns:
                    columns[name] = [math.nan] * rows
            for name, value in zip(header, values):
                columns[name].append(value)
            rows += 1
            for name, column in columns.items():
                if len(column) < rows:      # a column the current header lacks
                    column.append(math.nan)
            last_step = step
    if not rows:
        raise InputError(path, None, "no thermo output in this log (no 'Step ...' table): "
                         "the run printed none (thermo 0)")
    per_atom = norm if norm is not None else units == "lj"      # LAMMPS's default: lj only
    return Thermo(path, {k: np.asarray(v, float) for k, v in columns.items()}, sections, units,
                  per_atom)
