"""Run a neutral model in one call (tests, benchmarks): ``run_fibrenet`` (FibreNet's plan,
``translate.fibrenet.plan``) and ``run_granular`` (the shared granular request,
``granular_run.request``, every frame handed to a function).  The plans are the homes'; the
pipeline executes them."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from fibrelmp.granular_run.request import granular_request
from fibrelmp.pipeline.run import run
from fibrelmp.runplan import RunOptions, RunPlan
from fibrelmp.translate.fibrenet.plan import fibrenet_plan

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularFrame, GranularModel
    from fibrelmp.model import Model
    from fibrelmp.translate.granular_job import GranularJob
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
