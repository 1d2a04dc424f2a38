"""``fibrelmp post``: convert a LAMMPS dump (or any MDAnalysis trajectory) into a target format.

Frames stream from the frame reader the registry has for the input (``frames`` role) through
the ``Completer`` (facts from ``--data``, id order, ``--types``) into the target the registry
has for ``--to`` (``target`` role, a ``post.target.DumpTarget``); only frames that
``--frames`` selects are parsed.  Nothing here knows a format: what differs between targets
is in their classes (files, units, last_frame_by_default, uses_local).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Iterator

from fibrelmp.errors import InputError
from fibrelmp.post.complete import Completer
from fibrelmp.post.selection import Selection
from fibrelmp.post.target import DumpTarget, PostContext, TypeNames
from fibrelmp.registry import FRAMES, TARGET, choose, formats, names
from fibrelmp.textio import refuse_special_file


def post_command(dump: Path, to: str | None, out: Path | None, info: bool, frames: str | None,
                 types: list[str] | None, data: Path | None, local: Path | None,
                 gravity: tuple | None, force: bool, topology: Path | None,
                 say: Callable[[str], None],
                 report: Callable[[list[tuple[str, str]]], None] | None = None,
                 precision: int | None = None) -> list[Path]:
    """Convert ``dump`` (see docs/post.md); returns the files written.  Warnings go to
    ``report`` (the CLI's grouped, coloured report) or, without one, to ``say``.

    Under MPI (``mpiexec -n N``) rank 0 does the conversion and writes; the other ranks
    touch no file, return ``[]`` and wait for rank 0 (an error on rank 0 aborts them all)."""
    from fibrelmp._lammps import mpi_wait_for_all
    from fibrelmp.runner import mpi_rank_size

    dump = Path(dump)
    if mpi_rank_size()[0] != 0:
        mpi_wait_for_all()
        return []
    warnings: list[tuple[str, str]] = []
    try:
        written = _post(dump, to, out, info, frames, types, data, local, gravity, force, topology,
                        say, warnings, precision)
    except InputError as exc:
        if exc.path is not None:
            raise
        # an option's error (--to pdb, --precision 0, ...): name the trajectory, not "<input>"
        raise InputError(dump, exc.line, exc.message) from None
    finally:
        if report is not None:
            report(warnings)
        else:
            _report(warnings, say)
    mpi_wait_for_all()                  # the other ranks wait here for the files to be written
    return written


def _report(warnings: list[tuple[str, str]], say) -> None:
    groups: dict[str, list[str]] = {}
    for kind, text in warnings:
        groups.setdefault(kind, []).append(text)
    for kind, texts in groups.items():
        more = f" (and {len(texts) - 1} more)" if len(texts) > 1 else ""
        say(f"warning [{kind}]: {texts[0]}{more}")


def open_frames(path: Path, topology: Path | None, warnings: list):
    """The frame reader for ``path``: the first registered one that claims the file, else
    the first registered one (which then explains what is wrong with the file)."""
    if not path.exists():
        raise InputError(path, None, "file not found")
    refuse_special_file(path, "trajectory")     # a FIFO would block the format test for ever
    readers = [f.load(FRAMES) for f in formats(FRAMES)]
    kind = next((r for r in readers if r.claims(path, topology)), readers[0])
    return kind(path, topology, warnings)


def _post(dump, to, out, info, frames, types, data, local, gravity, force, topology, say, warnings,
          precision=None):
    reader = open_frames(dump, topology, warnings)
    if info:
        for ln in reader.describe():
            say(ln)
        return []
    if to is None:
        raise InputError(None, None, f"choose an output with --to ({', '.join(names(TARGET))}) or use --info")
    kind: type[DumpTarget] = choose(TARGET, to.lower(), "--to").load(TARGET)
    if out is None:
        raise InputError(None, None, "give the output with -o/--out")
    if local is not None and local.exists():
        refuse_special_file(local, "--local dump")
    if local is not None and not kind.uses_local:
        users = " or ".join(f.name for f in formats(TARGET) if f.load(TARGET).uses_local)
        raise InputError(local, None, f"--local (per-contact data) is used by --to {users} only")
    if precision is not None:
        if not 1 <= precision <= 17:
            raise InputError(None, None, f"--precision must be 1..17, got {precision}")
        if not kind.takes_precision:
            users = " or ".join(f.name for f in formats(TARGET) if f.load(TARGET).takes_precision)
            raise InputError(None, None, f"--precision has no meaning for --to {to.lower()}: only "
                             f"--to {users} writes numbers with a chosen number of digits")
    out = Path(out)
    base = out / dump.name.split(".")[0] if out.is_dir() else out
    context = PostContext(dump, local=local, gravity=gravity, warnings=warnings, precision=precision,
                          target_name=to.lower())
    target = kind(base, context, force=force)        # refuses existing outputs without force
    created = [p for p in (base.parent, *base.parent.parents) if not p.exists()]
    if created:
        try:
            base.parent.mkdir(parents=True)
        except OSError as exc:
            raise InputError(base.parent, None, f"cannot create output folder: {exc.strerror or exc}") from None
    try:
        return _convert(reader, target, dump, data, types, frames)
    except BaseException:
        target.abort()
        for folder in created:        # a failed conversion leaves no new (empty) folders
            try:
                folder.rmdir()
            except OSError:
                break
        raise


def _convert(reader, target: DumpTarget, dump: Path, data: Path | None, types: list[str] | None,
             frames: str | None) -> list[Path]:
    """The conversion proper, once the output folder exists; returns the files written."""
    context = target.context
    if data is not None:
        from fibrelmp.post.lammps_data.reader import read_data
        if data.is_dir() and (data / "data.lammps").is_file():
            data = data / "data.lammps"           # --data of a fibrelmp work folder: its data file
        context.datafile = read_data(data)
    else:
        from fibrelmp.translate.work_facts import facts_path

        beside = dump.parent / "data.lammps"
        if facts_path(beside).is_file():
            context.warn("work folder", f"{dump} is a fibrelmp job's dump: give --data {beside} "
                         "for the run's names, ids and exact times (docs/post.md)")
    known: dict[int, str] = dict(context.datafile.type_names) if context.datafile else {}
    context.type_names = TypeNames(known, reader.type_names)    # labels met later join ``known``
    complete = Completer(context.datafile, types, known, context.warnings, target.units,
                         target.check_finite)
    for frame in _selected(reader, Selection(frames, default_last=target.last_frame_by_default),
                           last_only=target.last_frame_by_default and frames is None):
        target.add(complete(frame))
    complete.check_types(dump)        # before the target finishes its files
    if not target.count:
        raise InputError(dump, None, "no complete frame was selected; nothing written")
    return target.close()


def _selected(reader, sel: Selection, last_only: bool) -> Iterator:
    if last_only:
        last = reader.last()
        if last is not None:
            yield last
        return
    total = reader.count() if sel.needs_count else None
    if total is not None and sel.spec is not None:
        sel.check(total, reader.what, reader.path)
    chosen = sel.resolve(total)
    last = [-1]                         # the highest frame index the reader came to

    def want(i: int) -> bool:
        last[0] = max(last[0], i)
        return chosen(i)

    yield from reader.frames(want, sel.stop)
    if total is None and sel.spec is not None and (sel.stop is None or last[0] + 1 < sel.stop):
        sel.check(last[0] + 1, reader.what, reader.path)     # the reader met the end: last + 1 frames
