"""The one MUSEN text reader: tokenising MUSEN text files (``ImportFromText.cpp`` syntax),
object lines, scene lines and the per-time-point sections (``scan_text``, used by the scene
reader ``scene.py`` and ``mdem/text_import.py``), plus ``read_time_points`` for whole result
files.

Speed: a line is split once and its time-point part converted to floats in one numpy call;
the tag layout of a line is worked out once and then only verified for lines of the same
shape, so a 64 MB result with 12 time points per object reads in about a second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.textio import read_text

SPHERE, SOLID_BOND, LIQUID_BOND, WALL = 1, 9, 13, 14
TYPE_NAMES = {SPHERE: "sphere", SOLID_BOND: "solid bond", LIQUID_BOND: "liquid bond",
              WALL: "triangular wall"}
GEOMETRY_SIZE = {SPHERE: 2, SOLID_BOND: 4, LIQUID_BOND: 4, WALL: 0}
# per-time-point tags -> number of values (10/11/17 are old tags MUSEN reads and skips)
TD_SIZE = {2: 1, 10: 3, 11: 3, 12: 3, 15: 3, 16: 3, 17: 3, 18: 1, 20: 3, 31: 4, 36: 9, 37: 1,
           42: 3, 43: 1, 44: 9, 45: 3}
SCENE_TAGS = (22, 28, 29, 30, 25, 26, 27, 38, 32, 33, 34, 39, 40, 41)


class TimePoints(NamedTuple):
    """All saved time points of a MUSEN text file, objects sorted by id."""

    times: np.ndarray               # (T,) union of all objects' times, ascending
    ids: np.ndarray                 # (n,) object ids, ascending
    types: np.ndarray               # (n,) 1 sphere, 9 solid bond, 13 liquid bond, 14 wall
    fields: dict[int, np.ndarray]   # tag -> (T, n, k) values as written; nan where absent
    present: np.ndarray | None = None   # (T, n) the object has a `2 t` record at that time


@dataclass
class _Layout:
    """Where the tags of one time-point section sit: found once, reused for every line of
    the same length whose tags sit at the same places."""

    n: int
    tag_pos: np.ndarray
    tag_vals: np.ndarray
    time_idx: np.ndarray                          # (T,)
    fields: dict[int, np.ndarray]                 # tag -> (T, k) indices, -1 = absent in group


@dataclass
class TextScan:
    """A MUSEN text file as ``scan_text`` tokenised it: per object line (in file order) its line
    number, id, type, geometry numbers, material key, activity interval, time-point values and
    their tag layout; the scene lines as (line number, tag, tokens)."""
    path: Path
    lines: list[int] = field(default_factory=list)
    ids: list[int] = field(default_factory=list)
    types: list[int] = field(default_factory=list)
    geoms: list[list[float]] = field(default_factory=list)
    keys: list[str | None] = field(default_factory=list)
    acts: list[tuple[float, float] | None] = field(default_factory=list)
    vals: list[np.ndarray] = field(default_factory=list)
    layouts: list[_Layout | None] = field(default_factory=list)
    scene: list[tuple[int, int, list[str]]] = field(default_factory=list)  # (line, tag, tokens)


def _num(tok: list[str], i: int, path: Path, ln: int, what: str, allow_inf: bool = False) -> float:
    if i >= len(tok):
        raise InputError(path, ln, f"{what}: the line ends too early (truncated line?)")
    try:
        value = float(tok[i])
    except ValueError:
        raise InputError(path, ln, f"{what}: expected a number, got {tok[i]!r}") from None
    if math.isnan(value) or (math.isinf(value) and not allow_inf):
        raise InputError(path, ln, f"{what}: expected a finite number, got {tok[i]!r}")
    return value


def _int(tok: list[str], i: int, path: Path, ln: int, what: str) -> int:
    value = _num(tok, i, path, ln, what)
    if not math.isfinite(value) or value != int(value) or not 0 <= value < 2 ** 53:
        raise InputError(path, ln, f"{what}: expected a non-negative integer, got {tok[i]!r}")
    return int(value)


def _bool(tok: list[str], i: int, path: Path, ln: int, what: str) -> bool:
    if i >= len(tok):
        raise InputError(path, ln, f"{what}: the line ends too early (truncated line?)")
    if tok[i] not in ("0", "1"):
        raise InputError(path, ln, f"{what}: expected 0 or 1, got {tok[i]!r}")
    return tok[i] == "1"


def _is_tag(token: str) -> int | None:
    return int(token) if token.isdigit() else None


def _misplaced(tag: int, path: Path, ln: int, where: str) -> InputError:
    if tag in (2, 23, 24):
        return InputError(path, ln, f"`{tag}` {where}: an object line must begin "
                          "`0 ID 1 TYPE 5 GEOMETRY...` (MUSEN stops the import here)")
    if tag in TD_SIZE:
        return InputError(path, ln, f"per-time-point tag `{tag}` {where}: it must follow a "
                          "time point `2 T` on an object line")
    return InputError(path, ln, f"unknown tag `{tag}` {where}")


def _object_header(tok: list[str], path: Path, ln: int):
    """``0 ID 1 TYPE 5 GEOM [23 KEY] [24 T0 T1]`` -> (id, type, geom, key, act, td start)."""
    oid = _int(tok, 1, path, ln, "object id (`0 ID`)")
    for i, want in ((2, 1), (4, 5)):
        if i >= len(tok):
            raise InputError(path, ln, "truncated object line: it must begin "
                             "`0 ID 1 TYPE 5 GEOMETRY...`")
        tag = _is_tag(tok[i])
        if tag != want:
            if tag is None:
                raise InputError(path, ln, f"expected tag `{want}`, got {tok[i]!r}")
            raise _misplaced(tag, path, ln, f"where `{want}` is expected")
        if want == 1:
            typ = tok[3] if len(tok) > 3 else ""
            if typ not in ("1", "9", "13", "14"):
                raise InputError(path, ln, f"unknown object type {typ!r} (MUSEN knows 1 sphere, "
                                 "9 solid bond, 13 liquid bond, 14 triangular wall)")
    otype = int(tok[3])
    k = GEOMETRY_SIZE[otype]
    geom = [_num(tok, 5 + j, path, ln, f"{TYPE_NAMES[otype]} geometry (`5`) value {j + 1}")
            for j in range(k)]
    key, act, i = None, None, 5 + k
    while i < len(tok):
        tag = _is_tag(tok[i])
        if tag == 2:
            break
        if tag == 23:
            if i + 1 >= len(tok):
                raise InputError(path, ln, "`23` needs a material key (truncated line?)")
            key, i = tok[i + 1], i + 2
        elif tag == 24:
            act = (_num(tok, i + 1, path, ln, "activity start (`24`)"),
                   _num(tok, i + 2, path, ln, "activity end (`24`)", allow_inf=True))
            i += 3
        elif tag is None:
            hint = (" (a sphere needs `5 RADIUS CONTACT_RADIUS`, a bond `5 LEFT RIGHT DIAMETER "
                    "LENGTH`, a wall nothing after `5`)" if i == 5 + k else "")
            raise InputError(path, ln, f"expected a tag, got {tok[i]!r}{hint}")
        elif tag in (0, 1, 5):
            raise InputError(path, ln, f"tag `{tag}` twice on one object line (one object per "
                             "line; MUSEN would mix the objects up)")
        else:
            raise _misplaced(tag, path, ln, "before the first time point `2`")
    if not all(math.isfinite(g) for g in geom):
        raise InputError(path, ln, f"{TYPE_NAMES[otype]} geometry (`5`) values must be finite")
    if act is not None and (not math.isfinite(act[0]) or math.isnan(act[1]) or act[0] > act[1]):
        raise InputError(path, ln, f"activity interval `24 {act[0]:g} {act[1]:g}`: need a finite "
                         "start not after the end")
    return oid, otype, geom, key, act, i


def _td_tokens_slow(tok: list[str], start: int, path: Path, ln: int):
    """Time-point part that numpy could not convert in one go: find the bad token, or pull
    out `23`/`24` given after time points (MUSEN accepts that)."""
    out, key, act, i = [], None, None, start
    while i < len(tok):
        tag = _is_tag(tok[i])
        if tag == 23 and i + 1 < len(tok):
            key, i = tok[i + 1], i + 2
            continue
        if tag == 24:
            act = (_num(tok, i + 1, path, ln, "activity start (`24`)"),
                   _num(tok, i + 2, path, ln, "activity end (`24`)", allow_inf=True))
            i += 3
            continue
        size = TD_SIZE.get(tag) if tag is not None else None
        if size is None:
            raise InputError(path, ln, f"expected a per-time-point tag, got {tok[i]!r}")
        out.append(float(tag))
        out += [_num(tok, i + 1 + j, path, ln, f"`{tag}` value {j + 1}") for j in range(size)]
        i += 1 + size
    return np.array(out, dtype=np.float64), key, act


def _walk_layout(vals: np.ndarray, path: Path, ln: int) -> _Layout:
    groups: list[dict[int, int]] = []
    tag_pos: list[int] = []
    pos, n = 0, len(vals)
    prev = None
    while pos < n:
        v = float(vals[pos])
        tag = int(v) if v.is_integer() and 0 <= v < 100 else None
        size = TD_SIZE.get(tag) if tag is not None else None
        if size is None:
            hint = f" (is the `{prev}` before it short of values?)" if prev else ""
            raise InputError(path, ln, f"{v:g} is not a per-time-point tag{hint}")
        if pos + size >= n:
            raise InputError(path, ln, f"`{tag}` needs {size} value(s) but the line ends after "
                             f"{n - pos - 1} (truncated line?)")
        tag_pos.append(pos)
        if tag == 2:
            groups.append({2: pos + 1})
        else:
            groups[-1][tag] = pos + 1
        prev, pos = tag, pos + size + 1
    tags = sorted({t for g in groups for t in g} - {2})
    fields = {}
    for t in tags:
        idx = np.full((len(groups), TD_SIZE[t]), -1, np.int64)
        for gi, g in enumerate(groups):
            if t in g:
                idx[gi] = np.arange(g[t], g[t] + TD_SIZE[t])
        fields[t] = idx
    tag_pos_a = np.array(tag_pos, np.int64)
    return _Layout(n, tag_pos_a, vals[tag_pos_a].copy(),
                   np.array([g[2] for g in groups], np.int64), fields)


def _check_binary(path: Path) -> None:
    p = Path(path)
    if p.suffix.lower() == ".mdem":
        raise InputError(p, None, "this is a binary MUSEN .mdem file; export it as text with cmusen "
                         "(a job with COMPONENT EXPORT_TO_TEXT) or MUSEN's File > Export to text")
    try:
        with open(p, "rb") as fh:
            head = fh.read(4096)
    except OSError:
        return                              # read_text reports missing / unreadable files
    if b"\x00" in head and not head.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError(p, None, "binary file (a MUSEN .mdem?), expected a MUSEN text scene; "
                         "export it as text with cmusen COMPONENT EXPORT_TO_TEXT")


# The last scan of a text up to this size, reused while the text is the same: a job script
# reads its scene up to three times (planning, IMPORT_FROM_TEXT, the result's scene message).
# Keyed on the text itself (what read_text returns: `fibrelmp check` substitutes failing
# lines), not on the file's times.  A scan takes ~5x its text, so at most ~25 MB is held
# (through the run); larger texts are scanned each time.
_REUSE_BYTES = 4 << 20
_last_scan: tuple[tuple, str, TextScan] | None = None


def scan_text(path: Path, objects_only: bool = False) -> TextScan:
    """The one MUSEN text reader (scenes, results, ``.mdem`` text import): every line of
    ``path`` tokenised, malformed lines an InputError at their line; ``objects_only`` skips the
    scene lines.  The result is shared with later calls on the same text: read it only (its
    arrays are read-only)."""
    global _last_scan
    _check_binary(path)
    text = read_text(path, "MUSEN text file")
    key = (str(path), objects_only)
    last = _last_scan
    if last is not None and last[0] == key and last[1] == text:
        return last[2]
    scan = _scan_text(path, objects_only, text)
    if len(text) <= _REUSE_BYTES:
        for vals in scan.vals:
            vals.setflags(write=False)
        _last_scan = (key, text, scan)
    return scan


def _scan_text(path: Path, objects_only: bool, text: str) -> TextScan:
    if "\r" in text:                       # MUSEN's safeGetLine accepts \n, \r\n and \r
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    scan = TextScan(path)
    cache: dict[int, list[_Layout]] = {}
    any_line = False
    for ln, line in enumerate(text.split("\n"), 1):
        tok = line.split()
        if not tok:
            continue
        any_line = True
        if tok[0] != "0":
            if not objects_only:
                _scene_line(tok, path, ln, scan)
            elif _is_tag(tok[0]) is None:
                raise InputError(path, ln, f"expected a tag, got {tok[0]!r}")
            continue
        oid, otype, geom, key, act, start = _object_header(tok, path, ln)
        try:
            vals = np.array(tok[start:], dtype=np.float64)
        except ValueError:
            vals, key2, act2 = _td_tokens_slow(tok, start, path, ln)
            key, act = key2 or key, act2 or act
        if not np.isfinite(vals).all():
            bad = int(np.flatnonzero(~np.isfinite(vals))[0])
            raise InputError(path, ln, f"time-point value {bad + 1} is {vals[bad]} (values must be "
                             "finite)")
        layout = None
        if len(vals):
            for cand in cache.get(len(vals), ()):
                if np.array_equal(vals[cand.tag_pos], cand.tag_vals):
                    layout = cand
                    break
            else:
                layout = _walk_layout(vals, path, ln)
                cache.setdefault(len(vals), []).append(layout)
        scan.lines.append(ln)
        scan.ids.append(oid)
        scan.types.append(otype)
        scan.geoms.append(geom)
        scan.keys.append(key)
        scan.acts.append(act)
        scan.vals.append(vals)
        scan.layouts.append(layout)
    if not any_line:
        raise InputError(path, 1, "empty MUSEN text file")
    return scan


def _scene_line(tok: list[str], path: Path, ln: int, scan: TextScan) -> None:
    """Scene lines (22..41).  Lines 32/33/34/38..41 take the rest of the line."""
    i = 0
    while i < len(tok):
        tag = _is_tag(tok[i])
        if tag is None:
            raise InputError(path, ln, f"expected a tag, got {tok[i]!r} (MUSEN text files have "
                             "no comments)")
        if tag not in SCENE_TAGS:
            raise _misplaced(tag, path, ln, "outside an object line" if i == 0 else
                             "after scene data")
        if tag in (32, 33, 34, 38, 39, 40, 41):
            scan.scene.append((ln, tag, tok[i + 1:]))
            return
        if tag == 25:
            size = 7 if len(tok) > i + 7 and tok[i + 7] in ("0", "1") else 6
        elif tag == 26:
            mtype = tok[i + 1] if len(tok) > i + 1 else ""
            if mtype == "0":                     # "26 0 0" now, "26 0" in old files
                size = 2 if len(tok) > i + 2 and tok[i + 2] == "0" else 1
            else:
                size = 2 + 11 * _int(tok, i + 2, path, ln, "`26` number of motion intervals")
        elif tag == 27:
            size = 1 + _int(tok, i + 1, path, ln, "`27` number of walls")
        else:
            size = {22: 6, 28: 10, 29: 1, 30: 1}[tag]
        if i + size > len(tok) - 1:
            raise InputError(path, ln, f"`{tag}` needs {size} value(s), the line has "
                             f"{len(tok) - i - 1} (truncated line?)")
        scan.scene.append((ln, tag, tok[i + 1: i + 1 + size]))
        i += 1 + size


# --------------------------------------------------------------------------- states

def _musen_interp(times: np.ndarray, y: np.ndarray, t: float) -> np.ndarray:
    """MUSEN's InterpolatedValue (MUSENVectorFunctions.h), extrapolating outside the range."""
    if len(times) == 0:
        return np.zeros(y.shape[1:])
    if len(times) == 1:
        return y[0]
    ir = 1
    while ir < len(times) - 1 and times[ir] <= t:
        ir += 1
    if times[ir] == times[ir - 1]:
        return y[ir]
    il = ir - 1
    return y[il] + (t - times[il]) * (y[ir] - y[il]) / (times[ir] - times[il])


def _state(scan: TextScan, rows: np.ndarray, tags: tuple[int, ...], t: float,
           warn: list[str]) -> dict[int, np.ndarray]:
    """Values of ``tags`` at time ``t`` for object ``rows`` (nan where an object's time point
    lacks the tag); rows sharing a layout are handled as one stacked array."""
    out = {tag: np.full((len(rows), TD_SIZE[tag]), np.nan) for tag in tags}
    groups: dict[int, list[int]] = {}
    for j, r in enumerate(rows):
        lay = scan.layouts[r]
        groups.setdefault(id(lay) if lay is not None else 0, []).append(j)
    for members in groups.values():
        members_a = np.array(members)
        lay = scan.layouts[rows[members[0]]]
        if lay is None:                     # no time point at all
            continue
        stack = np.stack([scan.vals[rows[j]] for j in members])
        stack = np.hstack([stack, np.full((len(members), 1), np.nan)])   # index -1 -> nan
        times = stack[:, lay.time_idx]
        last_ok = times[:, -1] == t
        for tag in tags:
            if tag not in lay.fields:
                continue
            out[tag][members_a[last_ok]] = stack[last_ok][:, lay.fields[tag][-1]]
        for j in np.flatnonzero(~last_ok):   # objects lacking the last time point (rare)
            warn.append(str(scan.ids[rows[members[j]]]))
            for tag in tags:
                if tag in lay.fields:
                    series = stack[j][lay.fields[tag]]
                    out[tag][members[j]] = _musen_interp(times[j], series, t)
    return out


def _fill(a: np.ndarray, default) -> np.ndarray:
    a = a.copy()
    bad = np.isnan(a).any(axis=1)
    a[bad] = default
    return a


def check_duplicate_ids(scan: TextScan, ids: np.ndarray, path: Path) -> None:
    """An InputError at the second line of an id used twice."""
    order = np.argsort(ids, kind="stable")
    dup = np.flatnonzero(np.diff(ids[order]) == 0)
    if len(dup):
        first, second = order[dup[0]], order[dup[0] + 1]
        raise InputError(path, scan.lines[second], f"object id {ids[second]} is already used on "
                         f"line {scan.lines[first]} (MUSEN would keep the first object and drop "
                         "this one's data); ids are unique across spheres, bonds and walls")


def read_time_points(path: str | Path, types: tuple[int, ...] | None = None,
                     tags: tuple[int, ...] | None = None) -> TimePoints:
    """Every saved time point of a MUSEN text file, as written (no defaults filled in).

    ``types``/``tags`` limit what is returned (memory: T x n x k floats per tag)."""
    path = Path(path)
    return time_points_of(scan_text(path, objects_only=True), types, tags)


def time_points_of(scan: TextScan, types: tuple[int, ...] | None = None,
                   tags: tuple[int, ...] | None = None) -> TimePoints:
    """``read_time_points`` of a scanned file."""
    path = scan.path
    ids = np.array(scan.ids, np.int64)
    otypes = np.array(scan.types, np.int64)
    check_duplicate_ids(scan, ids, path)
    keep = np.ones(len(ids), bool) if types is None else np.isin(otypes, types)
    rows = np.flatnonzero(keep)
    rows = rows[np.argsort(ids[rows], kind="stable")]
    pos_of_row = np.full(len(ids), -1, np.int64)
    pos_of_row[rows] = np.arange(len(rows))
    groups: dict[int, list[int]] = {}
    for r in rows:
        if scan.layouts[r] is not None:
            groups.setdefault(id(scan.layouts[r]), []).append(int(r))
    stacks = []
    all_times = []
    for members in groups.values():
        lay = scan.layouts[members[0]]
        stack = np.stack([scan.vals[r] for r in members])
        stack = np.hstack([stack, np.full((len(members), 1), np.nan)])
        stacks.append((np.array(members), lay, stack))
        all_times.append(np.unique(stack[:, lay.time_idx]))
    times = np.unique(np.concatenate(all_times)) if all_times else np.zeros(0)
    wanted = set(tags) if tags is not None else {t for _, lay, _ in stacks for t in lay.fields}
    fields = {t: np.full((len(times), len(rows), TD_SIZE[t]), np.nan) for t in sorted(wanted)}
    present = np.zeros((len(times), len(rows)), bool)
    for members, lay, stack in stacks:
        tidx = np.searchsorted(times, stack[:, lay.time_idx])           # (m, T_lay)
        obj = np.broadcast_to(pos_of_row[members][:, None], tidx.shape)
        present[tidx, obj] = True
        for t in wanted & set(lay.fields):
            fields[t][tidx, obj] = stack[:, lay.fields[t]]
    return TimePoints(times=times, ids=ids[rows], types=otypes[rows], fields=fields,
                      present=present)
