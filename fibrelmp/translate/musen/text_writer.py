"""The one MUSEN text writer's formatting (what cmusen's EXPORT_TO_TEXT writes,
``ExportAsText.cpp``), shared by the result writer from frames (``writer.py``) and the
``.mdem`` text export (``mdem/text_export.py``), which differ only in where the values come
from.

An object line is its constant part (``object_header``: 0 id, 1 type, 5 geometry, 23 material,
24 activity interval) followed by every saved time point (``time_point_lines``: ``2 t`` and the
selected tags with ``precision`` significant digits, C++ ostream ``%g``); a scene line is
``scene_line``.  Time-point values come from a spool file laid out (saves, objects, columns)
(``gather_spool``), so memory holds a chunk of objects, not the whole result.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import IO, Any

import numpy as np

from fibrelmp.numtext.fast import format_g_template

# MUSEN's export selector groups and flags, in ExportAsText.h order (cmusen TEXT_EXPORT_*).
EXPORT_FLAGS: dict[str, tuple[str, ...]] = {
    "objectTypes": ("particles", "bonds", "walls"),
    "constProps": ("id", "type", "geometry", "material", "activityInterval"),
    "tdPropsPart": ("angVel", "coord", "force", "forceAmpl", "orient", "princStress",
                    "stressTensor", "temperature", "velocity"),
    "tdPropsBond": ("coord", "force", "forceAmpl", "tangOverlap", "temperature", "totTorque",
                    "velocity"),
    "tdPropsWall": ("coord", "force", "forceAmpl", "velocity"),
    "sceneInfo": ("domain", "pbc", "anisotropy", "contactRadius"),
    "geometries": ("baseInfo", "tdProperties", "wallsList", "analysisVolumes"),
    "materials": ("compounds", "interactions", "mixtures"),
    "generators": ("packageGenerator", "bondsGenerator"),
}
# (flag, tag, number of values) of a time-point field
Field = tuple[str, int, int]


def all_on() -> dict[str, dict[str, bool]]:
    """Every export selector on (cmusen's default)."""
    return {g: {f: True for f in flags} for g, flags in EXPORT_FLAGS.items()}


def export_selectors(overrides: dict[str, dict[str, bool]] | None = None) -> dict[str, dict[str, bool]]:
    """All selectors on, then ``overrides`` (group -> flag -> on) applied."""
    sel = all_on()
    for group, flags in (overrides or {}).items():
        sel[group].update(flags)
    return sel


def number_text(x: float) -> str:
    """A number as a C++ ostream writes it with the default precision 6."""
    return "%g" % x


def scene_line(tag: int, *values: Any) -> str:
    """``tag v1 v2 ... `` and a newline: every value followed by a space, as MUSEN writes."""
    return f"{tag} " + "".join(f"{v} " for v in values) + "\n"


# constProps flag -> its part of an object line (``%s``: its text), in MUSEN's order
_HEADER_PARTS = (("id", "0 %s "), ("type", "1 %s "), ("geometry", "5 %s "), ("material", "23 %s "),
                 ("activityInterval", "24 %s %s "))


def object_header(const: dict[str, bool], oid: int, otype: int, geometry: str, key: str,
                  start: str, end: str) -> str:
    """The constant part of an object line, the parts ``const`` (constProps) selects;
    ``start``/``end``: the activity interval already as text."""
    values = {"id": (oid,), "type": (otype,), "geometry": (geometry,), "material": (key,),
              "activityInterval": (start, end)}
    return "".join(part % values[flag] for flag, part in _HEADER_PARTS if const[flag])


def object_headers(const: dict[str, bool], ids: Sequence, otype: int, geometries: Sequence[str],
                   keys: Sequence[str], starts: Sequence[str], ends: Sequence[str]) -> list[str]:
    """``object_header`` of many objects of one type, with one ``%`` for them all (a line at a
    time in Python costs ~10 µs per object)."""
    columns = {"id": [ids], "type": [[otype] * len(ids)], "geometry": [geometries],
               "material": [keys], "activityInterval": [starts, ends]}
    tpl, picked = "", []
    for flag, part in _HEADER_PARTS:
        if const[flag]:
            tpl += part
            picked += columns[flag]
    return bulk_format(tpl, *picked) if picked else [""] * len(ids)


def bulk_format(fmt: str, *columns) -> list[str]:
    """``fmt % row`` for every row of the columns (arrays or sequences of equal length), with
    one ``%`` for them all; ``fmt`` must not contain a newline."""
    n = len(columns[0])
    if n == 0:
        return []
    lists = [c.tolist() if isinstance(c, np.ndarray) else list(c) for c in columns]
    out = ("\n".join([fmt] * n) % tuple(v for row in zip(*lists) for v in row)).split("\n")
    if len(out) != n:                   # a value held a newline: row by row
        return [fmt % row for row in zip(*lists)]
    return out


def gather_spool(fh: IO[bytes], count: int, width: int, nt: int, rows: np.ndarray,
                 steps: slice | None = None) -> np.ndarray:
    """(len(rows), nt, width) from a float64 spool laid out (nt, count, width): one read of
    the row span per save (rows of one type come in id order, so the span is tight).  With
    ``steps``, only those saves: (len(rows), saves in steps, width), read through a memory
    map (a long line's piece; no Python loop over the saves)."""
    if steps is not None:
        spool = np.memmap(fh, np.float64, "r", shape=(nt, count, width))
        return np.ascontiguousarray(spool[steps][:, rows].transpose(1, 0, 2))
    lo, hi = int(rows.min()), int(rows.max()) + 1
    out = np.empty((len(rows), nt, width))
    for k in range(nt):
        fh.seek(((k * count) + lo) * width * 8)
        block = np.fromfile(fh, np.float64, (hi - lo) * width).reshape(hi - lo, width)
        out[:, k] = block[rows - lo]
    return out


def time_point_lines(heads: Sequence[str], fields: Sequence[Field], flags: dict[str, bool],
                     times: Sequence[float], precision: int,
                     values_of: Callable[[list[int]], np.ndarray]) -> list[str]:
    """Whole object lines: each head followed by its time points.  ``fields`` in spool column
    order, ``flags`` the selector group that picks them; ``values_of(columns)`` gives the
    selected spool columns as (len(heads), len(times), len(columns))."""
    nt = len(times)
    if nt == 0:
        return [h + "\n" for h in heads]
    cols, prefixes = _time_point_layout(fields, flags)
    values = np.empty((len(heads), nt, len(prefixes)))
    values[:, :, 0] = times
    if cols:
        values[:, :, 1:] = values_of(cols)
    text = _points_text(values.reshape(-1, len(prefixes)), prefixes, precision, nt)
    return [h + body + "\n" for h, body in zip(heads, text.split("\n"))]


def _time_point_layout(fields: Sequence[Field], flags: dict[str, bool]) -> tuple[list[int], list[str]]:
    """(spool columns, what precedes each value of a time point: ``2 `` the time, ``TAG `` a
    field's first value) of the fields ``flags`` selects."""
    cols: list[int] = []
    prefixes, start = ["2 "], 0
    for flag, tag, width in fields:
        if flags[flag]:
            cols.extend(range(start, start + width))
            prefixes += [f"{tag} "] + [""] * (width - 1)
        start += width
    return cols, prefixes


def _points_text(values: np.ndarray, prefixes: list[str], precision: int, per_line: int) -> str:
    """Rows of ``values`` as time points (each value its prefix, ``%.{precision}g`` and a space),
    a newline after every ``per_line`` rows: the C formatter at precision 6 (printf-identical),
    else one C-level ``%`` of Python."""
    raw = format_g_template(values, prefixes, per_line) if precision == 6 else None
    if raw is not None:
        return raw.decode("ascii")
    tpl = "".join(f"{p}%.{precision}g " for p in prefixes)
    return ((tpl * per_line + "\n") * (len(values) // per_line)) % tuple(values.ravel().tolist())


def long_lines(nt: int, values_per_save: int, most_values: int) -> int | None:
    """Saves per piece when even 16 object lines of ``nt`` saves would hold more than
    ``most_values`` numbers (then lines are written one at a time, in pieces:
    ``write_long_line``), else None (chunks of whole lines: ``time_point_lines``)."""
    if 16 * nt * values_per_save <= most_values:
        return None
    return max(1, most_values // values_per_save)


def write_long_line(out: IO[str], head: str, fields: Sequence[Field], flags: dict[str, bool],
                    times: Sequence[float], precision: int, piece: int,
                    values_of: Callable[[list[int], slice], np.ndarray]) -> None:
    """One object line of ``time_point_lines`` written to ``out`` ``piece`` saves at a time
    (the same text; memory holds one piece); ``values_of(columns, steps)`` gives the selected
    spool columns of those saves as (saves, len(columns))."""
    out.write(head)
    cols, prefixes = _time_point_layout(fields, flags)
    times = np.asarray(times, float)
    for lo in range(0, len(times), piece):
        steps = slice(lo, min(len(times), lo + piece))
        values = np.empty((steps.stop - lo, len(prefixes)))
        values[:, 0] = times[steps]
        if cols:
            values[:, 1:] = values_of(cols, steps)
        out.write(_points_text(values, prefixes, precision, len(values))[:-1])   # one line: no newline
    out.write("\n")
