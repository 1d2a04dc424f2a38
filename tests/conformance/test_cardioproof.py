"""CardioProof cases: the conformance checks of the ``input`` role; the sample comes from the
home (``fibrelmp.translate.cardioproof.samples``)."""

from fibrelmp.translate.cardioproof import samples

from .base import InputConformance


class TestCardioproofInput(InputConformance):
    format = "cardioproof"
    sample = samples.CASE
