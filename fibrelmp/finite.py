"""The last guard before results are written: a frame holding nan or inf is a RunError.

A simulation that blew up (or met a case its law divides by zero in) keeps running in LAMMPS
and writes nan/inf into its dumps; every result format would then carry ``nan`` tokens and
the run would exit 0.  ``guarded(frames)`` checks each frame as it is fed to the writers
(``runplan.feed``) and raises a RunError naming the first non-finite value: its
quantity, the particle (source id), the time and step.  The writers' loop aborts them on it,
so no result is written, half or whole.

Values that are nan by design are not checked: a bond's force, torque and tangential overlap
where the bond is no longer alive (the frame's mark for "absent"), a bond's end time (inf:
alive).  ``scan_text_files`` does the same for results a LAMMPS style wrote itself
(FibreNet's files from ``fix fibrenet/output``), reading them in blocks (bounded memory).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable, Iterator

import numpy as np

from fibrelmp.errors import RunError

# (attribute, what it is, whose: "sphere" / "bond" / "triangle" / "particle") per frame kind
_GRANULAR = [("position", "position", "sphere"), ("velocity", "velocity", "sphere"),
             ("omega", "angular velocity", "sphere"), ("force", "force", "sphere"),
             ("quaternion", "orientation", "sphere"),
             ("bond_force", "force", "bond"), ("bond_torque", "torque", "bond"),
             ("bond_tangential_overlap", "tangential overlap", "bond"),
             ("triangle_vertices", "vertices", "triangle"),
             ("triangle_velocity", "velocity", "triangle"), ("triangle_force", "force", "triangle"),
             ("stress_tensor", "stress tensor", "sphere"), ("saved_triangle_force", "force", "triangle")]
_SPH = [("positions", "position"), ("velocities", "velocity"), ("density", "density"),
        ("pressure", "pressure")]
_BLOCK = 1 << 20
# a nan/inf value after a separator (a type name such as "Nanofibre" is no hit)
_WORDS = [sep + word for sep in (b"\t", b" ") for word in (b"nan", b"-nan", b"inf", b"-inf")]
_TAIL = 8


def guarded(frames: Iterable[Any], model: Any = None) -> Iterator[Any]:
    """``frames``, each checked by ``check`` before it is handed on."""
    for frame in frames:
        check(frame, model)
        yield frame


def check(frame: Any, model: Any = None) -> None:
    """A RunError at the first nan/inf of ``frame``: a GranularFrame (``model``, the
    GranularModel, gives the source ids), a CardioProof SphFrame or a LAMMPS dump Frame;
    other objects (a FibreNet frame counter) carry no values."""
    found = _first_non_finite(frame, model)
    if found is None:
        return
    quantity, who, value = found
    step = getattr(frame, "step", None)
    time = getattr(frame, "time", None)
    when = (f"t = {time:.17g}" if time is not None else "") + \
        (f" (step {step})" if step is not None else "")
    raise RunError(f"the simulation produced {value} in the {quantity} of {who} at {when.strip()}: "
                   "no results written (the run blew up or met a singular case; check the time "
                   "step, overlaps and coincident particles in the input)")


def _first_non_finite(frame: Any, model: Any) -> tuple[str, str, str] | None:
    kind = type(frame).__name__
    if kind == "GranularFrame":
        return _granular(frame, model)
    if kind == "SphFrame":
        for name, what in _SPH:
            hit = _first_bad(getattr(frame, name))
            if hit is not None:
                row, value = hit
                return what, f"particle {int(frame.ids[row])}", value
        if frame.nodes is not None:
            hit = _first_bad(frame.nodes)
            if hit is not None:
                return "position", f"wall mesh node {hit[0] + 1}", hit[1]
        return None
    columns = getattr(frame, "columns", None)
    if isinstance(columns, dict):           # a LAMMPS dump frame
        ids = columns.get("id")
        for name, values in columns.items():
            hit = _first_bad(values)
            if hit is not None:
                row, value = hit
                who = f"atom {int(ids[row])}" if ids is not None and np.isfinite(ids[row]) else f"row {row + 1}"
                return f"dump column '{name}'", who, value
    return None


def _granular(frame: Any, model: Any) -> tuple[str, str, str] | None:
    alive = frame.bond_alive
    for name, what, whose in _GRANULAR:
        values = getattr(frame, name)
        if values is None:
            continue
        values = np.asarray(values)
        rows = None
        if whose == "bond" and alive is not None:
            rows = np.flatnonzero(alive)             # absent bonds hold nan by design
            values = values[rows]
        hit = _first_bad(values)
        if hit is None:
            continue
        row, value = hit
        if rows is not None:
            row = int(rows[row])
        if whose == "sphere":
            row = int(frame.sphere_rows[row])
        ids = None
        if model is not None:
            owner = {"sphere": model.spheres, "bond": model.bonds, "triangle": model.triangles}[whose]
            ids = getattr(owner, "ids", None)
        who = f"{whose} {int(ids[row])}" if ids is not None else f"{whose} row {row}"
        return what, who, value
    return None


def _first_bad(values: Any) -> tuple[int, str] | None:
    """(row, 'nan'/'inf'/'-inf') of the first non-finite entry of an array, by row."""
    a = np.asarray(values)
    if a.dtype.kind not in "fc" or a.size == 0:
        return None
    bad = ~np.isfinite(a)
    if not bad.any():
        return None
    flat = np.flatnonzero(bad.reshape(len(a), -1).any(axis=1)) if a.ndim > 1 else np.flatnonzero(bad)
    row = int(flat[0])
    v = a[row].reshape(-1)[~np.isfinite(a[row].reshape(-1))][0]
    return row, "nan" if np.isnan(v) else ("inf" if v > 0 else "-inf")


def scan_text_files(paths: Iterable[Path]) -> None:
    """A RunError when a result text file holds a nan/inf value: its path and line.  The
    files are read in 1 MiB blocks (bounded memory) and searched for a separator followed by
    ``nan``/``inf``/``-inf``, as C's printf and Python write them (a particle row starts with
    its type name, which is therefore never taken for a value)."""
    for path in paths:
        path = Path(path)
        if not path.is_file():
            continue
        with open(path, "rb") as fh:
            line, tail, tail_lines = 1, b"", 0
            for block in iter(lambda: fh.read(_BLOCK), b""):
                data = tail + block
                hit = min((i for i in (data.find(word) for word in _WORDS) if i >= 0), default=-1)
                if hit >= 0:
                    start = data.rfind(b"\n", 0, hit) + 1
                    end = data.find(b"\n", hit)
                    text = data[start:end if end >= 0 else len(data)].decode("utf-8", "replace")
                    value = data[hit + 1:].split(None, 1)[0].decode("ascii", "replace")
                    number = line - tail_lines + data.count(b"\n", 0, hit)
                    raise RunError(f"{path}:{number}: the simulation produced {value} (this line: "
                                   f"{text.strip()[:120]!r}): no results written (the run blew up "
                                   "or met a singular case)")
                tail = data[-_TAIL:]
                tail_lines = tail.count(b"\n")
                line += block.count(b"\n")
