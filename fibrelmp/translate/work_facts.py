"""What a job's data file cannot hold but ``fibrelmp post`` needs to write the run's own
files from the job's dump: ``data.fibrelmp.json`` beside ``data.lammps`` in the work folder.

A LAMMPS data file and dump carry positions, velocities, forces, types, radii and masses;
they cannot carry the source's names (exact FibreNet type names, MUSEN material keys), MUSEN
object ids, the orientation a MUSEN sphere started with (LAMMPS quaternions start at the
identity), the exact simulated times (``ITEM: TIME`` is LAMMPS's running sum, printed with 16
digits) or the DEMDF document a snapshot repeats.  The job writes them here; ``post --data
data.lammps`` reads them (``post.lammps_data.reader``).  Plain JSON with numbers in Python's
round-trip form, so every value comes back bit for bit.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.textio import atomic_write, read_text

SUFFIX = ".fibrelmp.json"
VERSION = 1
# MUSEN's variable time step: fix musen/leapfrog writes "step time dt" per frame (17 digits)
# to this file beside the data file; those frames' times come from it
VARIABLE_CLOCK = "clock.txt"


def facts_path(data: str | Path) -> Path:
    """``data.lammps`` -> ``data.fibrelmp.json``."""
    data = Path(data)
    return data.with_name(data.stem + SUFFIX)


@dataclass
class WorkFacts:
    """The facts of one job (see the module text); arrays are indexed by LAMMPS atom id - 1."""

    kind: str                                    # "fibrenet" | "musen" | "demdf"
    source: str                                  # the input's file name
    time_start: float                            # time of step 0
    time_step: float                             # time per LAMMPS step
    type_names: dict[int, str]                   # LAMMPS type -> the source's name
    material_keys: dict[int, str] | None = None  # LAMMPS type -> MUSEN material key
    object_ids: np.ndarray | None = None         # MUSEN object id of each atom
    orientation: np.ndarray | None = None        # (n, 4) initial w x y z (None: all identity)
    radius: np.ndarray | None = None             # sphere radius where it is not the contact radius
    box_lengths: np.ndarray | None = None        # FibreNet's box (its FRAME lines)
    output_types: list[str] | None = None        # FibreNet output_type (None: all)
    output_fields: list[str] | None = None       # FibreNet output_data (position velocity force)
    demdf: dict[str, Any] | None = None          # what DEMDF snapshots repeat (the document, ...)
    path: Path | None = None
    clock: str = "product"                       # "musen": cmusen's summed time (t += dt);
                                                 # "variable": VARIABLE_CLOCK's times
    _musen: Any = field(default=None, repr=False, compare=False)   # the clock, once read

    def time(self, step: int) -> float:
        """The simulated time of ``step``, computed as the run computes it."""
        if self.clock == "variable":
            return self._variable_time(step)
        if self.clock == "musen":
            if self._musen is None:
                from fibrelmp.translate.granular.musen_clock import MusenClock

                self._musen = MusenClock(self.time_start, self.time_step)
            return self._musen.time(step)
        return self.time_start + step * self.time_step


    def _variable_time(self, step: int) -> float:
        if self._musen is None:
            clock = (self.path.parent if self.path is not None else Path(".")) / VARIABLE_CLOCK
            times: dict[int, float] = {}
            for line in read_text(clock, "the variable time step's clock").splitlines():
                words = line.split()
                if len(words) == 3:
                    times[int(words[0])] = float(words[1])
            self._musen = (clock, times)
        clock, times = self._musen
        if step not in times:
            raise InputError(clock, None, f"no time for step {step}: MUSEN's variable time step "
                             "gives times only to the steps of the run's frames")
        return times[step]


def write_facts(data: str | Path, facts: WorkFacts) -> Path:
    """Write ``facts`` beside the data file ``data``; returns the path."""
    doc: dict[str, Any] = {
        "fibrelmp_work_facts": VERSION, "kind": facts.kind, "source": facts.source,
        "time": {"start": float(facts.time_start), "step": float(facts.time_step), "clock": facts.clock},
        "type_names": {str(t): name for t, name in sorted(facts.type_names.items())},
    }
    if facts.material_keys is not None:
        doc["material_keys"] = {str(t): key for t, key in sorted(facts.material_keys.items())}
    for name in ("object_ids", "orientation", "radius", "box_lengths"):
        value = getattr(facts, name)
        if value is not None:
            doc[name] = np.asarray(value).tolist()
    for name in ("output_types", "output_fields"):
        if getattr(facts, name) is not None:
            doc[name] = list(getattr(facts, name))
    if facts.demdf is not None:
        doc["demdf"] = facts.demdf
    path = facts_path(data)
    atomic_write(path, json.dumps(doc, ensure_ascii=True, default=_plain) + "\n")
    return path


def _plain(value: Any) -> Any:
    """numpy values in a document (JSON has no such types)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON data")


def read_facts(data: str | Path) -> WorkFacts | None:
    """The facts beside the data file ``data``, or None when it has none."""
    path = facts_path(data)
    if not path.is_file():
        return None
    try:
        doc = json.loads(read_text(path, "fibrelmp work facts"))
        if doc.get("fibrelmp_work_facts") != VERSION:
            raise ValueError(f"unknown version {doc.get('fibrelmp_work_facts')!r}")
        time = doc["time"]
        facts = WorkFacts(
            kind=str(doc["kind"]), source=str(doc["source"]),
            time_start=float(time["start"]), time_step=float(time["step"]),
            type_names={int(t): str(v) for t, v in doc["type_names"].items()},
            material_keys=({int(t): str(v) for t, v in doc["material_keys"].items()}
                           if "material_keys" in doc else None),
            object_ids=_array(doc, "object_ids", np.int64),
            orientation=_array(doc, "orientation", np.float64),
            radius=_array(doc, "radius", np.float64),
            box_lengths=_array(doc, "box_lengths", np.float64),
            output_types=[str(t) for t in doc["output_types"]] if "output_types" in doc else None,
            output_fields=[str(t) for t in doc["output_fields"]] if "output_fields" in doc else None,
            demdf=doc.get("demdf"), path=path, clock=str(time.get("clock", "product")))
        if facts.clock not in ("product", "musen", "variable"):
            raise ValueError(f"unknown clock {facts.clock!r}")
        if not (math.isfinite(facts.time_start) and math.isfinite(facts.time_step)):
            raise ValueError("non-finite time")
        if facts.orientation is not None and facts.orientation.shape[1:] != (4,):
            raise ValueError("orientation needs 4 values per atom")
    except InputError:
        raise
    except (ValueError, KeyError, TypeError, AttributeError, IndexError) as exc:
        raise InputError(path, None, f"damaged fibrelmp work facts ({exc}); write the job again "
                         "(fibrelmp translate) or leave out --data") from None
    return facts


def _array(doc: dict, key: str, dtype) -> np.ndarray | None:
    return np.asarray(doc[key], dtype=dtype) if key in doc else None
