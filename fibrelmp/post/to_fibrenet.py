"""Convert LAMMPS dump frames into FibreNet's own output files."""

from __future__ import annotations

from pathlib import Path
from typing import Iterable, Sequence

import numpy as np

from .fibrenet_out import RESTART_SUFFIX, XYZ_SUFFIX, XyzWriter, write_restart
from .lammps_dump import Frame

# dump column names for the velocity FibreNet writes (v~) and its total force
VEL_COLUMNS = ("v_fn_vx", "v_fn_vy", "v_fn_vz")
FORCE_COLUMNS = ("v_fn_fx", "v_fn_fy", "v_fn_fz")


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


def write_fibrenet(frames: Iterable[Frame], basename: str, folder: Path, fields: Sequence[str],
                   names_of_type: dict[int, str], dt: float, box_lengths: np.ndarray,
                   output_types: set[str] | None, restart: bool = True) -> list[Path]:
    """Write ``<basename>_coord/_vel/_force.xyz`` (every frame) and ``_restart.res`` (last)."""
    folder = Path(folder)
    writers = {f: XyzWriter(folder / f"{basename}{XYZ_SUFFIX[f]}") for f in fields}
    last = None
    try:
        for frame in frames:
            order = np.argsort(frame.column("id"), kind="stable")
            names = np.array([names_of_type[int(t)] for t in frame.column("type")[order]], dtype=object)
            keep = np.ones(len(order), bool) if output_types is None else np.isin(names, list(output_types))
            wrapped, unwrapped = wrapped_and_unwrapped(frame)
            data = {"position": wrapped[order]}
            if "velocity" in fields or restart:
                data["velocity"] = _pick(frame, VEL_COLUMNS, ("vx", "vy", "vz"))[order]
            if "force" in fields or restart:
                data["force"] = _pick(frame, FORCE_COLUMNS, ("fx", "fy", "fz"))[order]
            for f, w in writers.items():
                w.write(frame.step, dt, box_lengths, names[keep], data[f][keep])
            last = (frame.step, names, data["position"], unwrapped[order], data.get("velocity"),
                    data.get("force"))
    except BaseException:
        for w in writers.values():
            w.abort()
        raise
    for w in writers.values():
        w.close()
    written = [w.path for w in writers.values()]
    if restart and last is not None:
        path = folder / f"{basename}{RESTART_SUFFIX}"
        step, names, x, xu, v, f = last
        write_restart(path, step, dt, box_lengths, names, x, xu, v, f)
        written.append(path)
    return written
