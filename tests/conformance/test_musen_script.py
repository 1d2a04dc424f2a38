"""cmusen job scripts: the conformance checks of the ``input`` role."""

from .base import InputConformance


class TestMusenScriptInput(InputConformance):
    format = "musen-script"
    sample = "examples/musen/single_particle_job.txt"
