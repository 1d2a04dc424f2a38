"""Numbers and data-file rows as the LAMMPS jobs write them (bead-spring and granular).

``float_text`` is how every float enters an input script (shortest text that reads back to the
same double); ``data_rows`` formats the columns of a data-file section.
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
    # fast path: "%d"/"%.17g" columns and literal tokens, formatted digit-column-wise
    tokens, it = fmt_row.split(), iter(columns)
    if fmt_row.endswith("\n") and fmt_row.count("%") == len(columns):
        text = rows_text([next(it) if tok.startswith("%") else tok for tok in tokens])
        if text is not None:
            return text.decode("ascii")
    return format_rows(fmt_row, columns)
