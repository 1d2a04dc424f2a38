"""The Python API: what the command line does, as functions that return results.

``fibrelmp.read``, ``fibrelmp.translate_job``, ``fibrelmp.run`` and ``fibrelmp.convert``
(see docs/python.md; ``fibrelmp.translate`` is the translators' subpackage).  They raise ``fibrelmp.InputError`` (bad input, ``path:line: message``) or
``fibrelmp.RunError`` (LAMMPS or the machine failed) and never exit the interpreter; a run
restores the signal handlers it installed for checkpoints when it returns.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Iterator

from fibrelmp.errors import InputError

Say = Callable[[str], None]
Warn = Callable[[list[tuple[str, str]]], None]


def _quiet(_: object) -> None:
    pass


def _input(path: Path):
    """The INPUT hook of the input's format (``fibrelmp.inputformat.InputFormat``)."""
    from fibrelmp.registry import INPUT, detect

    return detect(path).load(INPUT)()


def read(path: str | Path):
    """The neutral model of any supported input (``fibrelmp.registry.formats("input")``): a
    ``Model`` (bead-spring networks), a ``GranularModel`` (DEM scenes) or, for a job script of
    several simulations, its checked ``ScriptPlan``."""
    path = Path(path)
    return _input(path).read(path)


def translate_job(path: str | Path, folder: str | Path, warn: Warn | None = None, *,
                  stock_styles: bool = False) -> Path:
    """Write ``folder/in.lammps`` and its data file for the input at ``path`` (a job
    script: its first simulation); returns the script's path (replay: ``lmp -in in.lammps``).
    ``warn`` receives the input's warnings, then those the translation found.
    ``stock_styles``: a job for a LAMMPS without the PLUGIN package (fibrelmp's own styles
    replaced by stock ones; where that approximates the source's physics a warning says so)."""
    return write_job(path, folder, warn, stock_styles=stock_styles).script


def write_job(path: str | Path, folder: str | Path, warn: Warn | None = None, *,
              stock_styles: bool = False):
    """``translate_job``, returning the job (``.script``, ``.data``)."""
    from fibrelmp import lammps_styles

    path = Path(path)
    hook = _input(path)
    model = hook.model(path)
    said = len(model.warnings)
    if warn is not None:
        warn(model.warnings)
    with lammps_styles.stock(stock_styles):
        job = hook.write_job(model, Path(folder))
    if warn is not None and model.warnings[said:]:
        warn(model.warnings[said:])
    return job


@dataclass
class RunResult:
    """What a run wrote: the result files in the input's own format, and each simulation's
    LAMMPS script and frame dump (read back lazily: memory does not grow with frames)."""
    outputs: list[Path] = field(default_factory=list)
    scripts: list[Path] = field(default_factory=list)
    dumps: list[Path] = field(default_factory=list)
    warnings: list[tuple[str, str]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    summaries: list[dict] = field(default_factory=list)   # per simulation (docs/record.md)

    def frames(self, simulation: int = -1) -> Iterator:
        """The saved frames of one simulation (default: the last), one at a time, as
        ``fibrelmp.post.lammps_dump.reader.Frame`` (``.step``, ``.column('x')``, ``.vector('x','y','z')``)."""
        from fibrelmp.post.convert import open_frames       # the registered reader that claims it

        return iter(open_frames(self.dumps[simulation], None, []))

    def universe(self, simulation: int = -1):
        """The frames as an MDAnalysis ``Universe`` (``ts.time`` is the dump's ITEM: TIME)."""
        from fibrelmp.post.convert import open_frames

        return open_frames(self.dumps[simulation], None, []).universe()


def run(path: str | Path, out: str | Path | None = None, *, work: str | Path | None = None,
        force: bool = False, checkpoint_every: int | None = None, resume: bool = False,
        end_time: float | None = None, step: float | None = None, save_step: float | None = None,
        steps: int | None = None, precision: int | None = None, progress: bool = False,
        stock_styles: bool = False, also: Iterable[str] = (), say: Say = _quiet,
        warn: Warn | None = None, log_every: str | None = None,
        allow_huge: bool = False, viewer_files: bool = False) -> RunResult:
    """Run any supported input on LAMMPS and write its results in the input's own format.

    ``out``: the results' folder, or the result file of an input with a single result;
    default next to the input.  Existing results are replaced, completely, only with
    ``force``.  ``end_time``/``step``/``save_step`` and ``steps`` override the
    input's (an input that sets them itself refuses them).  ``precision``: significant
    digits of text results that take it (default 6; refused for the others).  ``stock_styles``: stock LAMMPS
    styles instead of fibrelmp's own (see ``translate_job``).  ``also`` (``run --also``):
    formats also written from every saved frame beside the results, any of
    ``fibrelmp.registry.names("also")`` (``fibrelmp.also``; the files are in
    ``outputs``); ``viewer_files=True`` is deprecated: every one of them.  ``say`` receives progress notes, ``warn`` lists of
    ``(kind, text)`` warnings as they are found (they are also in the result).  ``progress``:
    a bar on a terminal, else a line on stderr every ``log_every`` (``"10%"``, ``"60s"``,
    ``"10%,5m"``: the default).  Each simulation's summary (``summary.json``) is in
    ``summaries``.

    A run that cannot finish is refused before anything is written (``InputError``): step
    counts LAMMPS cannot hold, an estimated output larger than the free disk space, or an
    optimistic run time beyond 30 days (``fibrelmp.sanity.run_budget``); ``allow_huge``
    (``run --yes-i-mean-it``) lifts the last two."""
    from fibrelmp.checkpoint import check_every
    from fibrelmp.pipeline import RunOptions, run as run_plan
    from fibrelmp.also import chosen
    from fibrelmp.inputformat import RunSettings

    path = Path(path)
    hook = _input(path)
    check_every(checkpoint_every)         # before any folder is made
    also = [also] if isinstance(also, str) else list(also)
    if viewer_files:
        import warnings

        from fibrelmp.registry import ALSO, names

        warnings.warn(f"run(viewer_files=True) is deprecated: use also={names(ALSO)!r}",
                      DeprecationWarning, stacklevel=2)
        also += names(ALSO)
    also = chosen(also)                   # an unknown name: an InputError listing the choices
    if precision is not None:
        _check_precision(precision)
        unused = hook.precision_unused(path, None if out is None else Path(out))
        if unused is not None:
            raise InputError(path, None, f"--precision has no meaning here: {unused}")
    from fibrelmp.runner import parse_log_every

    every = None if log_every is None else parse_log_every(log_every)
    result = RunResult()

    def warned(items: list[tuple[str, str]]) -> None:
        result.warnings.extend(items)
        if warn is not None and items:
            warn(list(items))

    settings = RunSettings(None if out is None else Path(out), None if work is None else Path(work),
                           end_time, step, save_step, steps, 6 if precision is None else precision,
                           also=also)
    if resume and not hook.has_checkpoint(path, settings.out, settings.work):    # before reading
        from .checkpoint import NO_CHECKPOINT

        raise InputError(path, None, NO_CHECKPOINT)
    from fibrelmp import lammps_styles

    with lammps_styles.stock(stock_styles):
        plan = hook.plan(path, settings, RunOptions(progress, force, checkpoint_every, resume, every,
                                              allow_huge), say, warned)
        outcome = run_plan(plan, warn=warned)
    result.outputs, result.notes = outcome.outputs, list(plan.notes)
    result.scripts = [job.script for job in outcome.jobs]
    result.dumps = [job.job.frames for job in outcome.jobs]
    result.summaries = outcome.summaries
    return result


def convert(dump: str | Path, to: str | None, out: str | Path | None, *, frames: str | None = None,
            types: list[str] | None = None, data: str | Path | None = None,
            local: str | Path | None = None, gravity: tuple[float, float, float] | None = None,
            force: bool = False, topology: str | Path | None = None, say: Say = _quiet,
            warn: Warn | None = None, precision: int | None = None) -> list[Path]:
    """Convert a trajectory (``fibrelmp.registry.formats("frames")``; ``topology`` for those
    that need one) into ``to``, any of ``fibrelmp.registry.names("target")``; returns the
    files written (docs/post.md).  ``precision``: significant digits, for targets that write
    text with a chosen number of them (refused for the others).  ``warn`` receives the conversion's ``(kind, text)``
    warnings (without it they go to ``say`` as text)."""
    from fibrelmp.post.convert import post_command

    return post_command(Path(dump), to, None if out is None else Path(out), False, frames, types,
                        None if data is None else Path(data), None if local is None else Path(local),
                        gravity, force, None if topology is None else Path(topology), say,
                        report=warn, precision=precision)


def convert_file(source: str | Path, target: str | Path, *, to: str | None = None,
                 precision: int | None = None, force: bool = False) -> list[Path]:
    """Convert a whole scene/result file into another form of the same code (the registry's
    ``document`` formats, e.g. a code's binary and text forms of a scene).  The target's format is ``to``, else its
    file name's suffix; ``precision``: significant digits of text time-point values (default
    6, as the codes write).  Returns the written path; existing files are kept unless ``force``."""
    from fibrelmp.registry import DOCUMENT, choose, detect, formats, names

    source, target = Path(source), Path(target)
    fmt = detect(source)
    if DOCUMENT not in fmt.roles:
        raise InputError(source, None, f"{fmt.title} cannot be converted (convert takes "
                         f"{', '.join(f.title for f in formats(DOCUMENT))})")
    if to is not None:
        out_fmt = choose(DOCUMENT, to, "--to")
    else:
        hits = [f for f in formats(DOCUMENT) if target.suffix.lower() in f.load(DOCUMENT).suffixes]
        if not hits:
            raise InputError(target, None, f"cannot tell the output format from the name: use "
                             f"--to ({', '.join(names(DOCUMENT))})")
        out_fmt = hits[0]
    if target.resolve() == source.resolve():
        raise InputError(target, None, "the output would overwrite the input; choose another name")
    if precision is not None:
        _check_precision(precision)
        if not out_fmt.load(DOCUMENT).takes_precision:
            raise InputError(target, None, f"--precision has no meaning for {out_fmt.title}: it "
                             "stores every number exactly")
    doc = fmt.load(DOCUMENT).open(source)
    try:
        with out_fmt.load(DOCUMENT).writer(target, precision, force=force) as writer:
            writer.add(doc)
    finally:
        doc.close()
    return [target]


def _check_precision(precision: int) -> None:
    if not 1 <= precision <= 17:
        raise InputError(None, None, f"--precision must be 1..17, got {precision}")


@dataclass
class CheckReport:
    """What ``fibrelmp check`` prints: summary lines and the input's warnings."""
    format: str
    lines: list[str]
    warnings: list[tuple[str, str]]


def check(path: str | Path, *, stock_styles: bool = False) -> CheckReport:
    """Parse and validate an input without running LAMMPS.  For line-oriented formats every
    error is collected: several raise ``InputErrors`` (an ``InputError`` listing them).
    The report says which LAMMPS styles a run would use (``stock_styles``: see ``translate_job``)."""
    from . import lammps_styles
    from .registry import INPUT, detect

    path = Path(path)
    fmt = detect(path)
    hook = fmt.load(INPUT)()
    model = _read_for_check(lambda: hook.model(path), lambda: hook.check_patch(path))
    with lammps_styles.stock(stock_styles):     # the wall lines depend on the styles too
        styles = lammps_styles.plugin().describe() if hook.styles is None else hook.styles
        lines = hook.check_lines(path, model)
        lines[-1:-1] = [f"{'styles':<12} {styles}"]      # before the last line: where results go
    return CheckReport(fmt.name, lines, list(model.warnings))


def _read_for_check(read, patch):
    """``read()``; on an input error in a line-oriented format (``patch()`` is not None),
    every error of the file (the readers stop at the first: ``collect_errors`` re-reads with
    failing lines patched out)."""
    from .errors import InputErrors
    from .textio import MAX_ERRORS, collect_errors

    try:
        return read()
    except InputError as first:
        fix = patch()
        if fix is None:
            raise
        errors = collect_errors(read, first, fix)
    if len(errors) == 1:
        raise errors[0]
    files = list(dict.fromkeys(e.path for e in errors))          # in the order they were met
    errors.sort(key=lambda e: (files.index(e.path), e.line or 0))
    raise InputErrors(errors, at_limit=len(errors) >= MAX_ERRORS)


def describe(dump: str | Path, topology: str | Path | None = None, say: Say = print,
             warn: Warn | None = None) -> None:
    """``fibrelmp post --info``: frames, atoms, columns and box of a trajectory, line by line
    to ``say``; ``warn`` as in ``convert``."""
    from .post.convert import post_command

    post_command(Path(dump), None, None, True, None, None, None, None, None, False,
                 None if topology is None else Path(topology), say, report=warn)


def plot(result: str | Path, out: str | Path | None = None, *, source: str = "auto",
         size: tuple[int, int] | str | None = None, force: bool = False):
    """``fibrelmp plot``: the energy/thermo history of a result (a run's work folder, its
    ``log.lammps`` or a result file) as a PNG; returns a ``fibrelmp.pictures.Plot`` (the
    file, the data source used and every line as drawn).  Needs matplotlib."""
    from fibrelmp.pictures import plot as draw

    return draw(result, out, source=source, size=size, force=force)


def snapshot(result: str | Path, out: str | Path | None = None, *, frame: int | None = None,
             size: tuple[int, int] | str | None = None, force: bool = False):
    """``fibrelmp snapshot``: one frame of a result as a PNG (``frame`` negative: from the
    end; default the last); returns a ``fibrelmp.pictures.Snapshot`` (what was drawn)."""
    from fibrelmp.pictures import snapshot as draw

    return draw(result, out, frame=frame, size=size, force=force)
