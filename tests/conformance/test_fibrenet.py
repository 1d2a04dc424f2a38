"""FibreNet inputs: the conformance checks of the ``input`` role on the fibre-network example
(``fibrelmp.translate.fibrenet.samples``)."""

from fibrelmp.translate.fibrenet import samples

from .base import InputConformance


class TestFibrenetInput(InputConformance):
    format = "fibrenet"
    sample = samples.INPUT
