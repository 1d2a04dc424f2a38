"""The time history ``fibrelmp plot`` draws: LAMMPS's thermo from the run's log, else what the
result files themselves tell (kinetic energy from masses and velocities, particle counts,
bonds whose activity ended).  ``History.source`` says which."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.pictures.locate import LOG, LOG_NAME, WORK, Located, run_folder
from fibrelmp.pictures.sources import open_source

# thermo keywords (LAMMPS's header names) -> the panel they go to
_ENERGY_KEYWORDS = {"ke", "pe", "etotal", "enthalpy", "evdwl", "ecoul", "epair", "ebond", "eangle",
                    "edihed", "eimp", "emol", "elong", "etail", "ecouple", "econserve"}
_COUNT_WORDS = ("atoms", "spheres", "beads", "contact", "bond", "spring", "broken", "lost",
                "removed", "particles", "count")
_SKIP = {"Step", "Time", "Elapsed", "CPU", "Dt", "T/CPU", "S/CPU", "CPULeft", "Elaplong", "TimeStep"}
_TIME_UNITS = {"si": "s", "lj": "τ", "real": "fs", "metal": "ps", "cgs": "s", "micro": "µs",
               "nano": "ns", "electron": "fs"}
_ENERGY_UNITS = {"si": "J", "lj": "ε", "real": "kcal/mol", "metal": "eV", "cgs": "erg",
                 "micro": "pg·µm²/µs²", "nano": "ag·nm²/ns²", "electron": "Ha"}


@dataclass
class History:
    """Series over one axis (simulated time, else step), grouped into panels."""

    source: str                                  # "thermo of <log>" / "<result> (...)"
    path: Path                                   # the file the numbers come from
    x_name: str                                  # "time" / "step" / a thermo column
    x: np.ndarray
    series: dict[str, np.ndarray] = field(default_factory=dict)
    panels: dict[str, list[str]] = field(default_factory=dict)    # title -> series names
    x_unit: str = ""
    notes: list[str] = field(default_factory=list)


def panel_of(name: str) -> str:
    """"energy", "counts", "temperature" (a MUSEN heat model's sphere temperatures, not
    LAMMPS's kinetic ``Temp``), or the column's own panel (other quantities have other units)."""
    low = name.lower()
    bare = low[2:] if low[:2] in ("c_", "v_", "f_") else low
    if bare.startswith("temperature"):
        return "temperature"
    if bare in _ENERGY_KEYWORDS or bare.endswith("eng") or bare.startswith("e_") or "energy" in bare:
        return "energy"
    if any(w in bare for w in _COUNT_WORDS):
        return "counts"
    return name


def from_log(log: Path, notes: list[str] | None = None) -> History:
    """LAMMPS's thermo table of ``log``: every column over Time (else Step)."""
    from fibrelmp.pictures.thermo import read_thermo

    thermo = read_thermo(log)
    cols = thermo.columns
    x_name = "Time" if "Time" in cols else "Step"
    hist = History(f"LAMMPS thermo of {log}", log, x_name, cols[x_name], notes=list(notes or []))
    for name, values in cols.items():
        if name in _SKIP or not np.isfinite(values).any():
            continue
        hist.series[name] = values
        hist.panels.setdefault(panel_of(name), []).append(name)
    if not hist.series:
        raise InputError(log, None, f"the thermo table has only {', '.join(cols)}: nothing to plot "
                         "over time")
    units = _units(log, thermo.units)
    if x_name == "Time":
        hist.x_unit = _TIME_UNITS.get(units or "", "")
    energy = _ENERGY_UNITS.get(units or "")
    if "energy" in hist.panels:
        title = "energy per atom" if thermo.per_atom else "energy"
        hist.panels[f"{title} [{energy}]" if energy else title] = hist.panels.pop("energy")
    if "temperature" in hist.panels and units == "si":
        hist.panels["temperature [K]"] = hist.panels.pop("temperature")
    hist.panels = dict(sorted(hist.panels.items(), key=lambda kv: _panel_rank(kv[0])))
    return hist


def _panel_rank(title: str) -> int:
    return 0 if title.startswith("energy") else 1 if title == "counts" else 2


def _units(log: Path, logged: str | None) -> str | None:
    """The log's unit system, unless the job beside it says its input is dimensionless
    (a DEMDF job runs in LAMMPS's si units, but its numbers have none)."""
    from fibrelmp.registry import formats

    script = log.with_name("in.lammps")
    try:
        with open(script, encoding="utf-8", errors="replace") as fh:
            first = fh.readline()
    except OSError:
        return logged
    hit = re.search(r"written by fibrelmp from .*\((\S+)\)\s*$", first)
    named = {f.name: f.units for f in formats()}
    if hit and named.get(hit.group(1)) == "dimensionless":
        return None
    return logged


def from_result(located: Located, notes: list[str] | None = None) -> History:
    """What the result's frames give: kinetic energy (Σ ½ m v², where masses and
    velocities are known), the number of particles, and bonds ended by each frame's time."""
    source = open_source(located)
    times, steps, kinetic, particles, broken = [], [], [], [], []
    temperature: list[tuple[float, float, float]] = []      # min, mean, max of each frame
    for frame in source.frames():
        times.append(np.nan if frame.time is None else frame.time)
        steps.append(np.nan if frame.step is None else frame.step)
        particles.append(frame.count)
        if frame.velocity is not None and frame.mass is not None:
            kinetic.append(0.5 * float(np.sum(frame.mass * np.einsum("ij,ij->i", frame.velocity,
                                                                      frame.velocity))))
        if frame.broken_bonds is not None:
            broken.append(frame.broken_bonds)
        if frame.temperature is not None:
            t = frame.temperature
            temperature.append((float(t.min()), float(t.mean()), float(t.max())) if len(t)
                               else (np.nan, np.nan, np.nan))
    if not times:
        raise InputError(located.path, None, f"the {source.what} has no frames")
    t = np.asarray(times)
    use_time = np.isfinite(t).all()
    hist = History(f"the frames of {located.path}", located.path, "time" if use_time else "step",
                   t if use_time else np.asarray(steps, float),
                   x_unit=source.time_unit if use_time else "",
                   notes=list(notes or []) + source.notes)
    if len(kinetic) == len(times):
        name = "kinetic energy Σ½mv²"
        hist.series[name] = np.asarray(kinetic)
        unit = f" [{source.energy_unit}]" if source.energy_unit else ""
        hist.panels[f"energy{unit}"] = [name]
    else:
        hist.notes.append("no kinetic energy: the result has no velocities or masses")
    hist.series["particles"] = np.asarray(particles, float)
    hist.panels["counts"] = ["particles"]
    if len(broken) == len(times):
        hist.series["bonds broken (activity ended)"] = np.asarray(broken, float)
        hist.panels["counts"].append("bonds broken (activity ended)")
    # a heat model's temperatures (a MUSEN result without one writes 0 for every sphere)
    values = np.asarray(temperature, float).reshape(-1, 3)
    if len(temperature) == len(times) and np.nan_to_num(values).any():
        title = "temperature [K]" if source.energy_unit == "J" else "temperature"
        hist.panels[title] = []
        for k, name in enumerate(("temperature min", "temperature mean", "temperature max")):
            hist.series[name] = values[:, k]
            hist.panels[title].append(name)
    return hist


def history(located: Located, prefer: str = "auto") -> History:
    """The history of any result: ``prefer`` "log" (LAMMPS's thermo; an error without a
    log), "result" (the result's frames) or "auto" (the log when one is found)."""
    if located.kind == LOG:
        if prefer == "result":
            raise InputError(located.path, None, "a log has no frames: --source result needs a "
                             "result file or a work folder")
        return from_log(located.path)
    if located.kind == WORK:
        log = located.path / LOG_NAME
        if prefer != "result" and log.is_file():
            return from_log(log)
        if prefer == "log":
            raise InputError(located.path, None, f"this work folder has no {LOG_NAME}")
        return from_result(located, [f"no {LOG_NAME} in {located.path}: from its frames"])
    if prefer == "result":
        return from_result(located)
    folder, how = run_folder(located.path)
    log = folder / LOG_NAME if folder is not None else None
    if log is not None and log.is_file():
        return from_log(log, [f"log of {how}"])
    why = how if folder is None else f"{folder} has no {LOG_NAME}"
    if prefer == "log":
        raise InputError(located.path, None, f"no LAMMPS log for this result: {why}")
    return from_result(located, [f"no LAMMPS log ({why}): from the result's frames"])
