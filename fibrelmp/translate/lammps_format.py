"""Numbers and data-file rows as the LAMMPS jobs write them (lammps_data writes the data files).

``float_text`` is how every float enters an input script (shortest text that reads back to the
same double); ``data_rows`` formats the columns of a data-file section; ``atomfile_blocks``
writes per-atom values for ``fix property/atom`` that the data file does not hold.
"""

from __future__ import annotations

import numpy as np

from fibrelmp.numtext.shortest import rows_text
from fibrelmp.textio import format_rows


def float_text(x: float) -> str:
    """A number in an input script: repr of the double (round-trips exactly)."""
    return repr(float(x))


def data_rows(fmt_row: str, columns: list[np.ndarray]) -> str:
    """Data-file rows: digit-wise numpy formatting when possible, else one % operation."""
    n = len(columns[0])
    if n == 0:
        return ""
    # fast path: "%d"/"%.17g" columns and literal tokens, single-spaced, formatted
    # digit-column-wise; anything else (%s, %g, two spaces) takes the % operation
    tokens, it = fmt_row.split(), iter(columns)
    if fmt_row == " ".join(tokens) + "\n" and fmt_row.count("%") == len(columns) \
            and all(tok in ("%d", "%.17g") for tok in tokens if "%" in tok):
        text = rows_text([next(it) if tok.startswith("%") else tok for tok in tokens])
        if text is not None:
            return text.decode("ascii")
    return format_rows(fmt_row, columns)


def atomfile_blocks(ids: np.ndarray, columns: list[tuple[str, np.ndarray]], title: str) -> str:
    """Per-atom values as consecutive LAMMPS atomfile blocks, one per column (``variable V
    atomfile FILE``, then ``set group all NAME v_V`` and ``next V`` for each): a comment naming
    the column, a count and "atom-id value" lines.  A value not listed is 0 to LAMMPS, so only
    values other than +0.0 are listed, and at least one line, as LAMMPS takes an empty block
    for the end of the file.  Kept out of the data file, whose custom sections other readers
    (MDAnalysis, OVITO) cannot skip."""
    ids = np.asarray(ids, np.int64)
    parts = ["".join(f"# {line}\n" for line in title.splitlines())]
    for name, values in columns:
        values = np.asarray(values)
        keep = (values != 0) | (np.signbit(values) if values.dtype.kind == "f" else False)
        if not keep.any():
            keep = np.zeros(len(values), bool)
            keep[0] = True
        parts.append(f"# {name}\n{int(keep.sum())}\n")
        fmt = "%d %d\n" if values.dtype.kind in "iu" else "%d %.17g\n"
        parts.append(data_rows(fmt, [ids[keep], values[keep]]))
    return "".join(parts)
