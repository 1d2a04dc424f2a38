"""VTK frames (``.vtp``/``.vtm`` with a ``.pvd`` index): the ``post --to`` target role."""

from .base import TargetConformance


class TestVtkTarget(TargetConformance):
    format = "vtk"
