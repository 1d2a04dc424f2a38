"""The one run pipeline: every input (FibreNet, MUSEN scene, cmusen script, DEMDF) runs here.

``run(plan)`` locks the plan's outputs, then for each simulation: renders the job to disk on
rank 0 (the LAMMPS script first: ``lmp -in in.lammps`` replays it), prepares checkpoints (or
resumes), runs LAMMPS serially or with the frame conversion overlapped on a second core,
feeds every saved frame to the result writers (closed on success, aborted on any failure)
and checks the frame schedule (a missing or extra frame is a RunError, never a silently
wrong result).  Finally it removes earlier results this run did not write again.

MPI: LAMMPS runs on every rank; files, frames and writers are rank 0's.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from fibrelmp.errors import InputError, RunError
from fibrelmp.checkpoint import has_checkpoint
from fibrelmp.lammps_flow import is_stop_print
from fibrelmp.runplan import (Action, Consumer, Outcome, Rendered, RunOptions, RunPlan,
                              RunRequest)

Warn = Callable[[list[tuple[str, str]]], None]
_EXTRA = object()            # the token of a frame beyond the schedule


def run(plan: RunPlan, warn: Warn | None = None) -> Outcome:
    """Run every step of ``plan``; ``warn`` receives the warnings each simulation adds to
    its model while it is translated and run."""
    from fibrelmp.outputs import finish, locked
    from fibrelmp.runner import mpi_rank_size
    from fibrelmp.sanity import (check_steps, needs_job, rank_check, run_budget,
                                 long_run_check, time_step_check)

    rank, size = mpi_rank_size()
    options = plan.options
    if options.resume and not has_checkpoint(plan.outputs.work):
        from fibrelmp.checkpoint import NO_CHECKPOINT

        raise InputError(plan.outputs.source, None, NO_CHECKPOINT)
    # runs that cannot finish (steps LAMMPS cannot count, output beyond the free disk space,
    # years of CPU) are refused before anything is written: each job rendered in memory
    jobs = []
    for step in plan.steps:
        if isinstance(step, RunRequest):
            check_steps(step.model, plan.outputs.source, options.allow_huge)
            if not needs_job(step.model, plan.outputs):
                continue
            said = len(step.model.warnings)
            jobs.append((step.model, step.build(Path(step.work).resolve(), False)))
            del step.model.warnings[said:]      # said when the job is rendered for the run
    run_budget(jobs, plan.outputs, size, options.allow_huge, disk=rank == 0)
    outcome = Outcome()
    several = sum(isinstance(step, RunRequest) for step in plan.steps) > 1
    # resuming continues this run's own (locked) work: its partial results are not "earlier" ones
    with locked(plan.outputs, options.force or options.resume, rank):
        try:
            if size > 1:
                from fibrelmp._lammps import mpi_barrier

                mpi_barrier()     # every rank checked the outputs before rank 0 writes any
            for step in plan.steps:
                if isinstance(step, Action):
                    outcome.outputs += step.run(rank == 0)
                    continue
                said = len(step.model.warnings)
                time_step_check(step.model)     # check's warning, said before the run starts
                long_run_check(step.model)      # over a day even at optimistic speeds
                rank_check(step.model, size)    # too many MPI ranks for this system
                if warn is not None and step.model.warnings[said:]:
                    warn(step.model.warnings[said:])
                said = len(step.model.warnings)
                rendered, written, summary = simulate(step, options, rank, size,
                                                      Path(step.work).name if several else "")
                outcome.jobs.append(rendered)
                outcome.outputs += written
                if summary is not None:
                    outcome.summaries.append(summary)
                if warn is not None and step.model.warnings[said:]:
                    warn(step.model.warnings[said:])    # found while translating or running
            if rank == 0:
                finish(plan.outputs, outcome.outputs)
        finally:
            for cleanup in plan.cleanup:
                cleanup()
    return outcome


def simulate(request: RunRequest, options: RunOptions, rank: int = 0, size: int = 1,
             label: str = "") -> tuple[Rendered, list[Path], dict | None]:
    """Render, run and convert one simulation; (the rendered job, the result files, its
    summary: rank 0, also written as ``summary.json`` beside ``log.lammps``).  ``label``
    names the simulation in progress lines."""
    import time

    from fibrelmp._lammps import mpi_barrier, mpi_wait_for_all
    from fibrelmp.checkpoint import STATE
    from fibrelmp.record import SUMMARY_NAME, Recorder, write_summary
    from fibrelmp.runner import run_script

    # every rank renders identically; only rank 0 writes the job files
    rendered = request.build(Path(request.work).resolve(), rank == 0)
    if size > 1:
        mpi_barrier()        # the data file is complete before any rank hashes it
    # a cmusen script resumes the simulation that was interrupted; finished ones run again
    resume = options.resume and (rendered.folder / STATE).exists()
    checkpoints = prepare_checkpoints(rendered.folder, rendered.text, options.checkpoint_every,
                                      resume, [p.name for p in rendered.dumps], rank, rendered.inputs)
    if rank == 0 and not resume:
        for dump in rendered.dumps:
            dump.unlink(missing_ok=True)
    if rank == 0:            # an earlier run's summary must not pass for this run's
        (rendered.folder / SUMMARY_NAME).unlink(missing_ok=True)
    record = (request.recorder or Recorder)(request.model, rendered.job, rendered.text)
    started = time.monotonic()
    if rank != 0:            # the same script text; LAMMPS reads the data file on rank 0 only
        with _hint(request.model):
            run_script(rendered.script, rendered.total_steps, progress=False, text=rendered.text,
                       checkpoints=checkpoints, record=record)
        mpi_wait_for_all()   # asleep while rank 0 converts the frames (with both cores)
        return rendered, [], None
    more = dict(record=record, log_every=options.log_every, label=label)

    source = request.frames(rendered)
    try:
        consume = request.results(rendered)
        schedule = _FrameSteps(rendered.schedule)

        def token(words: list[str]) -> Any:
            if is_stop_print(words):
                schedule.stop()
            return next(schedule, _EXTRA) if source.is_frame(words) else None

        def convert(tokens: Iterator[Any]) -> list[Path]:
            return consume(_scheduled(tokens, source, schedule, rendered))

        if size == 1 and (os.cpu_count() or 1) > 1:
            from fibrelmp.runner import run_overlapped

            # convert each frame on a second core while LAMMPS computes the next ones (the
            # lammps module releases the GIL inside the library)
            with _hint(request.model):
                written = run_overlapped(rendered.script, rendered.total_steps, token, convert,
                                         progress=options.progress, checkpoints=checkpoints,
                                         finished=rendered.finished, **more)
        else:
            with _hint(request.model):
                written = _run_serial(rendered, token, convert, options.progress, checkpoints, more)
    finally:
        source.close()
    tally = getattr(source, "tally", None)
    summary = record.summary(rendered, time.monotonic() - started, request.model.warnings,
                             tally() if tally is not None else None)
    if schedule.stopped or summary.get("frames") is None:   # the frames written (a stop, a
        summary["frames"] = schedule.given                   # variable step): not scheduled
    write_summary(rendered.folder, summary)
    if size > 1:
        mpi_wait_for_all()
    return rendered, list(written), summary


@contextmanager
def _hint(model) -> Iterator[None]:
    """A LAMMPS error that follows from too large a time step gets a hint
    (``sanity.blow_up_hint``)."""
    from fibrelmp.sanity import blow_up_hint

    try:
        yield
    except RunError as exc:
        hint = blow_up_hint(model, str(exc))
        if hint is None:
            raise
        raise RunError(f"{exc}\n{hint}") from None


def _run_serial(rendered: Rendered, token: Callable, convert: Consumer, progress: bool,
                checkpoints, more: dict) -> list[Path]:
    """Run LAMMPS to the end, then convert the frames it saved (MPI, or a single core)."""
    from fibrelmp.runner import RunAborted, run_script

    tokens: list[Any] = []

    def hook(words: list[str]) -> None:
        t = token(words)
        if t is not None:
            tokens.append(t)

    def aborted() -> Iterator[Any]:
        raise RunAborted()
        yield

    try:
        run_script(rendered.script, rendered.total_steps, progress=progress, on_command=hook,
                   text=rendered.text, checkpoints=checkpoints, finished=rendered.finished, **more)
    except BaseException:
        try:
            convert(aborted())      # the writers discard what they staged
        except BaseException:       # never hide the run's own error (or the stop signal)
            pass
        raise
    return convert(iter(tokens))


def _scheduled(tokens: Iterator[Any], source, schedule: Iterator[int], rendered: Rendered) -> Iterator[Any]:
    """The frames of ``tokens``, checked against the job's schedule: a frame the schedule
    does not have, or one it has but the run did not write, is a RunError (raised inside the
    writers' loop, so they discard their partial results)."""
    from fibrelmp.numtext.fast import cores_taken

    try:
        total = len(rendered.schedule)
    except TypeError:
        total = -1
    for k, step in enumerate(tokens, 1):
        if step is _EXTRA:
            raise RunError(f"{rendered.script}: the run wrote more frames than the "
                           f"{_count(rendered.schedule)} scheduled")
        if k == total:
            # the last frame ends the script: LAMMPS's core is free again for the reading
            with cores_taken(-1):
                frame = source.read(step)
            yield frame
        else:
            yield source.read(step)
    # (a _FrameSteps knows a variable step's open schedule, whose frames are never missing)
    missing = schedule.missing() if isinstance(schedule, _FrameSteps) else next(schedule, None)
    if missing is not None:
        raise RunError(f"{rendered.script}: the run ended without the frame of step {missing} "
                       f"({_count(rendered.schedule)} were scheduled)")


class _FrameSteps:
    """The steps of the frames: the schedule's, until the script stops early (its
    ``lammps_flow.STOP_PRINT``); then one frame, one step after the last, and no more."""

    def __init__(self, steps: Iterable[int]):
        self._steps, self._last = iter(steps), 0
        self.given, self.stopped = 0, False

    def __iter__(self) -> "_FrameSteps":
        return self

    def __next__(self) -> int:
        self._last = next(self._steps)
        self.given += 1
        return self._last

    def stop(self) -> None:
        # (a variable step's frames have no step known in advance: the last one's neither)
        self._steps, self.stopped = iter([self._last + 1 if self._last >= 0 else self._last]), True

    def missing(self) -> int | None:
        """The step of a scheduled frame the run did not write, else None (a variable time
        step's open schedule, whose steps are negative, misses none)."""
        step = next(self._steps, None)
        return step if step is not None and step >= 0 else None


def _count(schedule) -> str:
    try:
        return str(len(schedule))
    except TypeError:
        return "frames"


def prepare_checkpoints(folder: Path, text: str, every: int | None, resume: bool,
                        appended: list[str], rank: int, inputs: list[Path] = ()):
    """Checkpointing for a job (always on: a SIGTERM/Ctrl-C leaves a checkpoint behind);
    when resuming, load the state (refused when the script or any of ``inputs``, the files
    the job reads, changed) and cut the dumps back to the checkpoint."""
    from fibrelmp.checkpoint import Checkpointing, check_every, load, truncate_outputs

    check_every(every)
    state = load(folder, text, inputs) if resume else None
    if state is not None and rank == 0:
        truncate_outputs(folder, state)
    return Checkpointing(Path(folder), every, state, list(appended), list(inputs))
