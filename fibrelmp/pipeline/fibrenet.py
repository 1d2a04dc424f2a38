"""``run_fibrenet``: run a FibreNet model in one call (tests, benchmarks).  The plan is
FibreNet's own (``translate.fibrenet.plan``); the pipeline executes it."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.pipeline.run import run
from fibrelmp.runplan import RunOptions
from fibrelmp.translate.fibrenet.plan import fibrenet_plan

if TYPE_CHECKING:
    from fibrelmp.model import Model
    from fibrelmp.translate.lammps_job import Job


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
