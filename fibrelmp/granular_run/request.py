"""Granular runs (MUSEN scenes and cmusen scripts, DEMDF): a ``GranularModel`` rendered by
``translate.granular_job``, its frames built by ``FrameBuilder``, fed to the format's writers.
The format homes build their plans with ``granular_request``; the pipeline executes them."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Callable

from fibrelmp.runplan import Rendered, RunRequest, feed

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel


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
                             job.contacts, job.variable_clock, job.stress_contacts, job.stress_walls)
                 if p is not None]
        return Rendered(job, text, job.save_steps, dumps)
    return build


def granular_request(model: "GranularModel", work: str | Path,
                     writers: Callable[[], list]) -> RunRequest:
    """One simulation of ``model`` in ``work``, its frames added to ``writers()`` (made on
    rank 0 once the outputs are locked; closed on success, aborted on failure)."""
    from fibrelmp.granular_run.frames import FrameBuilder

    return RunRequest(model, render(model), lambda rendered: FrameBuilder(model, rendered.job),
                      lambda rendered: feed(writers(), model), Path(work))
