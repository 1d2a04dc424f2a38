"""The one LAMMPS data-file writer: bead-spring (``lammps_job``), granular (``granular/data``)
and CardioProof SPH (``cardioproof/job``) jobs describe their data file as a title, count
lines, a box and sections of column arrays; this module lays them out (LAMMPS ``read_data``
format) with one formatting path, ``lammps_format.data_rows``.

Layout: the title line, a blank line, one ``<count> <keyword>`` line per count, a blank line
(``blank_before_box``), ``lo hi xlo xhi`` lines, then per section a blank line, its header
(keyword and optional ``# style`` comment), a blank line and its rows.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.textio import atomic_write
from fibrelmp.translate.lammps_format import data_rows, float_text


@dataclass(frozen=True)
class DataSection:
    """One section: ``header`` as LAMMPS reads it (``"Atoms # bpm/sphere"``), one row per
    element of the ``columns``, each row formatted by the %-format ``row_format`` (ending in
    a newline; a column of str goes in through ``%s``)."""
    header: str
    row_format: str
    columns: Sequence[np.ndarray | Sequence]


def data_file_text(title: str, counts: Sequence[tuple[int, str]],
                   box: Sequence[tuple[float, float]], sections: Sequence[DataSection],
                   blank_before_box: bool = True) -> str:
    """The data file as text: ``counts`` as (number, keyword) pairs in order (``(5, "atoms")``),
    ``box`` as (lo, hi) per axis x, y, z; every section given is written, with or without
    rows (a caller leaves out Bonds when there are none)."""
    parts = [f"{title}\n\n", *(f"{number} {keyword}\n" for number, keyword in counts)]
    if blank_before_box:
        parts.append("\n")
    parts += [f"{float_text(lo)} {float_text(hi)} {axis}lo {axis}hi\n" for (lo, hi), axis in zip(box, "xyz")]
    for section in sections:
        parts.append(f"\n{section.header}\n\n")
        parts.append(data_rows(section.row_format, list(section.columns)))
    return "".join(parts)


def write_data_file(path: Path, title: str, counts: Sequence[tuple[int, str]],
                    box: Sequence[tuple[float, float]], sections: Sequence[DataSection],
                    blank_before_box: bool = True) -> None:
    """``data_file_text`` written atomically to ``path``."""
    atomic_write(path, data_file_text(title, counts, box, sections, blank_before_box))
