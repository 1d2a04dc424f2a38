"""CardioProof cases: the conformance checks of the ``input`` role."""

from .base import InputConformance


class TestCardioproofInput(InputConformance):
    format = "cardioproof"
    sample = "examples/cardioproof/piston_tube.json"
