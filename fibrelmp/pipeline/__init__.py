"""The run pipeline: it executes the ``RunPlan`` an input's hook builds.

``run``             ``run(plan)``: lock, render, checkpoint, run (serial or overlapped),
                    feed the writers, check the frame schedule, finish the outputs
``run_model``       ``run_fibrenet``, ``run_granular``: a model's plan (FibreNet's,
                    ``translate.fibrenet.plan``; the granular request, ``granular_run``), run
``evaluate``        one LAMMPS force evaluation of a FibreNet model (tests)

The plan types (``RunPlan``, ``RunRequest``, ``RunOptions``, ``feed``) live in the core
module ``fibrelmp.runplan``; the input hooks and their plans live in each format's home
(``translate/<format>/``), which never imports the pipeline.  ``python_api`` and the CLI use
the pipeline through the registry's INPUT hooks.
"""

from fibrelmp.runplan import (Action, Outcome, Rendered, RunOptions, RunPlan,
                              RunRequest)
from fibrelmp.pipeline.run import run

__all__ = ["Action", "Outcome", "Rendered", "RunOptions", "RunPlan", "RunRequest", "run"]
