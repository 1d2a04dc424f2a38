"""Convert LAMMPS dump frames into FibreNet's own output files."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np

from fibrelmp.translate.fibrenet.writer import RESTART_SUFFIX, XYZ_SUFFIX, XyzWriter, write_restart
from fibrelmp.post.lammps_dump.reader import Frame

# dump column names for the velocity FibreNet writes (v~) and its total force
VEL_COLUMNS = ("v_fn_vx", "v_fn_vy", "v_fn_vz")
FORCE_COLUMNS = ("v_fn_fx", "v_fn_fy", "v_fn_fz")
OUTSIDE_KIND = "beads outside finite box"


class FibreNetDivergenceWarning(UserWarning):
    """The run has left the regime where fibrelmp reproduces FibreNet (see docs/fibrenet.md)."""


def outside_finite_box(wrapped: np.ndarray, periodic: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Per bead: is its centre outside FibreNet's grid [0, L) on a finite (walled) axis?

    FibreNet's FillGrid (kernel.cl) puts a bead in cell floor(x / cell) and drops it when that
    cell is outside 0 .. n-1, i.e. when x < 0 or x >= L: such a bead has no pair contacts."""
    fin = ~np.asarray(periodic, bool)
    if not fin.any() or not len(wrapped):
        return np.zeros(len(wrapped), bool)
    x = wrapped[:, fin]
    return ((x < 0) | (x >= np.asarray(lengths, float)[fin])).any(axis=1)


def outside_message(step: int, count: int, lengths: np.ndarray) -> str:
    return (f"from the frame at step {step} on ({count} bead(s) then), bead centres lie outside the "
            f"finite box [0, L) (L = {' x '.join(f'{v:g}' for v in lengths)}), i.e. pressed into a "
            "wall: FibreNet drops such beads from its contact grid, so they lose every hs/st/lj "
            "pair contact, while LAMMPS keeps them; results diverge from FibreNet's from there on")


def _pick(frame: Frame, preferred: Sequence[str], fallback: Sequence[str]) -> np.ndarray:
    names = preferred if preferred[0] in frame.columns else fallback
    return np.column_stack([frame.column(c) for c in names])


def wrapped_and_unwrapped(frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """Positions wrapped into [lo, hi) on periodic axes, and unwrapped positions."""
    lengths = frame.hi - frame.lo
    if "x" in frame.columns:
        x = np.column_stack([frame.column(c) for c in "xyz"])
        if "ix" in frame.columns:
            img = np.column_stack([frame.column(c) for c in ("ix", "iy", "iz")])
            unwrapped = x + img * lengths
        else:
            unwrapped = x.copy()
    else:
        unwrapped = np.column_stack([frame.column(c) for c in ("xu", "yu", "zu")])
        x = unwrapped
    wrapped = x.copy()
    per = frame.periodic
    wrapped[:, per] = frame.lo[per] + np.mod(unwrapped[:, per] - frame.lo[per], lengths[per])
    return wrapped, unwrapped


def type_codes(types: np.ndarray, names_of_type: dict[int, str]) -> tuple[np.ndarray, list[str]]:
    """Per-atom index into a small table of type names (no per-atom Python code)."""
    t = np.asarray(types).astype(np.int64)
    if t.size == 0:
        return np.zeros(0, np.int64), []
    uniq, codes = np.unique(t, return_inverse=True) if int(t.max()) - int(t.min()) > 1 << 20 else \
        _small_unique(t)
    return codes.ravel(), [names_of_type[int(u)] for u in uniq]


def _small_unique(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    lo = int(t.min())
    present = np.zeros(int(t.max()) - lo + 1, bool)
    present[t - lo] = True
    remap = np.cumsum(present) - 1
    return np.flatnonzero(present) + lo, remap[t - lo]


def write_fibrenet(frames: Iterable[Frame], basename: str, folder: Path, fields: Sequence[str],
                   names_of_type: dict[int, str], dt: float, box_lengths: np.ndarray | None,
                   output_types: set[str] | None, restart: bool = True,
                   warn: Callable[[str, str], None] | None = None) -> list[Path]:
    """Write ``<basename>_coord/_vel/_force.xyz`` (every frame) and ``_restart.res`` (last).

    ``box_lengths`` None: each frame's own box (post-processing of dumps whose box changes).

    With ``box_lengths`` (FibreNet's box [0, L]) the first frame with a bead centre outside
    [0, L) on a finite axis triggers one warning (``outside_message``): ``warn(kind, text)``
    when given (e.g. ``model.warn``), otherwise a ``FibreNetDivergenceWarning`` through Python's
    ``warnings`` module (printed on stderr by default).
    """
    folder = Path(folder)
    writers = {f: XyzWriter(folder / f"{basename}{XYZ_SUFFIX[f]}") for f in fields}
    last = None
    warned = box_lengths is None
    try:
        for frame in frames:
            ids = frame.column("id")
            # dumps written with "modify sort id" need no reordering (saves a sort per frame)
            order = slice(None) if bool(np.all(ids[1:] > ids[:-1])) else np.argsort(ids, kind="stable")
            codes, table = type_codes(frame.column("type")[order], names_of_type)
            keep = slice(None) if output_types is None else \
                np.isin(codes, [k for k, name in enumerate(table) if name in output_types])
            wrapped, unwrapped = wrapped_and_unwrapped(frame)
            if not warned:
                out = outside_finite_box(wrapped, frame.periodic, box_lengths)
                if out.any():
                    warned = True
                    text = outside_message(frame.step, int(out.sum()), np.asarray(box_lengths, float))
                    if warn is not None:
                        warn(OUTSIDE_KIND, text)
                    else:
                        warnings.warn(f"[{OUTSIDE_KIND}] {text}", FibreNetDivergenceWarning, stacklevel=2)
            data = {"position": wrapped[order]}
            if "velocity" in fields or restart:
                data["velocity"] = _pick(frame, VEL_COLUMNS, ("vx", "vy", "vz"))[order]
            if "force" in fields or restart:
                data["force"] = _pick(frame, FORCE_COLUMNS, ("fx", "fy", "fz"))[order]
            lengths = box_lengths if box_lengths is not None else frame.hi - frame.lo
            for f, w in writers.items():
                w.write_codes(frame.step, dt, lengths, codes[keep], table, data[f][keep])
            last = (frame.step, (codes, table), data["position"], unwrapped[order], data.get("velocity"),
                    data.get("force"), lengths)
    except BaseException:
        for w in writers.values():
            w.abort()
        raise
    pending = list(writers.values())
    try:
        while pending:
            pending[0].close()
            pending.pop(0)
    except BaseException:            # e.g. a full disk: no temp file of the others stays
        for w in pending[1:]:
            w.abort()
        raise
    written = [w.path for w in writers.values()]
    if restart and last is not None:
        path = folder / f"{basename}{RESTART_SUFFIX}"
        step, (codes, table), x, xu, v, f, lengths = last
        names = np.array(table, dtype=object)[codes]
        write_restart(path, step, dt, lengths, names, x, xu, v, f)
        written.append(path)
    return written
