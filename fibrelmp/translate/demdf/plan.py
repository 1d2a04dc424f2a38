"""DEMDF time plan (ends, time step, saves) and output specification, as BOS reads them.

A mixin of ``demdf._Reader``: it uses the reader's ``j`` (JsonDoc), ``warn``, ``path``,
``snapshot``, ``t0``, ``dim``, ``rmax`` and ``contact_note`` (shortest contact time, worst
overlap).  See docs/demdf.md for the rules.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan
from fibrelmp.translate.json_doc import describe

# the keys of a snapshot output entry (BOS: output.snapshot; the draft: output[i] named "demdf")
_SNAPSHOT_KEYS = ("name", "filename", "saveCount", "savePeriodInTime", "savePeriodInTimeSteps")

LONG_RUN_STEPS = 20_000_000


@dataclass
class Output:
    filename: str = "output"
    save_count: int = 0
    period_time: float | None = None
    period_steps: int | None = None
    location: tuple | None = None        # keys of the snapshot spec in the document


class PlanMixin:
    """Reads the stop and save rules of a DEMDF document into a GranularPlan."""

    def _plan(self, doc: dict, out: Output, dt_need: float, gravity: np.ndarray, domain,
              time_end: float | None, steps: int | None, save_every: Any) -> GranularPlan:
        j, t0 = self.j, self.t0
        file_dt = j.number(doc["timeStep"], "timeStep", minimum=0) if "timeStep" in doc else 0.0
        self.step0 = j.integer(doc.get("timeStepCount", 0), "timeStepCount", minimum=0)
        if "eventCount" in doc:
            j.integer(doc["eventCount"], "eventCount", minimum=0)
        if "eventCountEnd" in doc:
            j.integer(doc["eventCountEnd"], "eventCountEnd", minimum=0)
            self.warn("demdf", "eventCountEnd (an event-driven limit) has no soft-sphere meaning; ignored")
        t_c, (ratio, label) = self.contact_note
        override = self._save_override(save_every)
        if file_dt > 0:
            unit, what = file_dt, "timeStep"
        else:   # no timeStep: a divisor of the save period, so snapshots fall on its multiples
            unit = override[1] if override and override[0] == "time" else \
                (out.period_time if override is None else None)
            what = "the save period"
        if unit is not None and unit / dt_need > 1e9:
            j.fail("timeStep" if file_dt > 0 else "", f"{what} {unit:g} is {unit / dt_need:.3g} "
                   f"times the step the contacts need ({dt_need:.3g})")
        k = max(1, math.ceil(unit / dt_need * (1 - 1e-12))) if unit is not None else 1
        dt = unit / k if unit is not None else dt_need
        if file_dt > 0 and k > 1:
            self.warn("physics", f"timeStep {file_dt:g} is too coarse for the contacts (shortest "
                      f"contact {t_c:.3g} = {t_c / file_dt:.3g} time steps); integrating with "
                      f"timeStep/{k} = {dt:.4g}.  Step counts in the document (timeStepCountEnd, "
                      "savePeriodInTimeSteps) still count timeStep steps")
        elif file_dt <= 0:
            self.warn("physics", f"no timeStep (BOS is event-driven): dt = {dt:.4g}, the contact "
                      f"time {t_c:.3g} (at the fastest approach) / {t_c / dt:.3g}"
                      + (f", chosen to divide {what} {unit:g}" if unit is not None else ""))
            k = 1
        self.file_dt, self.substeps = (file_dt if file_dt > 0 else dt), k
        t_end = self._end(doc, t0, dt, k, time_end, steps)
        every_steps, every_time = self._saves(out, k, override)
        nsteps = (t_end - t0) / dt if math.isfinite(t_end) else 0
        if nsteps > 1e12 and not self.snapshot:
            raise InputError(self.path, None, f"this run would take {nsteps:.3g} time steps of "
                             f"{dt:.3g}; give a nearer end (--time-end or --steps)")
        if nsteps > LONG_RUN_STEPS:
            self.warn("physics", f"this run takes {nsteps:.3g} time steps of {dt:.3g}; shorten it "
                      "with --time-end or --steps")
        lo_hi = domain
        if domain is not None and self.dim == 2:      # a slab one diameter thick around z = 0
            lo_hi = (np.append(domain[0][:2], -self.rmax), np.append(domain[1][:2], self.rmax))
        return GranularPlan(dt=dt, t_start=t0, t_end=t_end, save_every_steps=every_steps,
                            save_every_time=every_time, gravity=gravity, domain=lo_hi,
                            dimension=self.dim)

    def _end(self, doc: dict, t0: float, dt: float, k: int, time_end: float | None,
             steps: int | None) -> float:
        j = self.j
        file_end = j.number(doc["timeEnd"], "timeEnd") if "timeEnd" in doc else None
        count_end = j.integer(doc["timeStepCountEnd"], "timeStepCountEnd", minimum=0) \
            if "timeStepCountEnd" in doc else None
        ends: list[float] = []
        if time_end is not None or steps is not None:
            if time_end is not None:
                if not (isinstance(time_end, (int, float)) and math.isfinite(time_end)):
                    raise InputError(self.path, None, f"--time-end must be a number, got {time_end!r}")
                if not time_end > t0:
                    raise InputError(self.path, None, f"--time-end {time_end:g} is not after the "
                                     f"document's time {t0:g}")
                ends.append(float(time_end))
                self.warn("override", f"override: end time {time_end:g} (document: timeEnd "
                          f"{file_end if file_end is not None else 'none'}, timeStepCountEnd "
                          f"{count_end if count_end is not None else 'none'})")
            if steps is not None:
                if isinstance(steps, bool) or not isinstance(steps, int) or steps <= 0:
                    raise InputError(self.path, None, f"--steps must be a positive integer, got {steps!r}")
                ends.append(t0 + steps * dt)
                self.warn("override", f"override: {steps} time steps of {dt:.4g} (to time "
                          f"{t0 + steps * dt:.6g})")
            return min(ends)
        limits: list[tuple[float, str, str]] = []
        if file_end is not None and file_end >= 0:
            limits.append((file_end, "timeEnd", f"{file_end:g} is not after time {t0:g}"))
        if count_end is not None:
            limits.append((t0 + (count_end - self.step0) * k * dt, "timeStepCountEnd",
                           f"{count_end} is not after timeStepCount {self.step0}"))
        if not limits:
            if self.snapshot:
                return t0
            why = "timeEnd is negative (BOS: run for ever)" if file_end is not None else \
                "the document gives neither timeEnd nor timeStepCountEnd"
            j.fail("timeEnd", f"{why}, and a soft-sphere run needs an end: add timeEnd or "
                   "timeStepCountEnd, or give --time-end/--steps (eventCountEnd, an event count, "
                   "does not apply)")
        t_end, field, why = min(limits)
        if t_end <= t0:
            if self.snapshot:
                return t0
            j.fail(field, f"{why}: nothing to simulate (give --time-end or --steps)")
        return t_end

    def _save_override(self, save_every: Any) -> tuple[str, float] | None:
        """``save_every``: a float is a time, an int a number of steps (strings parsed)."""
        if save_every is None:
            return None
        value = save_every
        if isinstance(value, str):
            try:
                value = int(value)
            except ValueError:
                try:
                    value = float(value)
                except ValueError:
                    raise InputError(self.path, None, f"--save-every must be a number, got "
                                     f"{save_every!r}") from None
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value) or value <= 0:
            raise InputError(self.path, None, f"--save-every must be positive, got {save_every!r}")
        if isinstance(value, int):
            self.warn("override", f"override: a snapshot every {value} time steps")
            return "steps", value
        self.warn("override", f"override: a snapshot every {value:g} time units")
        return "time", float(value)

    def _saves(self, out: Output, k: int, override: tuple[str, float] | None
               ) -> tuple[int | None, float | None]:
        if override is not None:
            return (int(override[1]), None) if override[0] == "steps" else (None, override[1])
        if out.period_time is not None:
            if out.period_steps is not None:
                as_time = out.period_steps * self.file_dt
                if abs(as_time - out.period_time) > 1e-9 * out.period_time:
                    self.warn("demdf", f"savePeriodInTime {out.period_time:g} and "
                              f"savePeriodInTimeSteps {out.period_steps} (= {as_time:g}) disagree: "
                              "savePeriodInTime wins, as in BOS")
            return None, out.period_time
        if out.period_steps is not None:
            return out.period_steps * k, None
        return None, None

    # ------------------------------------------------------------------ output
    def _output(self, doc: dict) -> Output:
        if "output" not in doc:
            if not self.snapshot:
                self.warn("demdf", "no output: only the start and end states are written, as "
                          "output_<n>.json")
            return Output()
        value = doc["output"]
        spec, where, location = None, "output", None
        if isinstance(value, list):
            for i, entry in enumerate(value):
                entry = self.j.obj(entry, f"output[{i}]")
                name = entry.get("name", "demdf")
                if name == "demdf":
                    self.j.check_keys(entry, f"output[{i}]", ("output", i), _SNAPSHOT_KEYS)
                if name == "demdf" and spec is None:
                    spec, where, location = entry, f"output[{i}]", ("output", i)
                else:
                    self.warn("demdf", f"output[{i}] ({describe(name)}) is not a demdf snapshot "
                              "output (or not the first); ignored")
        elif isinstance(value, dict):
            # other output routines (measurements) may sit beside the snapshot: only a key
            # resembling "snapshot" is taken for a misspelling
            others = self.j.check_keys(value, "output", ("output",), ("snapshot",) if "filename"
                                       not in value else _SNAPSHOT_KEYS, lenient="filename" not in value)
            if "snapshot" in value:
                spec = self.j.obj(value["snapshot"], "output.snapshot")
                where, location = "output.snapshot", ("output", "snapshot")
                self.j.check_keys(spec, where, location, _SNAPSHOT_KEYS)
                for key in others:
                    self.warn("demdf", f"output.{key} is not an output fibrelmp writes; ignored")
            elif "filename" in value:
                spec, location = value, ("output",)
            else:
                self.warn("demdf", "output has no snapshot entry; ignored")
        else:
            self.j.fail("output", f"expected {{\"snapshot\": {{...}}}} or an array, got {describe(value)}")
        if spec is None:
            return Output()
        out = Output(location=location)
        if "filename" in spec:
            out.filename = self.j.string(spec["filename"], f"{where}.filename")
            if not out.filename.strip() or Path(out.filename).is_absolute():
                self.j.fail(f"{where}.filename", f"must be a non-empty relative name, got "
                            f"{out.filename!r}")
        out.save_count = self.j.integer(spec.get("saveCount", 0), f"{where}.saveCount", minimum=0)
        if "savePeriodInTime" in spec:
            out.period_time = self.j.number(spec["savePeriodInTime"], f"{where}.savePeriodInTime",
                                            positive=True)
        if "savePeriodInTimeSteps" in spec:
            out.period_steps = self.j.integer(spec["savePeriodInTimeSteps"],
                                              f"{where}.savePeriodInTimeSteps", minimum=1)
        return out
