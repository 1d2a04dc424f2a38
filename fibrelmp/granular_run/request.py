"""Granular runs (MUSEN scenes and cmusen scripts, DEMDF): a ``GranularModel`` rendered by
``translate.granular_job``, its frames built by ``FrameBuilder``, fed to the format's writers."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Callable

from fibrelmp.pipeline.request import Rendered, RunOptions, RunPlan, RunRequest
from fibrelmp.pipeline.run import feed, run

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularFrame, GranularModel
    from fibrelmp.translate.granular_job import GranularJob


def render(model: "GranularModel"):
    """The job builder: ``in.lammps`` + ``data.lammps`` (rank 0), the script text (all ranks)."""
    def build(folder: Path, write_files: bool) -> Rendered:
        from fibrelmp.translate.granular_job import build_granular_job, write_granular_job

        if write_files:
            job = write_granular_job(model, folder)
            text = job.script.read_text()
        else:
            job, text, _ = build_granular_job(model, folder)
        dumps = [p for p in (job.frames, job.bond_dump, job.tile_dump, job.breaks, job.wall_forces,
                             job.contacts) if p is not None]
        return Rendered(job, text, job.save_steps, dumps)
    return build


def granular_request(model: "GranularModel", work: str | Path,
                     writers: Callable[[], list]) -> RunRequest:
    """One simulation of ``model`` in ``work``, its frames added to ``writers()`` (made on
    rank 0 once the outputs are locked; closed on success, aborted on failure)."""
    from fibrelmp.pipeline.granular_frames import FrameBuilder

    return RunRequest(model, render(model), lambda rendered: FrameBuilder(model, rendered.job),
                      lambda rendered: feed(writers(), model), Path(work))


class _Calls:
    """A writer that hands every frame to a function."""

    def __init__(self, on_frame: Callable[["GranularFrame"], None]):
        self.add = on_frame

    def close(self) -> None:
        pass

    def abort(self) -> None:
        pass


def run_granular(model: "GranularModel", work: str | Path,
                 on_frame: Callable[["GranularFrame"], None], progress: bool = True,
                 checkpoint_every: int | None = None, resume: bool = False) -> "GranularJob":
    """Translate ``model`` into ``work``, run it and call ``on_frame`` for every saved frame
    (rank 0 only), in time order.  ``checkpoint_every``/``resume``: see fibrelmp.checkpoint
    (a resumed run feeds the frames saved before the checkpoint again, from the dumps)."""
    from fibrelmp.outputs import Outputs

    work = Path(work).resolve()
    plan = RunPlan(Outputs(model.source, work), [granular_request(model, work, lambda: [_Calls(on_frame)])],
                   RunOptions(progress, False, checkpoint_every, resume))
    return run(plan).jobs[0].job
