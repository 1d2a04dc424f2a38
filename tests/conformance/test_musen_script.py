"""cmusen job scripts: the conformance checks of the ``input`` role; the sample comes from
the MUSEN home (``fibrelmp.translate.musen.samples``)."""

from fibrelmp.translate.musen import samples

from .base import InputConformance


class TestMusenScriptInput(InputConformance):
    format = "musen-script"
    sample = samples.SCRIPT
