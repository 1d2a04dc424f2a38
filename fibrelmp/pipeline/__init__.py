"""The run pipeline: how every input runs on LAMMPS and becomes results in its own format.

``inputs``          the ``InputFormat`` hooks (``fibrelmp.inputformat``; the registry's INPUT
                    role) of the formats not yet in their homes (MUSEN, .mdem, cmusen
                    scripts, CardioProof); FibreNet's and DEMDF's live in translate/<format>/
``request``         ``RunRequest`` (one simulation), ``RunPlan`` (an input's simulations and
                    script steps, with the outputs they lock), ``RunOptions``
``run``             ``run(plan)``: lock, render, checkpoint, run (serial or overlapped),
                    feed the writers, check the frame schedule, finish the outputs
``fibrenet``        FibreNet's run plan: its job, dump frames, native files moved into place
``granular``        granular jobs (MUSEN, DEMDF); ``granular_frames`` builds their frames
``spool``           on-disk frames of a cmusen simulation that a later job exports
``evaluate``        one LAMMPS force evaluation of a FibreNet model (tests)

Layers: ``translate`` (readers, job renderers, native writers), ``post`` (dump readers,
converters) and the format homes never import the pipeline (a home names the pipeline parts
its run plan needs, ``inputformat.pipeline_part``); the pipeline uses them; ``python_api``
and the CLI use the pipeline through the registry's INPUT hooks.
"""

from fibrelmp.pipeline.request import (Action, Outcome, Rendered, RunOptions, RunPlan,
                                       RunRequest)
from fibrelmp.pipeline.run import run

__all__ = ["Action", "Outcome", "Rendered", "RunOptions", "RunPlan", "RunRequest", "run"]
