"""``fibrelmp post --info``: what a dump holds, read from its ITEM lines only (no atom parsing)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fibrelmp.post.lammps_dump.reader import iter_headers

POSITION_KINDS = (("x y z", ("x", "y", "z")), ("scaled xs ys zs", ("xs", "ys", "zs")),
                  ("unwrapped xu yu zu", ("xu", "yu", "zu")),
                  ("scaled unwrapped xsu ysu zsu", ("xsu", "ysu", "zsu")))


def _range(values: list, fmt: str = "{}") -> str:
    lo, hi = min(values), max(values)
    return fmt.format(lo) if lo == hi else f"{fmt.format(lo)} .. {fmt.format(hi)}"


def describe_dump(path: Path, warnings: list[tuple[str, str]]) -> list[str]:
    steps, counts, times, boxes, columns, kinds = [], [], [], [], [], set()
    first = None
    for head, _ in iter_headers(path, warnings, want=lambda i, h: False):
        first = first or head
        steps.append(head.step)
        counts.append(head.count)
        if head.time is not None:
            times.append(head.time)
        boxes.append(np.concatenate([head.lo, head.hi, head.tilt if head.tilt is not None else np.zeros(3)]))
        if head.names not in columns:
            columns.append(head.names)
        kinds.add(head.kind)
    size = path.stat().st_size
    out = [f"file       {path} ({size / 1e6:.1f} MB{', gzip' if _gz(path) else ''}, LAMMPS text dump"
           f"{', local entries' if kinds == {'ENTRIES'} else ''})"]
    if first is None:
        out.append("frames     0 complete frames")
        return out
    inc = np.unique(np.diff(steps)) if len(steps) > 1 else np.array([])
    every = f", every {int(inc[0])}" if len(inc) == 1 else (", irregular steps" if len(inc) else "")
    out.append(f"frames     {len(steps)} (steps {steps[0]} .. {steps[-1]}{every})")
    what = "entries" if kinds == {"ENTRIES"} else "atoms"
    out.append(f"{what:<10s} {_range(counts)}{' (changes between frames)' if len(set(counts)) > 1 else ''}")
    for k, names in enumerate(columns):
        label = "columns" if k == 0 else "columns'"
        out.append(f"{label:<10s} {' '.join(names)}")
    names = set(columns[0])
    pos = [label for label, cols in POSITION_KINDS if names.issuperset(cols)]
    if {"ix", "iy", "iz"} <= names:
        pos.append("image flags (unwrapped positions derivable)")
    if kinds == {"ATOMS"}:
        out.append(f"positions  {', '.join(pos) if pos else 'none'}")
    b = np.array(boxes)
    tri = first.tilt is not None
    box = " x ".join(f"[{first.lo[k]:g}, {first.hi[k]:g}]" for k in range(3))
    if tri:
        box += f", tilt xy xz yz {first.tilt[0]:g} {first.tilt[1]:g} {first.tilt[2]:g}"
    changes = " (changes between frames)" if np.any(b != b[0]) else ""
    out.append(f"box        {'triclinic' if tri else 'orthogonal'} {' '.join(first.boundary)}: {box}{changes}")
    if times:
        out.append(f"time       {_range(times, '{:g}')} (ITEM: TIME)")
    else:
        out.append("time       not in the dump (no ITEM: TIME); conversions use step numbers as times")
    if first.units:
        out.append(f"units      {first.units}")
    return out


def _gz(path: Path) -> bool:
    with open(path, "rb") as fh:
        return fh.read(2) == b"\x1f\x8b"
