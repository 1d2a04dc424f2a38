"""``run_granular``: run a ``GranularModel`` in one call and see every frame (tests).  The
request is the shared granular one (``granular_run.request``); the pipeline executes it."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Callable

from fibrelmp.granular_run.request import granular_request
from fibrelmp.pipeline.run import run
from fibrelmp.runplan import RunOptions, RunPlan

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularFrame, GranularModel
    from fibrelmp.translate.granular_job import GranularJob


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
