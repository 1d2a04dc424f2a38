"""The run pipeline: how every input runs on LAMMPS and becomes results in its own format.

``inputs``          one ``InputFormat`` hook per input format (the registry's INPUT role):
                    read, check, translate, and the ``RunPlan`` of a run
``request``         ``RunRequest`` (one simulation), ``RunPlan`` (an input's simulations and
                    script steps, with the outputs they lock), ``RunOptions``
``run``             ``run(plan)``: lock, render, checkpoint, run (serial or overlapped),
                    feed the writers, check the frame schedule, finish the outputs
``fibrenet``        FibreNet jobs, their dump frames and result files
``granular``        granular jobs (MUSEN, DEMDF); ``granular_frames`` builds their frames
``spool``           on-disk frames of a cmusen simulation that a later job exports
``evaluate``        one LAMMPS force evaluation of a FibreNet model (tests)

Layers: ``translate`` (readers, job renderers, native writers) and ``post`` (dump readers,
converters) never import the pipeline; the pipeline uses both; ``python_api`` and the CLI
use the pipeline through the registry's INPUT hooks.
"""

from fibrelmp.pipeline.request import (Action, Outcome, Rendered, RunOptions, RunPlan,
                                       RunRequest)
from fibrelmp.pipeline.run import run

__all__ = ["Action", "Outcome", "Rendered", "RunOptions", "RunPlan", "RunRequest", "run"]
