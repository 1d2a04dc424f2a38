"""The record of a run: LAMMPS's own log (``log.lammps``, thermo output), the summary of each
simulation (``summary.json`` beside it, and the block ``fibrelmp run`` prints at the end).

Where each number comes from (docs/record.md lists every field):

* energies, contacts: LAMMPS's thermo output (the templates define the columns): the first
  line of the first run that advances the step (read back from ``log.lammps``, 8 digits as
  printed) and the last line of the run (``lammps.last_thermo()``, full precision);
* spheres and bonds at the end, spheres removed at their activity end or by leaving the
  domain: the frames as the result files have them (``FrameBuilder.tally``: LAMMPS drops a
  sphere beyond an 'f' face only at its next re-neighbouring, the frames at once);
* broken bonds: the job's breaks file (one line per break, written by LAMMPS) or, for
  FibreNet's breakable springs, the springs LAMMPS holds against the model's;
* largest overlap, largest spring strain: LAMMPS's final state, gathered once after the last
  command (``Recorder.end``; spheres beyond the domain left out, as in the frames);
* time step check: ``fibrelmp.sanity`` (what ``check`` prints).

MPI: the runner calls the ``Recorder`` hooks on every rank (``end`` gathers, a collective);
only rank 0 reads the log and writes the summary.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator

import numpy as np

if TYPE_CHECKING:
    from fibrelmp.particles import ParticleModel

LOG_NAME = "log.lammps"
SUMMARY_NAME = "summary.json"
SUMMARY_VERSION = 1
# thermo columns (templates/*.j2) -> summary energy names
# (granular runs: KinGravEng = kinetic + rotational + gravity's, no contact or bond energy)
ENERGY_COLUMNS = {"KinEng": "kinetic", "RotEng": "rotational", "PotEng": "potential", "TotEng": "total",
                  "KinGravEng": "kinetic_plus_gravity"}


# ---------------------------------------------------------------------------------------
# log.lammps
def thermo_blocks(log: str | Path) -> Iterator[list[dict[str, float]]]:
    """The thermo output of a LAMMPS log, one list of rows per ``run`` that printed any (LAMMPS
    prints a header and the run's first step at every ``run``, its last step, and every
    ``thermo N`` steps in between), streamed: one block in memory (``lammps_log.ThermoLog``:
    warnings between rows are skipped, a log cut short keeps its last rows)."""
    from fibrelmp.lammps_log import ThermoLog

    for block in ThermoLog(log).blocks():
        if block.rows:
            yield [dict(zip(block.header, values)) for values in block.rows]


def thermo(log: str | Path) -> Iterator[dict[str, float]]:
    """Every thermo row of a log once per step, in order: where consecutive rows share a
    step (the end of one run and the start of the next, or a FibreNet step prepared by
    commands before its run) the later one is kept.  Steps restart at 0 where the job resets
    them (after FibreNet's relaxation stage)."""
    pending: dict[str, float] | None = None
    for rows in thermo_blocks(log):
        for row in rows:
            if pending is not None and row.get("Step") != pending.get("Step"):
                yield pending
            pending = row
    if pending is not None:
        yield pending


def first_state(log: str | Path) -> dict[str, float] | None:
    """The first line of the first run that advances the step (a ``run 0`` block has one
    line: FibreNet's first step is prepared by a ``run 0`` whose velocities are not yet the
    step's); the log's first line when no run advanced."""
    first = None
    for rows in thermo_blocks(log):
        if first is None:
            first = rows[0]
        if len(rows) > 1:
            return rows[0]
    return first


def column_names(script: str) -> dict[str, str]:
    """The thermo columns a script renames (``thermo_modify ... colname KEYWORD NAME``):
    ``lammps.last_thermo()`` names them by keyword, the log by name."""
    names: dict[str, str] = {}
    for line in script.splitlines():
        words = line.split("#", 1)[0].split()
        if words[:1] == ["thermo_modify"]:
            for k, word in enumerate(words[:-2]):
                if word == "colname":
                    names[words[k + 1]] = words[k + 2]
    return names


# ---------------------------------------------------------------------------------------
# during the run
class Recorder:
    """What the summary needs from the running LAMMPS (hooks called by ``runner.run_script``
    on every rank) and the summary itself (rank 0)."""

    def __init__(self, model: "ParticleModel", job: Any, script: str = ""):
        self.model, self.job = model, job
        self.colnames = column_names(script)
        self.steps = self.resumed = 0
        self.last: dict | None = None           # lammps.last_thermo() after the last command
        self.final: dict = {}                    # figures of the final state (end())

    def end(self, lmp, steps: int, resumed: int) -> None:
        """After the last command, on every rank (the gathers are collective); the model
        says what it gathers and which figures its final state gives."""
        from fibrelmp.runner import mpi_rank_size

        self.steps, self.resumed = steps, resumed
        last = lmp.last_thermo()
        self.last = None if last is None else {self.colnames.get(k, k): v for k, v in last.items()}
        self.final["step"] = int(lmp.extract_global("ntimestep"))
        lo, hi, _, _, _, periodic, _ = lmp.extract_box()
        box = (np.array(lo, float), np.array(hi, float), np.array(periodic, bool))
        ids = gather_atoms(lmp, "id", 0, 1).astype(np.int64)
        x = gather_atoms(lmp, "x", 1, 3).reshape(-1, 3)
        gathered = self.model.final_gather(lmp)
        if mpi_rank_size()[0] != 0:                # the summary is rank 0's
            return
        self.final.update(self.model.final_figures(self.job, ids, x, box, gathered))

    # ---- rank 0, after LAMMPS closed (the log is complete)
    def summary(self, rendered: Any, wall_time: float, warnings: list[tuple[str, str]],
                tally: dict | None = None) -> dict:
        """The summary (docs/record.md); ``tally``: the frame source's counts of spheres and
        bonds at the last frame (``FrameBuilder.tally()``)."""
        from fibrelmp.sanity import STEP_FRACTION, time_step_scale
        from fibrelmp.units import system

        model, job = self.model, self.job
        folder = Path(rendered.folder)
        log = folder / LOG_NAME
        start = first_state(log) if log.exists() else None
        dt = model.run_time_step(job)
        session = self.steps - self.resumed
        out: dict[str, Any] = {
            "summary_version": SUMMARY_VERSION,
            "input": str(model.source),
            "kind": model.kind,
            "units": system(model.units).name,
            "folder": str(folder),
            "log": LOG_NAME if log.exists() else None,
            "steps": {"total": self.steps, "this_session": session, "resumed_from": self.resumed},
            "time_step": dt,
            "time": {"start": _num(start, "Time"), "end": _num(self.last, "Time")},
            "wall_time": wall_time,
            "steps_per_second": session / wall_time if wall_time > 0 else None,
            "frames": _count(rendered.schedule),
            "energy": {"start": _energies(start), "end": _energies(self.last)},
        }
        out.update(model.summary_figures(job, self.final, self.last, tally))
        clock = getattr(job, "clock", None)
        if clock is not None and start is not None and self.last is not None:
            # MUSEN's summed time, as its results write it (LAMMPS's Time is step * dt)
            out["time"] = {"start": clock.time(thermo_int(start, "Step")),
                           "end": clock.time(thermo_int(self.last, "Step"))}
        variable = getattr(job, "variable_clock", None)
        if variable is not None and variable.exists():
            # a variable time step: MUSEN's time of the last frame, as fix musen/leapfrog wrote
            # it (a run the fix stopped printed no thermo line at its last step)
            last = variable.read_text(encoding="ascii").split("\n")[-2].split()
            out["time"]["end"] = float(last[1])
        out["final_step"] = self.final["step"]
        scale = time_step_scale(model)
        if scale is not None:
            scale["steps_per"] = scale["value"] / dt
            scale["limit"] = 1 / STEP_FRACTION
            scale["ok"] = dt <= STEP_FRACTION * scale["value"]
        out["time_step_check"] = scale
        out["warnings"] = warning_counts(warnings)
        return out


def warning_counts(warnings: list[tuple[str, str]]) -> dict[str, int]:
    """``{kind: count}`` of a run's warnings, in the order they came (every summary's field)."""
    kinds: dict[str, int] = {}
    for kind, _ in warnings:
        kinds[kind] = kinds.get(kind, 0) + 1
    return kinds


def write_summary(folder: Path, summary: dict) -> Path:
    """``summary.json`` in the job folder (written whole: temp file + rename)."""
    from fibrelmp.textio import atomic_write

    path = Path(folder) / SUMMARY_NAME
    atomic_write(path, json.dumps(summary, indent=1, allow_nan=False, default=_json_default) + "\n")
    return path


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} in a summary")


# ---------------------------------------------------------------------------------------
# the final state
def gather_atoms(lmp, name: str, dtype: int, count: int) -> np.ndarray:
    n = int(lmp.get_natoms())
    data = lmp.gather_atoms_concat(name, dtype, count)
    if not n or data is None:
        return np.zeros(0, np.int64 if dtype == 0 else np.float64)
    return np.ctypeslib.as_array(data)[: n * count].copy()


def gather_bonds(lmp) -> np.ndarray:
    """(type, id1, id2) of every bond LAMMPS holds (type <= 0: turned off)."""
    got = lmp.numpy.gather_bonds()
    bonds = np.zeros((0, 3), np.int64) if got is None else np.asarray(got, np.int64).reshape(-1, 3)
    return bonds[bonds[:, 0] > 0]


def _min_image_diff(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, periodic: np.ndarray):
    """Minimum-image differences: a function of two index arrays."""
    span = hi - lo

    def diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        d = x[a] - x[b]
        if periodic.any():
            d[:, periodic] -= span[periodic] * np.round(d[:, periodic] / span[periodic])
        return d
    return diff


def largest_overlap(ids: np.ndarray, x: np.ndarray, radius: np.ndarray, lo: np.ndarray,
                    hi: np.ndarray, periodic: np.ndarray) -> dict | None:
    """The largest overlap r_i + r_j - |x_i - x_j| of two spheres (periodic axes: minimum
    image), with the pair's ids and the overlap relative to the smaller radius; None when no
    two spheres overlap."""
    from scipy.spatial import cKDTree

    if len(x) < 2:
        return None
    reach = 2.0 * float(radius.max())
    if not periodic.any():
        from fibrelmp.sanity import close_pairs

        pairs = close_pairs(x, reach)        # robust for any finite coordinates
    else:
        y = np.array(x, float)
        box = np.empty(3)
        for k in range(3):
            if periodic[k]:
                box[k] = hi[k] - lo[k]
                y[:, k] = np.mod(y[:, k] - lo[k], box[k])
                y[y[:, k] >= box[k], k] = 0.0
            else:     # wide enough that no pair meets across the (unused) wrap
                y[:, k] -= y[:, k].min()
                box[k] = 2.0 * (float(y[:, k].max()) + reach) or 1.0
        # Chebyshev candidates (no squared differences to overflow), confirmed below
        pairs = cKDTree(y, boxsize=box).query_pairs(reach, p=np.inf, output_type="ndarray")
    if not len(pairs):
        return None
    d = _min_image_diff(x, lo, hi, periodic)(pairs[:, 0], pairs[:, 1])
    overlap = radius[pairs[:, 0]] + radius[pairs[:, 1]] - np.sqrt((d * d).sum(1))
    k = int(np.argmax(overlap))
    if not overlap[k] > 0:
        return None
    i, j = pairs[k]
    a, b = sorted((int(ids[i]), int(ids[j])))
    return {"value": float(overlap[k]), "relative": float(overlap[k] / min(radius[i], radius[j])),
            "ids": [a, b], "pairs": int((overlap > 0).sum())}


def largest_strain(ids: np.ndarray, x: np.ndarray, bonds: np.ndarray, rest: np.ndarray,
                   lo: np.ndarray, hi: np.ndarray, periodic: np.ndarray) -> dict | None:
    """The spring with the largest |L - L0| / L0 (minimum image on periodic axes): its signed
    strain (stretched > 0) and its beads' ids; None without springs."""
    if not len(bonds):
        return None
    ids = np.asarray(ids)
    if len(ids) and ids.min() == 1 and ids.max() == len(ids):
        # LAMMPS's ids are unique: ids 1..n are a permutation, so each id's row is direct
        row_of = np.empty(len(ids) + 1, dtype=np.int64)
        row_of[ids] = np.arange(len(ids))
        rows = row_of[bonds[:, 1:]]
    else:
        order = np.argsort(ids)
        rows = order[np.searchsorted(ids[order], bonds[:, 1:])]
    d = _min_image_diff(x, lo, hi, periodic)(rows[:, 0], rows[:, 1])
    r0 = np.asarray(rest, float)[bonds[:, 0] - 1]
    strain = (np.sqrt((d * d).sum(1)) - r0) / r0
    k = int(np.argmax(np.abs(strain)))
    a, b = sorted(int(v) for v in bonds[k, 1:])
    return {"value": float(strain[k]), "ids": [a, b]}


# ---------------------------------------------------------------------------------------
# helpers
def _num(row: dict | None, key: str) -> float | None:
    if row is None or key not in row:
        return None
    value = float(row[key])
    return value if math.isfinite(value) else None


def thermo_int(row: dict | None, key: str) -> int | None:
    value = _num(row, key)
    return None if value is None else int(round(value))


def _energies(row: dict | None) -> dict | None:
    if row is None:
        return None
    out: dict[str, Any] = {"step": thermo_int(row, "Step"), "time": _num(row, "Time")}
    for column, name in ENERGY_COLUMNS.items():
        if column in row:
            out[name] = _num(row, column)
    return out


def _count(schedule) -> int | None:
    try:
        return len(schedule)
    except TypeError:
        return None


def line_count(path: Path) -> int:
    """Non-empty lines of a file (0 when it does not exist)."""
    try:
        with open(path, "rb") as fh:
            return sum(1 for line in fh if line.strip())
    except FileNotFoundError:
        return 0


# ---------------------------------------------------------------------------------------
# the block ``fibrelmp run`` prints
def summary_lines(s: dict) -> list[str]:
    """The summary as a short text block (stdout at the end of ``fibrelmp run``)."""
    def g(v, fmt: str = ".4g") -> str:
        return "?" if v is None else format(v, fmt)

    steps = s["steps"]
    lines = [f"summary of {s['folder']} ({s['kind']}, {s['units']} units)"]
    resumed = f", {steps['this_session']} in this session" if steps["resumed_from"] else ""
    lines.append(f"  steps      {steps['total']}{resumed}; t = {g(s['time']['start'])} .. "
                 f"{g(s['time']['end'])}, dt {g(s['time_step'])}; {s['frames']} frames")
    rate = f" ({s['steps_per_second']:.4g} steps/s)" if s.get("steps_per_second") else ""
    lines.append(f"  wall time  {s['wall_time']:.3g} s{rate}")
    e0, e1 = s.get("energy", {}).get("start"), s.get("energy", {}).get("end")
    if e0 or e1:
        parts = []
        for name in ENERGY_COLUMNS.values():
            if (e0 and name in e0) or (e1 and name in e1):
                parts.append(f"{name} {g((e0 or {}).get(name))} -> {g((e1 or {}).get(name))}")
        lines.append(f"  energy     {', '.join(parts)} (steps {g((e0 or {}).get('step'), 'd')} -> "
                     f"{g((e1 or {}).get('step'), 'd')})")
    p = s["particles"]
    if p["kind"] == "spheres":
        made = p.get("generated") or 0           # MUSEN's dynamic generators (inlets)
        removed = p["start"] + made - p["end"]
        lines.append(f"  spheres    {p['start']}{f' + {made} generated' if made else ''} -> {p['end']} "
                     f"({removed} removed: "
                     f"{p['removed_at_activity_end']} at their activity end, "
                     f"{p['left_domain']} left the domain)")
        ov = s.get("max_overlap")
        most = ("largest overlap " + (f"{ov['value']:.3g} ({100 * ov['relative']:.3g} % of the "
                f"smaller radius, spheres {ov['ids'][0]}-{ov['ids'][1]})" if ov else "none"))
        lines.append(f"  contacts   {g(s.get('contacts'), 'd')} overlapping sphere pairs; {most}")
    elif p["kind"] == "sph":
        lines.append(f"  fluid      {p['fluid_start']} -> {p['fluid_end']} particles; {p['wall']} wall particles")
        for name, o in s.get("openings", {}).items():
            lines.append(f"  opening    {name}: {o['crossed_particles']} particles crossed "
                         f"({o['crossed_volume']:.4g} m^3)")
    else:
        lines.append(f"  beads      {p['start']}")
    if "bonds" in s:
        b = s["bonds"]
        name = "springs " if p["kind"] == "beads" else "bonds   "
        lines.append(f"  {name}   {b['start']} -> {b['end']} ({b['broken']} broken)")
    temp = s.get("temperature")
    if temp and temp["frames"]:
        first, last = temp["frames"][0], temp["frames"][-1]
        lines.append(f"  temperature {g(first['min'])} .. {g(first['max'])} -> {g(last['min'])} .. "
                     f"{g(last['max'])} {temp['unit']} (min .. max of the spheres, first -> last frame)")
    st = s.get("max_spring_strain")
    if st:
        lines.append(f"  strain     largest spring strain {st['value']:+.3g} (beads "
                     f"{st['ids'][0]}-{st['ids'][1]})")
    check = s.get("time_step_check")
    if check:
        flag = "" if check["ok"] else f" -- fewer than {check['limit']:g}: see the 'time step' warning"
        lines.append(f"  time step  {check['name']} {check['value']:.4g} = {check['steps_per']:.3g} "
                     f"steps{flag}")
    warned = s["warnings"]
    lines.append("  warnings   " + (", ".join(f"{k} ({n})" for k, n in warned.items()) or "none"))
    if s.get("log"):
        lines.append(f"  record     {Path(s['folder']) / s['log']}, {Path(s['folder']) / SUMMARY_NAME}")
    return lines
