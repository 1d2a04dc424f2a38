"""FibreNet's run plan: the bead-spring job, its dump frames and FibreNet's own result files
(``_coord/_vel/_force.xyz``, ``_restart.res``): written by LAMMPS itself with fibrelmp's
plugin (``fix fibrenet/output``; moved into place after the run), else converted from the
dump frames by ``translate.fibrenet.target``.  The plan is built of the core's plan types
(``fibrelmp.runplan``) and ``run --also`` writers (``fibrelmp.also``); the pipeline only
executes it (``pipeline.run``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator

from fibrelmp.errors import RunError
from fibrelmp.runplan import Consumer, Rendered, RunOptions, RunPlan, RunRequest
from fibrelmp.translate.fibrenet.frames import DumpFrames, WrittenFrames, move_file
from fibrelmp.translate.fibrenet.input import fibrenet_outputs
from fibrelmp.translate.fibrenet.target import convert_frames, report_outside

if TYPE_CHECKING:
    from fibrelmp.model import Model
    from fibrelmp.post.lammps_dump.reader import Frame


def render(model: "Model"):
    """The job builder: ``in.lammps`` + data file (``translate.lammps_job``).  With fibrelmp's
    plugin the job writes FibreNet's files itself (``job.native``): its xyz files are
    appended like the dump (cut back to a checkpoint when resuming)."""
    def build(folder: Path, write_files: bool) -> Rendered:
        from fibrelmp.translate import lammps_job

        job = lammps_job.write_job(model, folder, write_files=write_files)
        if job.native is None:
            return Rendered(job, job.text, job.output_steps, [job.frames])
        return Rendered(job, job.text, job.output_steps, [job.frames, *job.native.xyz],
                        finished=report_outside(model, job.native))
    return build


def results(model: "Model", folder: Path, prefix: str,
            also: Callable[[], list] = lambda: []):
    """The FibreNet writers of a rendered job: a consumer of its frames (and, with ``also``'s
    writers, of the dump frames their files are made of: ``fibrelmp.also``)."""
    spec = model.plan.output

    def make(rendered: Rendered) -> Consumer:
        job = rendered.job
        if job.native is not None:
            consume = _move_native(job.native, folder, prefix, spec.fields)
        else:
            def consume(frames: Iterator["Frame"]) -> list[Path]:
                from fibrelmp.finite import guarded

                return convert_frames(model, job, guarded(frames), folder, prefix)
        from fibrelmp.also import also_to

        return also_to(consume, also())
    return make


def _move_native(native, folder: Path, prefix: str, fields) -> Consumer:
    """A consumer for a job that wrote FibreNet's files itself: when every scheduled frame
    was written, the files move from the job folder into place (nothing moves after a
    failure: the job folder keeps them, like its dump)."""
    from fibrelmp.translate.lammps_job import RESTART_SUFFIX, XYZ_SUFFIX

    def consume(frames: Iterator[int]) -> list[Path]:
        for _ in frames:            # the steps, checked against the schedule
            pass
        moves = [(src, folder / f"{prefix}{XYZ_SUFFIX[f]}") for src, f in zip(native.xyz, fields)]
        moves.append((native.restart, folder / f"{prefix}{RESTART_SUFFIX}"))
        for src, dst in moves:
            if not src.is_file():
                raise RunError(f"{src}: the job did not write this FibreNet file (fix fibrenet/output)")
        from fibrelmp.finite import scan_text_files

        # nan/inf: nothing moves into place (the fix counted them as it wrote; the files are
        # searched for the line to name only then, or when the count is unknown)
        if native.nonfinite != 0:
            scan_text_files(src for src, _ in moves)
            if native.nonfinite:        # counted, yet the search named no line: still refused
                raise RunError(f"{native.restart.parent}: the simulation produced {native.nonfinite} "
                               "nan/inf values in FibreNet's files: no results written")
        for src, dst in moves:
            move_file(src, dst)
        return [dst for _, dst in moves]
    return consume


def fibrenet_plan(model: "Model", out: str | Path | None = None, work: str | Path | None = None,
                  options: RunOptions = RunOptions(), also: tuple[str, ...] = ()) -> RunPlan:
    """The run of a FibreNet model: one simulation, its results next to the input (or in
    ``out``), its job in ``work`` (default ``<prefix>_work`` beside the results);
    ``also``: the formats also written from the frames, named ``<prefix>`` (``fibrelmp.also``)."""
    from fibrelmp.also import fibrenet_writers

    outputs, folder, prefix = fibrenet_outputs(model, out, work)
    extra = fibrenet_writers(also, model, outputs, folder / prefix)

    def frames(rendered: Rendered):
        if rendered.job.native is not None and not also:
            return WrittenFrames()
        return DumpFrames(rendered.job.frames)

    request = RunRequest(model, render(model), frames, results(model, folder, prefix, extra),
                         outputs.work)
    return RunPlan(outputs, [request], options)
