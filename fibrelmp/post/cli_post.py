"""``fibrelmp post``: convert an existing LAMMPS dump (or any MDAnalysis trajectory).

Frames stream from the reader through ``complete`` (facts from ``--data``, id order,
``--types``) into one writer; only frames that ``--frames`` selects are parsed.
"""

from __future__ import annotations

import gzip
import os
import shutil
import tempfile
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from fibrelmp.errors import InputError, RunError
from fibrelmp.textio import write_failure
from fibrelmp.post.lammps_dump.reader import Frame, frame_from, iter_frames, iter_headers

FORMATS = ("xyz", "res", "mercury", "vtk", "musen", "demdf")


# -- frame selection ------------------------------------------------------------------------
class Selection:
    """``--frames``: ``i``, ``start:stop:step`` (Python slice over frame indices) or a comma
    list of those.  Negative indices count from the end (they need the frame count)."""

    def __init__(self, spec: str | None, default_last: bool = False):
        self.spec = spec
        self.parts: list[tuple[int | None, int | None, int | None] | int] = []
        if spec is None:
            self.parts = [-1] if default_last else [(None, None, None)]
            return
        for part in spec.split(","):
            part = part.strip()
            try:
                if ":" in part:
                    bits = part.split(":")
                    if len(bits) > 3:
                        raise ValueError
                    a, b, c = (bits + [""] * 3)[:3]
                    sl = tuple(int(v) if v.strip() else None for v in (a, b, c))
                    if sl[2] is not None and sl[2] <= 0:
                        raise ValueError
                    self.parts.append(sl)
                else:
                    self.parts.append(int(part))
            except ValueError:
                raise InputError(None, None, f"--frames {spec!r}: expected an index, start:stop:step "
                                 "(positive step) or a comma list of those") from None

    @property
    def needs_count(self) -> bool:
        return any((p < 0) if isinstance(p, int) else any(v is not None and v < 0 for v in p[:2])
                   for p in self.parts)

    def resolve(self, total: int | None) -> Callable[[int], bool]:
        singles, slices = set(), []
        for p in self.parts:
            if isinstance(p, int):
                singles.add(p + total if p < 0 and total is not None else p)
            else:
                a, b, c = p
                if total is not None:
                    a, b, c = slice(a, b, c).indices(total)
                slices.append((a or 0, b, c or 1))
        self.stop = None if any(b is None for _, b, _ in slices) else \
            max([b for _, b, _ in slices] + [s + 1 for s in singles] + [0])

        def want(i: int) -> bool:
            return i in singles or any(i >= a and (b is None or i < b) and (i - a) % c == 0
                                       for a, b, c in slices)
        return want


# -- input ----------------------------------------------------------------------------------
def is_text_dump(path: Path) -> bool:
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
        if head[:2] == b"\x1f\x8b":
            with gzip.open(path, "rb") as fh:
                head = fh.read(4096)
    except (OSError, EOFError):
        return False
    text = head.lstrip()
    return not text or text.startswith(b"ITEM:")


def _mda_format(path: Path) -> bool:
    try:
        from MDAnalysis import _READERS
    except ImportError:
        return False
    ext = path.suffix.lstrip(".").upper()
    return bool(ext) and ext in _READERS and ext not in ("LAMMPSDUMP", "LAMMPSTRJ")


class Source:
    """Frames of the input, native reader or MDAnalysis."""

    def __init__(self, path: Path, topology: Path | None, warnings: list):
        self.path = Path(path)
        self.topology = topology
        self.warnings = warnings
        self.type_names: dict[int, str] = {}
        if not self.path.exists():
            raise InputError(self.path, None, "file not found")
        self.native = is_text_dump(self.path) or self.path.is_dir() or \
            (topology is None and not _mda_format(self.path))

    def count(self) -> int:
        if self.native:
            # warnings come from the conversion pass itself; this pass only counts
            return sum(1 for _ in iter_headers(self.path, [], want=lambda i, h: False))
        from fibrelmp.post.mdanalysis.reader import open_universe
        return len(open_universe(self.path, self.topology).trajectory)

    def frames(self, sel: Selection, last_only: bool = False) -> Iterator[Frame]:
        total = self.count() if sel.needs_count and not last_only else None
        want = sel.resolve(total)
        stop = sel.stop
        if not self.native:
            from fibrelmp.post.mdanalysis.reader import iter_mda_frames
            it = iter_mda_frames(self.path, self.topology, self.type_names,
                                 want=lambda i, ts: want(i) if not last_only else True)
            if last_only:
                last = None
                for last in it:
                    pass
                if last is not None:
                    yield last
                return
            yield from it
            return
        if last_only:
            # keep the newest block unparsed; parse only the one that survives
            last = None
            for head, block in iter_headers(self.path, self.warnings):
                last = (head, block)
            if last is not None:
                yield frame_from(last[0], last[1], self.path)
            return
        seen = [0]

        def wanted(i: int, h) -> bool:
            seen[0] = i + 1
            return want(i)

        for frame in iter_frames(self.path, self.warnings, wanted):
            yield frame
            if stop is not None and seen[0] >= stop:
                return                  # the selection is exhausted: do not read the rest


# -- completing frames -----------------------------------------------------------------------
class Completer:
    """Fill what writers need and the dump lacks; sort atoms by id; apply ``--types``."""

    def __init__(self, data, types: list[str] | None, names: dict[int, str], warnings: list,
                 target_units=None):
        self.data = data
        self.names = names
        self.warnings = warnings
        self.target_units = target_units     # (format name, units.UnitSystem) of the output, if any
        self.warned: set[str] = set()
        self.labels = {v: k for k, v in names.items()}
        self.keep = self._types(types) if types else None
        self.kept_any = False            # --types: some frame had an atom of those types
        self.present: set[int] = set()   # types met until then (for the error if none is)

    def _types(self, tokens: list[str]) -> set[int]:
        out = set()
        for tok in (t.strip() for item in tokens for t in item.split(",")):
            if not tok:
                continue
            if tok.lstrip("-").isdigit():
                out.add(int(tok))
            elif tok in self.labels:
                out.add(self.labels[tok])
            else:
                known = ", ".join(f"{v}={k}" for k, v in sorted(self.names.items())) or "none (give --data)"
                raise InputError(None, None, f"--types: unknown type {tok!r} (type names: {known})")
        return out

    def _warn(self, key: str, text: str) -> None:
        if key not in self.warned:
            self.warned.add(key)
            self.warnings.append((key, text))

    def __call__(self, frame: Frame) -> Frame:
        cols = dict(frame.columns)
        n = frame.count
        data = self.data
        if self.target_units is not None and frame.units is not None:
            from fibrelmp.units import mismatch_note

            note = mismatch_note(frame.units, self.target_units[1], self.target_units[0])
            if note is not None:
                self._warn("units", f"{frame.source}: {note}")
        if "id" not in cols:
            cols["id"] = np.arange(1, n + 1, dtype=np.float64)
            self._warn("no ids", f"{frame.source}: the dump has no 'id' column; atoms are numbered "
                       "1..N in file order")
        ids = cols["id"]
        if n > 1 and not bool(np.all(ids[1:] > ids[:-1])):
            order = np.argsort(ids, kind="stable")
            cols = {k: v[order] for k, v in cols.items()}
            ids = cols["id"]
            twice = np.flatnonzero(ids[1:] == ids[:-1])
            if len(twice):        # every writer keys atoms by id: two would be merged or doubled
                raise InputError(frame.source, frame.line, f"atom id {ids[twice[0]]:.0f} appears "
                                 f"twice in the frame of step {frame.step}")
        rows = None
        if data is not None and n:
            rows = data.rows(ids, "--data facts")
        if "type" not in cols:
            if rows is not None:
                cols["type"] = data.types[rows].astype(np.float64)
            else:
                cols["type"] = np.ones(n)
                self._warn("no types", f"{frame.source}: the dump has no 'type' column and no --data "
                           "was given; every atom is type 1")
        elif cols["type"].dtype.kind not in "fiu":       # type labels (dump_modify types labels)
            codes = np.empty(n)
            for k, lab in enumerate(cols["type"]):
                if lab not in self.labels:
                    self.labels[lab] = max(list(self.names) + [0]) + 1
                    self.names[self.labels[lab]] = lab
                codes[k] = self.labels[lab]
            cols["type"] = codes
        if "radius" not in cols:
            if "diameter" in cols:
                cols["radius"] = cols["diameter"] / 2
            elif rows is not None and data.radius is not None:
                cols["radius"] = data.radius[rows]
        if "mass" not in cols and rows is not None and data.mass is not None:
            cols["mass"] = data.mass[rows]
        out = Frame(frame.step, frame.lo, frame.hi, frame.boundary, cols, frame.tilt, frame.time,
                    frame.line, frame.units, frame.source)
        if not out.has("x", "y", "z"):
            x = out.positions()
            if x is not None:
                cols.update(x=x[:, 0], y=x[:, 1], z=x[:, 2])
            elif not out.has("xu", "yu", "zu"):
                xu = out.unwrapped()
                if xu is None:
                    out.wrapped()                      # raises the "no positions" error
                cols.update(xu=xu[:, 0], yu=xu[:, 1], zu=xu[:, 2])
        for names in (("x", "y", "z"), ("xu", "yu", "zu")):
            if out.has(*names):
                bad = ~np.isfinite(out.vector(*names)).all(axis=1)
                if bad.any():     # a blown-up run: no output format can hold these
                    k = int(np.flatnonzero(bad)[0])
                    raise InputError(frame.source, frame.line, f"atom id {ids[k]:.0f} has position "
                                     f"{out.vector(*names)[k].tolist()} in the frame of step "
                                     f"{frame.step} (did the simulation blow up?)")
        if self.keep is not None:
            codes = cols["type"].astype(np.int64)
            mask = np.isin(codes, list(self.keep))
            if not self.kept_any:
                self.kept_any = bool(mask.any())
                if not self.kept_any:
                    self.present.update(np.unique(codes).tolist())
            out = out.select(mask)
        return out

    def check_types(self, source) -> None:
        """``--types`` selecting no atom of any frame read is an error, not empty frames."""
        if self.keep is None or self.kept_any:
            return
        name = lambda t: f"{self.names[t]}={t}" if t in self.names else str(t)     # noqa: E731
        have = ", ".join(name(t) for t in sorted(self.present)) or "none (no atoms)"
        raise InputError(source, None, f"--types {', '.join(name(t) for t in sorted(self.keep))}: "
                         f"no atom of the selected frames has these types (types present: "
                         f"{have}); nothing written")


# -- the command -----------------------------------------------------------------------------
def _outputs(to: str, out: Path, dump: Path) -> tuple[Path, list[Path]]:
    """(base path, files the conversion will write) for ``-o``."""
    base = out / dump.name.split(".")[0] if out.is_dir() else out
    if to == "xyz":
        from fibrelmp.translate.fibrenet.writer import XYZ_SUFFIX
        files = [base.with_name(base.name + s) for s in XYZ_SUFFIX.values()]
    elif to == "res":
        from fibrelmp.translate.fibrenet.writer import RESTART_SUFFIX
        files = [base.with_name(base.name + RESTART_SUFFIX)]
    elif to == "mercury":
        files = [base.with_name(base.name + s) for s in (".data", ".ene", ".fstat")]
    elif to == "vtk":
        files = [base.with_name(base.name + ".pvd")] + \
            sorted(base.parent.glob(f"{base.name}_[0-9][0-9][0-9][0-9][0-9][0-9].vtu"))
    elif to == "demdf":           # snapshots <base>_<n>.json
        files = sorted(p for p in base.parent.glob(f"{base.name}_*.json")
                       if p.stem[len(base.name) + 1:].isdigit())
    else:
        files = [base]
    return base, files


def _time_of(frame: Frame, warn: Callable[[str, str], None]) -> float:
    if frame.time is not None:
        return frame.time
    warn("no times", f"{frame.source}: no ITEM: TIME in the dump (dump_modify time yes); the step "
         "number is written as the time")
    return float(frame.step)


def _peek(frames: Iterator[Frame], k: int) -> tuple[list[Frame], Iterator[Frame]]:
    head = []
    for f in frames:
        head.append(f)
        if len(head) == k:
            break

    def chain():
        yield from head
        yield from frames
    return head, chain()


def _dt(first: list[Frame], warn) -> float:
    """The MD time step for FibreNet's FRAME lines: from ITEM: TIME values when present."""
    for f in first:
        if f.time is not None and f.step:
            return f.time / f.step
    if len(first) == 2 and all(f.time is not None for f in first) and first[1].step != first[0].step:
        return (first[1].time - first[0].time) / (first[1].step - first[0].step)
    warn("no time step", "the dump does not give the time step (no ITEM: TIME); FRAME lines carry dt 0")
    return 0.0


def post_command(dump: Path, to: str | None, out: Path | None, info: bool, frames: str | None,
                 types: list[str] | None, data: Path | None, local: Path | None,
                 gravity: tuple | None, force: bool, topology: Path | None,
                 say: Callable[[str], None],
                 report: Callable[[list[tuple[str, str]]], None] | None = None) -> list[Path]:
    """Convert ``dump`` (see docs/post.md); returns the files written.  Warnings go to
    ``report`` (the CLI's grouped, coloured report) or, without one, to ``say``."""
    dump = Path(dump)
    warnings: list[tuple[str, str]] = []
    try:
        return _post(dump, to, out, info, frames, types, data, local, gravity, force, topology, say, warnings)
    finally:
        if report is not None:
            report(warnings)
        else:
            _report(warnings, say)


def _report(warnings: list[tuple[str, str]], say) -> None:
    groups: dict[str, list[str]] = {}
    for kind, text in warnings:
        groups.setdefault(kind, []).append(text)
    for kind, texts in groups.items():
        more = f" (and {len(texts) - 1} more)" if len(texts) > 1 else ""
        say(f"warning [{kind}]: {texts[0]}{more}")


def _post(dump, to, out, info, frames, types, data, local, gravity, force, topology, say, warnings):
    source = Source(dump, topology, warnings)
    if info:
        from fibrelmp.post.lammps_dump.info import describe_dump, describe_universe
        lines = describe_dump(dump, warnings) if source.native else describe_universe(dump, topology)
        for ln in lines:
            say(ln)
        return []
    if to is None:
        raise InputError(None, None, "choose an output with --to (" + ", ".join(FORMATS) + ") or use --info")
    to = to.lower()
    if to not in FORMATS:
        raise InputError(None, None, f"--to {to!r}: unknown format (choose from {', '.join(FORMATS)})")
    if out is None:
        raise InputError(None, None, "give the output with -o/--out")
    if local is not None and to != "mercury":
        raise InputError(local, None, "--local (per-contact data) is used by --to mercury only")
    base, files = _outputs(to, Path(out), dump)
    existing = [p for p in files if p.exists()]
    if existing and not force:
        raise InputError(existing[0], None, "output exists; use --force to overwrite")
    created = [p for p in (base.parent, *base.parent.parents) if not p.exists()]
    if created:
        try:
            base.parent.mkdir(parents=True)
        except OSError as exc:
            raise InputError(base.parent, None, f"cannot create output folder: {exc.strerror or exc}") from None
    try:
        return _convert(dump, to, base, source, data, types, frames, local, gravity, warnings)
    except BaseException:
        for folder in created:        # a failed conversion leaves no new (empty) folders
            try:
                folder.rmdir()
            except OSError:
                break
        raise


def _convert(dump, to, base, source, data, types, frames, local, gravity, warnings) -> list[Path]:
    """The conversion proper, once the output folder exists; returns the files written."""
    datafile = None
    if data is not None:
        from fibrelmp.post.lammps_data.reader import read_data
        datafile = read_data(data)
    names: dict[int, str] = dict(datafile.type_names) if datafile else {}
    from fibrelmp.units import LJ, SI

    # FibreNet files hold LAMMPS reduced numbers, MUSEN files SI; the others have no units
    targets = {"xyz": ("FibreNet", LJ), "res": ("FibreNet", LJ), "musen": ("MUSEN", SI)}
    complete = Completer(datafile, types, names, warnings, targets.get(to))
    sel = Selection(frames, default_last=(to == "res"))

    def completed():
        yield from (complete(f) for f in source.frames(sel, last_only=(to == "res" and frames is None)))
        complete.check_types(dump)        # before the writers finish their files
    stream = completed()

    def warn(kind: str, text: str) -> None:
        if kind not in {k for k, _ in warnings}:
            warnings.append((kind, text))

    # Convert into a staging folder beside the outputs and move the files into place only
    # when the whole conversion succeeded: a bad frame half-way leaves earlier outputs
    # (replaced with --force) untouched and writes nothing.
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{base.name}.post-", dir=base.parent))
    except OSError as exc:
        raise write_failure(base.parent, exc) from None
    try:
        try:
            written = _CONVERTERS[to](stream, stage / base.name, datafile, names, source, local,
                                      gravity, warn, warnings)
        except (InputError, RunError) as exc:
            raise _unstaged(exc, stage, base.parent) from None
        except OSError as exc:            # a writer without its own message (mercury's .data...)
            raise _unstaged(write_failure(base, exc), stage, base.parent) from None
        complete.check_types(dump)
        if not written:
            raise InputError(dump, None, "no complete frame was selected; nothing written")
        if to == "vtk":
            from fibrelmp.post.vtk.writer import remove_stale
            remove_stale(base)    # frames of an earlier conversion (exist only with --force)
        final = []
        for path in written:
            target = base.parent / Path(path).relative_to(stage)
            try:
                os.replace(path, target)
            except OSError as exc:
                raise write_failure(target, exc) from None
            final.append(target)
        return final
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _unstaged(exc: InputError | RunError, stage: Path, folder: Path) -> InputError | RunError:
    """``exc`` with the outputs' staging folder in its path or message replaced by the output
    folder: a writer's error (a full disk...) names the output the user asked for."""
    staged = str(stage)
    if isinstance(exc, InputError):
        if exc.path is None or not exc.path.startswith(staged):
            return exc
        return InputError(str(folder) + exc.path[len(staged):], exc.line, exc.message)
    text = Exception.__str__(exc)
    return RunError(text.replace(staged, str(folder))) if staged in text else exc


class _Names(dict):
    """Type names for FibreNet files, looked up in live tables (labels met later in the
    stream are added to them); a type without a name is written as its number."""

    def __init__(self, *live: dict[int, str]):
        super().__init__()
        self.live = live

    def __missing__(self, key: int) -> str:
        for table in self.live:
            if key in table:
                return table[key]
        return str(key)


def _to_fibrenet(stream, base, datafile, names, source, local, gravity, warn, warnings, restart: bool):
    from fibrelmp.post.to_fibrenet import write_fibrenet

    first, stream = _peek(stream, 2)
    if not first:
        return []
    dt = _dt(first, warn)
    table = _Names(names, source.type_names)
    fields = () if restart else ("position", "velocity", "force")
    if not restart:
        have = first[0].columns
        fields = tuple(f for f, cols in (("position", ("x",)), ("velocity", ("vx", "v_fn_vx")),
                                         ("force", ("fx", "v_fn_fx")))
                       if f == "position" or any(c in have for c in cols))
        missing = sorted({"velocity", "force"} - set(fields))
        if missing:
            warn("missing fields", f"{source.path}: no {' or '.join(missing)} columns; only "
                 + ", ".join(f"_{'coord' if f == 'position' else f[:3]}.xyz" for f in fields) + " written")
    else:
        for need, cols in (("velocity", ("vx", "vy", "vz")), ("force", ("fx", "fy", "fz"))):
            if not (first[0].has(*cols) or first[0].has(*("v_fn_" + c[0] + c[1] for c in cols))):
                raise InputError(source.path, first[0].line, f"a FibreNet restart needs {need}: "
                                 f"the dump has no {' '.join(cols)} columns")
    return write_fibrenet(stream, base.name, base.parent, fields, table, dt, None, None, restart=restart)


def _to_xyz(*args):
    return _to_fibrenet(*args, restart=False)


def _to_res(*args):
    return _to_fibrenet(*args, restart=True)


def _to_mercury(stream, base, datafile, names, source, local, gravity, warn, warnings):
    from fibrelmp.post.mercury.writer import MercuryWriter, iter_matching

    g = np.zeros(3) if gravity is None else np.asarray(gravity, float)
    bonds = {tuple(map(int, b)) for b in datafile.bonds} if datafile is not None else None
    writer = MercuryWriter(base, g, fstat=local is not None, bonds=bonds)
    local_frames = iter_frames(local, warnings) if local is not None else None
    pending: list = []
    count = 0
    try:
        for frame in stream:
            time = _time_of(frame, warn)
            lf = None
            if local_frames is not None:
                lf = iter_matching(local_frames, frame.step, pending)
                if lf is None:
                    warn("no contacts", f"{local}: no local-dump frame for step {frame.step}; its .fstat "
                         "frame has no contact lines")
            writer.write(frame, time, lf)
            count += 1
    except BaseException:
        writer.abort()
        raise
    if count and (local is None or writer.no_elastic):
        warn("no elastic energy", "elasticEnergy in the .ene file is 0: it comes from an 'eng' column "
             "of a --local contact dump")
    if not count:
        writer.abort()
        return []
    paths = writer.close()
    return paths


def _to_vtk(stream, base, datafile, names, source, local, gravity, warn, warnings):
    from fibrelmp.post.vtk.writer import VtkWriter

    writer = VtkWriter(base, datafile.bonds if datafile is not None else None)
    try:
        for frame in stream:
            writer.write(frame, _time_of(frame, warn))
    except BaseException:
        writer.abort()
        raise
    if not writer.entries:
        return []
    return writer.close()


def _to_granular(kind: str, stream, base, source, names, warn):
    """MUSEN result / DEMDF snapshots through the neutral granular model and the same
    writers ``fibrelmp run`` uses."""
    from fibrelmp.post.to_granular import demdf_document, granular_frames, model_from_frame

    first, stream = _peek(stream, 2)
    if not first:
        return []
    times = [_time_of(f, warn) for f in first]
    dt = times[1] - times[0] if len(times) > 1 else 1.0
    model = model_from_frame(first[0], Path(source.path), {**source.type_names, **names}, kind,
                             times[0], dt)
    frames = granular_frames(((f, _time_of(f, warn)) for f in stream), model)
    if kind == "musen":
        from fibrelmp.translate.musen.writer import MusenResultWriter

        writer = MusenResultWriter(model, base)
        done = lambda: [writer.close()]                          # noqa: E731
    else:
        from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

        s = model.spheres
        model.passthrough["demdf"] = {
            "document": demdf_document(model, base.name), "dimensionality": 3,
            "particle_rows": [[0.0] * 6 + [int(t)] for t in s.material],
            "particles_file": None, "output_location": ("output", "snapshot"),
            "filename": base.name, "save_count": 0, "file_time_step": dt, "substeps": 1,
            "time_step_count": 0}
        writer = DemdfSnapshotWriter(model, base.parent)
        done = lambda: (writer.close(), list(writer.written))[1]  # noqa: E731
    count = 0
    try:
        for frame in frames:
            writer.add(frame)
            count += 1
    except BaseException:
        writer.abort()
        raise
    if not count:
        writer.abort()
        return []
    for kind_, text in model.warnings:
        warn(kind_, text)
    return done()


def _to_musen(stream, base, datafile, names, source, local, gravity, warn, warnings):
    return _to_granular("musen", stream, base, source, names, warn)


def _to_demdf(stream, base, datafile, names, source, local, gravity, warn, warnings):
    return _to_granular("demdf", stream, base, source, names, warn)


_CONVERTERS = {"xyz": _to_xyz, "res": _to_res, "mercury": _to_mercury, "vtk": _to_vtk,
               "musen": _to_musen, "demdf": _to_demdf}
