"""MercuryDPM files: the conformance checks of the ``post --to`` target role."""

from .base import TargetConformance


class TestMercuryTarget(TargetConformance):
    format = "mercury"
