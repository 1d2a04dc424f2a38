"""The Python API: what the command line does, as functions that return results.

``fibrelmp.read``, ``fibrelmp.translate_job``, ``fibrelmp.run`` and ``fibrelmp.convert``
(see docs/python.md; ``fibrelmp.translate`` is the translators' subpackage).  They raise ``fibrelmp.InputError`` (bad input, ``path:line: message``) or
``fibrelmp.RunError`` (LAMMPS or the machine failed) and never exit the interpreter; a run
restores the signal handlers it installed for checkpoints when it returns.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

from fibrelmp.errors import InputError

Say = Callable[[str], None]
Warn = Callable[[list[tuple[str, str]]], None]


def _quiet(_: object) -> None:
    pass


def read(path: str | Path):
    """The neutral model of any supported input: a ``Model`` (FibreNet), a ``GranularModel``
    (MUSEN scene, DEMDF) or, for a cmusen job script, its checked ``ScriptPlan``."""
    from fibrelmp.registry import detect

    kind = detect(path).name
    if kind == "fibrenet":
        from fibrelmp.api import read_input

        return read_input(path)
    if kind == "musen-script":
        from fibrelmp.granular_api import plan_musen_script

        return plan_musen_script(path)
    from fibrelmp.granular_api import read_granular

    return read_granular(path, kind)[0]


def translate_job(path: str | Path, folder: str | Path, warn: Warn | None = None) -> Path:
    """Write ``folder/in.lammps`` and its data file for the input at ``path`` (a cmusen
    script: its first simulation); returns the script's path (replay: ``lmp -in in.lammps``).
    ``warn`` receives the input's warnings, then those the translation found."""
    return write_job(path, folder, warn).script


def write_job(path: str | Path, folder: str | Path, warn: Warn | None = None):
    """``translate_job``, returning the job (``.script``, ``.data``)."""
    from fibrelmp.registry import detect

    kind = detect(path).name
    if kind == "fibrenet":
        from fibrelmp.api import read_input, translate as write

        model = read_input(path)
    else:
        from fibrelmp.granular_api import model_for_check
        from fibrelmp.translate.granular_job import write_granular_job as write

        model = model_for_check(path, kind)
    said = len(model.warnings)
    if warn is not None:
        warn(model.warnings)
    job = write(model, folder)
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

    def frames(self, simulation: int = -1) -> Iterator:
        """The saved frames of one simulation (default: the last), one at a time, as
        ``fibrelmp.post.lammps_dump.reader.Frame`` (``.step``, ``.column('x')``, ``.vector('x','y','z')``)."""
        from fibrelmp.post.lammps_dump.reader import iter_frames

        return iter_frames(self.dumps[simulation])

    def universe(self, simulation: int = -1):
        """The frames as an MDAnalysis ``Universe`` (needs MDAnalysis)."""
        import MDAnalysis

        return MDAnalysis.Universe(str(self.dumps[simulation]), format="LAMMPSDUMP")


def run(path: str | Path, out: str | Path | None = None, *, work: str | Path | None = None,
        force: bool = False, checkpoint_every: int | None = None, resume: bool = False,
        end_time: float | None = None, step: float | None = None, save_step: float | None = None,
        steps: int | None = None, precision: int = 6, progress: bool = False,
        say: Say = _quiet, warn: Warn | None = None) -> RunResult:
    """Run any supported input on LAMMPS and write its results in the input's own format.

    ``out``: the results' folder (FibreNet, DEMDF, cmusen script) or file (MUSEN scene);
    default next to the input.  Existing results are replaced, completely, only with
    ``force``.  ``end_time``/``step``/``save_step`` (MUSEN scene, DEMDF) and ``steps``
    (DEMDF) override the input.  ``say`` receives progress notes, ``warn`` lists of
    ``(kind, text)`` warnings as they are found (they are also in the result)."""
    from fibrelmp.checkpoint import check_every
    from fibrelmp.registry import detect
    from fibrelmp.granular_api import Checkpoints

    path = Path(path)
    kind = detect(path).name
    check_every(checkpoint_every)         # before any folder is made
    result = RunResult()

    def warned(items: list[tuple[str, str]]) -> None:
        result.warnings.extend(items)
        if warn is not None and items:
            warn(list(items))

    if kind == "fibrenet":
        from fibrelmp.api import read_input, run as run_fibrenet

        _no_overrides(path, (end_time, step, save_step, steps), "FibreNet inputs set their own "
                      "steps: --end-time/--step/--save-step/--steps are for MUSEN and DEMDF inputs")
        model = read_input(path)
        warned(model.warnings)
        said = len(model.warnings)
        done = run_fibrenet(model, out=out, work=work, progress=progress,
                            checkpoint_every=checkpoint_every, resume=resume, force=force)
        warned(model.warnings[said:])            # found while running (beads outside the box)
        result.outputs, result.scripts, result.dumps = done.outputs, [done.job.script], [done.job.frames]
        return result
    if resume and not has_checkpoint(path, kind, out, work):
        raise InputError(path, None, "no checkpoint to resume from (run without --resume, or "
                         "give the same --work folder as the interrupted run)")
    checkpoints = Checkpoints(checkpoint_every, resume)
    if kind == "musen-script":
        from fibrelmp.granular_api import run_musen_script

        _no_overrides(path, (end_time, step, save_step, steps), "a cmusen job script sets "
                      "END_TIME, SIMULATION_STEP and SAVING_STEP itself; edit the script instead")
        res = run_musen_script(path, work=work, progress=progress, say=say, warn=warned,
                               checkpoints=checkpoints, out=out, force=force)
    elif kind == "demdf":
        from fibrelmp.granular_api import run_demdf

        res = run_demdf(path, out=out, work=work, progress=progress, time_end=end_time,
                        steps=steps, save_every=save_step, warn=warned, say=say,
                        checkpoints=checkpoints, force=force)
    else:
        from fibrelmp.granular_api import read_granular, run_musen_scene, scene_result_path

        model, overrides = read_granular(path, kind, end_time, step, save_step, steps)
        for text in overrides:
            say(f"override: {text}")
        warned(model.warnings)
        said = len(model.warnings)
        res = run_musen_scene(model, scene_result_path(path, out), work=work, progress=progress, precision=precision,
                              checkpoints=checkpoints, force=force)
        warned(model.warnings[said:])            # found while translating or running
    result.outputs, result.notes = res.outputs, res.notes
    result.scripts = [job.script for job in res.jobs]
    result.dumps = [job.frames for job in res.jobs]
    return result


def _no_overrides(path: Path, values: tuple, message: str) -> None:
    if any(v is not None for v in values):
        raise InputError(path, None, message)


def has_checkpoint(path: Path, kind: str, out: str | Path | None, work: str | Path | None) -> bool:
    """Is there a checkpoint for this granular input's work folder(s)?"""
    if work is not None:
        folders = [Path(work)]
    elif kind in ("musen-script", "demdf"):
        folders = [Path(out or path.resolve().parent) / f"{path.stem}_work"]
    else:
        from fibrelmp.granular_api import scene_result_path

        target = scene_result_path(path, out)
        folders = [target.resolve().parent / f"{target.stem}_work"]
    return any(next(f.rglob("checkpoint.json"), None) is not None for f in folders if f.exists())


def convert(dump: str | Path, to: str, out: str | Path, *, frames: str | None = None,
            types: list[str] | None = None, data: str | Path | None = None,
            local: str | Path | None = None, gravity: tuple[float, float, float] | None = None,
            force: bool = False, topology: str | Path | None = None, say: Say = _quiet) -> list[Path]:
    """Convert a LAMMPS dump (or an MDAnalysis trajectory with ``topology``) into ``to``
    (xyz, res, musen, demdf, mercury, vtk); returns the files written (docs/post.md)."""
    from fibrelmp.post.convert import post_command

    return post_command(Path(dump), to, Path(out), False, frames, types,
                        None if data is None else Path(data), None if local is None else Path(local),
                        gravity, force, None if topology is None else Path(topology), say)


@dataclass
class CheckReport:
    """What ``fibrelmp check`` prints: summary lines and the input's warnings."""
    format: str
    lines: list[str]
    warnings: list[tuple[str, str]]


def check(path: str | Path) -> CheckReport:
    """Parse and validate an input without running LAMMPS.  For line-oriented formats every
    error is collected: several raise ``InputErrors`` (an ``InputError`` listing them)."""
    from .registry import detect

    path = Path(path)
    kind = detect(path).name
    if kind != "fibrenet":
        from .granular_api import model_for_check
        from .granular_check import summary

        model = _read_for_check(lambda: model_for_check(path, kind), kind, path)
        lines = summary(model) + [f"results      {_granular_results(path, kind, model)}"]
        return CheckReport(kind, lines, list(model.warnings))
    from .api import fibrenet_outputs, read_input
    from .sanity import spring_check, units_line

    model = _read_for_check(lambda: read_input(path), kind, path)
    p = model.particles
    lines = [f"input        {model.source}",
             units_line(model),
             f"beads        {p.count}",
             f"springs      {model.bonds.count}",
             f"angles       {model.angles.count}",
             f"types        {', '.join(p.type_names)}",
             "pairs        " + "; ".join(f"{law.kind} {p.type_names[law.type_i]}-{p.type_names[law.type_j]}"
                                         for law in model.pairs),
             f"box          {' x '.join(f'{x:g}' for x in model.box.lengths)} "
             f"({'periodic' if all(model.box.periodic) else 'finite, wall k = %g' % model.box.wall_stiffness})",
             f"time step    {model.dynamics.dt:g}   lambda {model.dynamics.lambda_:g}   damping {model.dynamics.damping:g}"]
    for st in model.plan.stages:
        extra = f" in chunks of {st.chunk}" + (", velocities reset" if st.reset else "") if st.name == "relax" else \
            f", output every {model.plan.output.every}"
        lines.append(f"stage        {st.name}: {st.steps} steps{extra}")
    lines += spring_check(model)
    outputs, folder, prefix = fibrenet_outputs(model)
    lines.append(f"results      {', '.join(str(p) for p in outputs.files)} (or in -o DIR)")
    return CheckReport(kind, lines, list(model.warnings))


def _granular_results(input: Path, kind: str, model) -> str:
    """Where ``run`` would write (without -o), as check reports it."""
    from .granular_api import demdf_outputs, musen_result_path, plan_musen_script, scene_result_path

    if kind == "demdf":
        outputs, folder = demdf_outputs(model)
        return f"{folder / model.passthrough['demdf']['filename']}_<n>.json (or in -o DIR)"
    if kind == "musen-script":
        written = [str(st.written) for st in plan_musen_script(input).steps if st.written is not None]
        return ", ".join(written) or "none (the script exports nothing)"
    return f"{musen_result_path(scene_result_path(input.resolve()))[0]} (or -o FILE)"


def _read_for_check(read, kind: str, input: Path):
    """``read()``; on an input error in a line-oriented format, every error of the file (the
    readers stop at the first: ``collect_errors`` re-reads with failing lines patched out)."""
    from .errors import InputErrors
    from .textio import MAX_ERRORS, collect_errors

    try:
        return read()
    except InputError as first:
        if kind == "demdf":
            raise
        if kind == "fibrenet":
            from .translate.fibrenet.reader import check_patch

            patch = check_patch(input)
        else:
            from .translate.musen.script import check_patch as patch
        errors = collect_errors(read, first, patch)
    if len(errors) == 1:
        raise errors[0]
    files = list(dict.fromkeys(e.path for e in errors))          # in the order they were met
    errors.sort(key=lambda e: (files.index(e.path), e.line or 0))
    raise InputErrors(errors, at_limit=len(errors) >= MAX_ERRORS)


def describe(dump: str | Path, topology: str | Path | None = None, say: Say = print) -> None:
    """``fibrelmp post --info``: frames, atoms, columns and box of a trajectory."""
    from .post.convert import post_command

    post_command(Path(dump), None, None, True, None, None, None, None, None, False,
                 None if topology is None else Path(topology), say)
