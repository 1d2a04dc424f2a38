"""FibreNet runs: the bead-spring job, its dump frames and FibreNet's own result files
(``_coord/_vel/_force.xyz``, ``_restart.res``, written by ``post.to_fibrenet``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

from fibrelmp.errors import InputError
from fibrelmp.pipeline.request import Consumer, Rendered, RunOptions, RunPlan, RunRequest
from fibrelmp.pipeline.run import run, wrong_frame

if TYPE_CHECKING:
    from fibrelmp.model import Model
    from fibrelmp.outputs import Outputs
    from fibrelmp.post.lammps_dump.reader import Frame
    from fibrelmp.translate.lammps_job import Job


def fibrenet_outputs(model: "Model", out: str | Path | None = None,
                     work: str | Path | None = None) -> tuple["Outputs", Path, str]:
    """Where a FibreNet run writes: (outputs, output folder, file name prefix).

    ``output_file`` is a name inside the output folder (``-o``, default the input's folder);
    one that leaves it (``..``) is refused, and an absolute one is honoured only without
    ``-o`` (as FibreNet would write it)."""
    from fibrelmp.outputs import Outputs
    from fibrelmp.translate.fibrenet.writer import RESTART_SUFFIX, XYZ_SUFFIX

    spec = model.plan.output
    name = Path(spec.basename)
    if name.is_absolute():
        if out is not None:
            raise InputError(model.source, spec.line, f"output_file {spec.basename} is an absolute "
                             "path, which -o cannot place: give a plain name, or leave out -o")
        target = name
    else:
        folder = (Path(out) if out is not None else spec.folder).resolve()
        if ".." in name.parts:
            raise InputError(model.source, spec.line, f"output_file {spec.basename} leaves the "
                             f"output folder {folder}: give a name inside it")
        target = folder / name
    if not target.name or target.name in (".", ".."):
        raise InputError(model.source, spec.line, f"output_file {spec.basename!r} names no file")
    folder, prefix = target.parent, target.name
    from fibrelmp.outputs import work_folder as job_folder

    work_folder = job_folder(folder, prefix, work)
    files = [folder / f"{prefix}{XYZ_SUFFIX[f]}" for f in spec.fields] + [folder / f"{prefix}{RESTART_SUFFIX}"]
    family = [folder / f"{prefix}{suffix}" for suffix in (*XYZ_SUFFIX.values(), RESTART_SUFFIX)]
    return Outputs(model.source, work_folder, files, family, inputs=list(model.inputs)), folder, prefix


def render(model: "Model"):
    """The job builder: ``in.lammps`` + data file (``translate.lammps_job``)."""
    def build(folder: Path, write_files: bool) -> Rendered:
        from fibrelmp.translate import lammps_job

        job = lammps_job.write_job(model, folder, write_files=write_files)
        return Rendered(job, job.text, job.output_steps, [job.frames])
    return build


class DumpFrames:
    """The frames of the job's dump (``write_dump`` commands), read as LAMMPS writes them."""

    def __init__(self, path: Path):
        self.path = path
        self.frames: Iterator["Frame"] | None = None

    def is_frame(self, words: list[str]) -> bool:
        return words[0] == "write_dump"

    def read(self, step: int) -> "Frame":
        from fibrelmp.post.lammps_dump.reader import iter_frames

        if self.frames is None:
            self.frames = iter_frames(self.path)
        frame = next(self.frames, None)
        if frame is None or frame.step != step:
            raise wrong_frame(self.path, step, None if frame is None else frame.step)
        return frame

    def close(self) -> None:
        if self.frames is not None:
            self.frames.close()


def results(model: "Model", folder: Path, prefix: str):
    """The FibreNet writers of a rendered job: a consumer of its dump frames."""
    spec = model.plan.output

    def make(rendered: Rendered) -> Consumer:
        from fibrelmp.post import to_fibrenet

        job = rendered.job
        names = {lt: model.particles.type_names[t] for lt, t in enumerate(job.type_of_ltype) if lt > 0}
        types = None if spec.types is None else {model.particles.type_names[t] for t in spec.types}

        def consume(frames: Iterator["Frame"]) -> list[Path]:
            return to_fibrenet.write_fibrenet(frames, prefix, folder, spec.fields, names,
                                              model.dynamics.dt, model.box.lengths, types,
                                              warn=model.warn)
        return consume
    return make


def fibrenet_plan(model: "Model", out: str | Path | None = None, work: str | Path | None = None,
                  options: RunOptions = RunOptions()) -> RunPlan:
    """The run of a FibreNet model: one simulation, its results next to the input (or in
    ``out``), its job in ``work`` (default ``<prefix>_work`` beside the results)."""
    outputs, folder, prefix = fibrenet_outputs(model, out, work)
    request = RunRequest(model, render(model), lambda rendered: DumpFrames(rendered.job.frames),
                         results(model, folder, prefix), outputs.work)
    return RunPlan(outputs, [request], options)


@dataclass
class FibreNetRun:
    job: "Job"                                         # the rendered job (script, dump)
    outputs: list[Path] = field(default_factory=list)  # the FibreNet files written


def run_fibrenet(model: "Model", out: str | Path | None = None, work: str | Path | None = None,
                 progress: bool = True, checkpoint_every: int | None = None,
                 resume: bool = False, force: bool = False) -> FibreNetRun:
    """Translate, run in-process and write FibreNet's result files for ``model``.

    ``checkpoint_every`` writes a checkpoint every that many steps (and one on SIGTERM or
    Ctrl-C in any case); ``resume`` continues from the checkpoint in the work folder.
    Existing results are replaced (completely) only with ``force``; the output and work
    folders are locked for the run."""
    plan = fibrenet_plan(model, out, work, RunOptions(progress, force, checkpoint_every, resume))
    outcome = run(plan)
    return FibreNetRun(outcome.jobs[0].job, outcome.outputs)
