"""LAMMPS dump frames -> FibreNet's own output files: ``write_fibrenet`` and ``convert_frames``
(``fibrelmp run`` without the plugin's native files; ``report_outside`` when LAMMPS wrote
them), and the ``post --to xyz|res`` targets."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Callable, ClassVar, Iterable, Iterator, Mapping, Sequence

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.post.target import DumpTarget, ReadBack
from fibrelmp.translate.fibrenet.writer import (RESTART_SUFFIX, XYZ_SUFFIX, FibreNetWriter, RestartState,
                                                XyzRows, read_restart, read_xyz)
from fibrelmp.units import LJ

if TYPE_CHECKING:
    from fibrelmp.model import Model
    from fibrelmp.translate.lammps_job import Job

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
    return frame.block(*names)


def wrapped_and_unwrapped(frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """Positions wrapped into [lo, hi) on periodic axes, and unwrapped positions."""
    lengths = frame.hi - frame.lo
    # views of the parsed table where possible (read-only): copies only where values change
    if "x" in frame.columns:
        x = frame.block("x", "y", "z")
        unwrapped = x + frame.block("ix", "iy", "iz") * lengths if "ix" in frame.columns else x
    else:
        unwrapped = x = frame.block("xu", "yu", "zu")
    per = frame.periodic
    if not per.any():
        return x, unwrapped
    if unwrapped is x and not frame.lo[per].any():
        # a box from 0 (FibreNet's) and x y z inside it, as LAMMPS dumps them: mod(x, L) is x
        # exactly, so the copy and the modulo are skipped (16 ms a frame at 256k atoms)
        inside = x[:, per]
        if inside.min(initial=0.0) >= 0 and bool((inside < lengths[per]).all()):
            return x, unwrapped
    wrapped = x.copy()
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


class FibreNetFrames:
    """Dump frames -> (XyzRows, RestartState) for ``FibreNetWriter``: atoms in id order,
    positions wrapped, FibreNet's velocity/force columns when dumped.

    ``box_lengths`` None: each frame's own box (post-processing of dumps whose box changes).
    With ``box_lengths`` (FibreNet's box [0, L]) the first frame with a bead centre outside
    [0, L) on a finite axis triggers one warning (``outside_message``): ``warn(kind, text)``
    when given (e.g. ``model.warn``), otherwise a ``FibreNetDivergenceWarning`` through Python's
    ``warnings`` module (printed on stderr by default)."""

    def __init__(self, fields: Sequence[str], names_of_type: Mapping[int, str], dt: float,
                 restart: bool, box_lengths: np.ndarray | None = None,
                 output_types: set[str] | None = None,
                 warn: Callable[[str, str], None] | None = None):
        self.fields, self.names, self.dt, self.restart = tuple(fields), names_of_type, dt, restart
        self.box_lengths, self.output_types, self.warn = box_lengths, output_types, warn
        self.warned = box_lengths is None

    def __call__(self, frame: Frame) -> tuple[XyzRows, RestartState]:
        ids = frame.column("id")
        # dumps written with "modify sort id" need no reordering (saves a sort per frame)
        order = slice(None) if bool(np.all(ids[1:] > ids[:-1])) else np.argsort(ids, kind="stable")
        codes, table = type_codes(frame.column("type")[order], self.names)
        keep = slice(None) if self.output_types is None else \
            np.isin(codes, [k for k, name in enumerate(table) if name in self.output_types])
        wrapped, unwrapped = wrapped_and_unwrapped(frame)
        if not self.warned:
            self._check_box(frame, wrapped)
        data = {"position": wrapped[order]}
        if "velocity" in self.fields or self.restart:
            data["velocity"] = _pick(frame, VEL_COLUMNS, ("vx", "vy", "vz"))[order]
        if "force" in self.fields or self.restart:
            data["force"] = _pick(frame, FORCE_COLUMNS, ("fx", "fy", "fz"))[order]
        lengths = self.box_lengths if self.box_lengths is not None else frame.hi - frame.lo
        rows = XyzRows(frame.step, self.dt, lengths, codes[keep], table,
                       {f: data[f][keep] for f in self.fields})
        state = RestartState(frame.step, self.dt, lengths, codes, table, data["position"],
                             unwrapped[order], data.get("velocity"), data.get("force"))
        return rows, state

    def _check_box(self, frame: Frame, wrapped: np.ndarray) -> None:
        out = outside_finite_box(wrapped, frame.periodic, self.box_lengths)
        if out.any():
            self.warned = True
            text = outside_message(frame.step, int(out.sum()), np.asarray(self.box_lengths, float))
            if self.warn is not None:
                self.warn(OUTSIDE_KIND, text)
            else:
                warnings.warn(f"[{OUTSIDE_KIND}] {text}", FibreNetDivergenceWarning, stacklevel=4)


def write_fibrenet(frames: Iterable[Frame], basename: str, folder: Path, fields: Sequence[str],
                   names_of_type: Mapping[int, str], dt: float, box_lengths: np.ndarray | None,
                   output_types: set[str] | None, restart: bool = True,
                   warn: Callable[[str, str], None] | None = None) -> list[Path]:
    """Write ``<basename>_coord/_vel/_force.xyz`` (every frame) and ``_restart.res`` (last);
    see ``FibreNetFrames`` for ``box_lengths``, ``output_types`` and ``warn``."""
    writer = FibreNetWriter(Path(folder) / basename, fields, restart)
    convert = FibreNetFrames(fields, names_of_type, dt, restart, box_lengths, output_types, warn)
    try:
        for frame in frames:
            writer.add(convert(frame))
    except BaseException:
        writer.abort()
        raise
    return writer.close()


def dt_from(first: list[Frame], warn: Callable[[str, str], None]) -> float:
    """The MD time step for FibreNet's FRAME lines: from ITEM: TIME values when present
    (rounded to 15 digits: LAMMPS's time is a running sum, printed with 16)."""
    for f in first:
        if f.time is not None and f.step:
            return _clean(f.time / f.step)
    if len(first) == 2 and all(f.time is not None for f in first) and first[1].step != first[0].step:
        return _clean((first[1].time - first[0].time) / (first[1].step - first[0].step))
    warn("no time step", "the dump does not give the time step (no ITEM: TIME); FRAME lines carry dt 0")
    return 0.0


def _clean(dt: float) -> float:
    return float(f"{dt:.15g}")


class _FibreNetTarget(DumpTarget):
    """``--to xyz`` / ``--to res``: FibreNet's files through ``FibreNetWriter``."""

    units = ("FibreNet", LJ)
    lookahead = 2                  # the time step comes from the first two frames
    finite_columns = frozenset({"vx", "vy", "vz", "fx", "fy", "fz", *VEL_COLUMNS, *FORCE_COLUMNS})
    restart: ClassVar[bool]
    own_suffixes: ClassVar[tuple[str, ...]]     # what -o may end with: the base is before it

    def __init__(self, base: str | Path, context=None, *, force: bool = True):
        super().__init__(self.named(Path(base)), context, force=force)

    @classmethod
    def named(cls, base: Path) -> Path:
        """The base of ``-o``: ``out/net`` as given; ``out/net.xyz`` or ``out/net_coord.xyz``
        mean ``out/net`` too (was: ``out/net.xyz_coord.xyz``)."""
        for suffix in cls.own_suffixes:
            if base.name.endswith(suffix) and len(base.name) > len(suffix):
                return base.with_name(base.name[:-len(suffix)])
        return base

    def fields(self, first: Frame) -> tuple[str, ...]:
        return ()

    def start(self, first: list[Frame]) -> None:
        """With fibrelmp's job facts (``--data`` of a FibreNet work folder) the files are the
        run's: its time step, box lengths, output_type and output_data."""
        ctx = self.context
        facts = ctx.facts if ctx.facts is not None and ctx.facts.kind == "fibrenet" else None
        fields = self.fields(first[0])
        if facts is None:
            self.convert = FibreNetFrames(fields, ctx.type_names, dt_from(first, ctx.warn), self.restart)
        else:
            if facts.output_fields is not None and not self.restart:
                fields = tuple(f for f in fields if f in facts.output_fields)
            only = None if facts.output_types is None else set(facts.output_types)
            self.convert = FibreNetFrames(fields, ctx.type_names, facts.time_step, self.restart,
                                          facts.box_lengths, only, ctx.warn)
        self.out = self.adopt(FibreNetWriter(self.target, fields, self.restart))

    def write_frame(self, frame: Frame) -> None:
        self.out.add(self.convert(frame))


class XyzTarget(_FibreNetTarget):
    """``<base>_coord.xyz`` and, when dumped, ``_vel.xyz`` / ``_force.xyz``: every frame."""

    restart = False
    own_suffixes = (*XYZ_SUFFIX.values(), ".xyz")

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        base = cls.named(base)
        return [base.with_name(base.name + s) for s in XYZ_SUFFIX.values()]

    def fields(self, first: Frame) -> tuple[str, ...]:
        have = first.columns
        fields = tuple(f for f, cols in (("position", ("x",)), ("velocity", ("vx", "v_fn_vx")),
                                         ("force", ("fx", "v_fn_fx")))
                       if f == "position" or any(c in have for c in cols))
        missing = sorted({"velocity", "force"} - set(fields))
        if missing:
            self.context.warn("missing fields", f"{self.context.source}: no {' or '.join(missing)} "
                              "columns; only " + ", ".join(f"_{'coord' if f == 'position' else f[:3]}.xyz"
                                                           for f in fields) + " written")
        return fields

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        frames = {p.name.rsplit("_", 1)[-1]: read_xyz(p) for p in files}
        out = []
        for k, f in enumerate(frames["coord.xyz"]):
            values = {cols: frames[name][k].values for name, cols in
                      (("vel.xyz", ("vx", "vy", "vz")), ("force.xyz", ("fx", "fy", "fz")))
                      if name in frames}
            out.append(ReadBack(f.values, atol=0.5e-5 + 1e-12, values=values))      # %.5f
        return out


class RestartTarget(_FibreNetTarget):
    """``<base>_restart.res``: one frame, the last unless ``--frames`` says otherwise."""

    restart = True
    last_frame_by_default = True
    own_suffixes = (RESTART_SUFFIX, ".res")

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        return [cls.named(base).with_name(cls.named(base).name + RESTART_SUFFIX)]

    def start(self, first: list[Frame]) -> None:
        for need, cols in (("velocity", ("vx", "vy", "vz")), ("force", ("fx", "fy", "fz"))):
            if not (first[0].has(*cols) or first[0].has(*("v_fn_" + c[0] + c[1] for c in cols))):
                raise InputError(self.context.source, first[0].line, f"a FibreNet restart needs {need}: "
                                 f"the dump has no {' '.join(cols)} columns")
        super().start(first)

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        names, rows = read_restart(files[0])
        return [ReadBack(rows[:, 0:3], rtol=6e-6, atol=1e-300,       # %g: 6 significant digits
                         values={("vx", "vy", "vz"): rows[:, 6:9], ("fx", "fy", "fz"): rows[:, 9:12]})]


def convert_frames(model: Model, job: Job, frames: Iterator[Frame], folder: Path,
                   prefix: str) -> list[Path]:
    """FibreNet's files from a run's dump frames (``write_fibrenet``): the path without
    fibrelmp's plugin, and the reference its ``fix fibrenet/output`` matches byte for byte."""
    spec = model.plan.output
    names = {lt: model.particles.type_names[t] for lt, t in enumerate(job.type_of_ltype) if lt > 0}
    types = None if spec.types is None else {model.particles.type_names[t] for t in spec.types}
    return write_fibrenet(frames, prefix, folder, spec.fields, names, model.dynamics.dt,
                          model.box.lengths, types, warn=model.warn)


def report_outside(model: Model, native=None):
    """After a run whose job wrote FibreNet's files itself: the fix's wall check (the
    warning ``outside_message`` the converter gives when it reads the frames itself), and
    how many nan/inf values it wrote into them (``native.nonfinite``: the files are searched
    for their lines only when there are any)."""
    def finished(lmp) -> None:
        from fibrelmp.translate.lammps_job import OUTPUT_FIX

        step, count, bad = (int(lmp.extract_fix(OUTPUT_FIX, 0, 1, k)) for k in (0, 1, 2))   # global vector
        if step >= 0:
            model.warn(OUTSIDE_KIND, outside_message(step, count, model.box.lengths))
        if native is not None:
            native.nonfinite = bad
    return finished
