"""The thermo table of a LAMMPS log (``log.lammps``), as one series per column.

LAMMPS prints a header line (``Step Time KinEng ...``) and then one row per thermo output
for every ``run`` command; fibrelmp's jobs are many short runs, so the table comes in many
sections whose first row repeats the previous section's last step.  ``read_thermo`` joins the
sections, keeps one row per repeated step (the later: commands between the runs may have
changed the state).  The log is read by ``fibrelmp.lammps_log.ThermoLog`` (the reader the run
record uses too): it keeps rows of a run cut short, skips the other lines LAMMPS mixes in
(warnings, commands) and refuses ``thermo_style multi`` / ``yaml`` logs with that reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.lammps_log import ThermoLog


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


def read_thermo(path: str | Path) -> Thermo:
    """Every thermo row of the log at ``path``; an InputError if it has none."""
    from fibrelmp.registry import check_regular_file

    path = Path(path)
    check_regular_file(path, "LAMMPS log")
    log = ThermoLog(path)
    columns: dict[str, list[float]] = {}
    sections, rows = 0, 0
    last_step: float | None = None
    for block in log.blocks():
        sections += 1
        header = block.header
        for k, values in enumerate(block.rows):
            step = values[0]
            if k == 0 and last_step is not None and step == last_step:
                # the previous run's last step again; the new row wins: commands between the
                # runs (a FibreNet start sets the velocities) may have changed the state
                for name, value in zip(header, values):
                    if name not in columns:
                        columns[name] = [math.nan] * rows
                    columns[name][-1] = value
                continue
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
    per_atom = log.norm if log.norm is not None else log.units == "lj"      # LAMMPS's default: lj only
    return Thermo(path, {k: np.asarray(v, float) for k, v in columns.items()}, sections, log.units,
                  per_atom)
