"""FibreNet inputs: the conformance checks of the ``input`` role on the fibre-network example."""

from .base import InputConformance


class TestFibrenetInput(InputConformance):
    format = "fibrenet"
    sample = "examples/fibre_network/input.txt"
