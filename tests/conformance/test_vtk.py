"""VTK frames (``.vtp``/``.vtm`` with a ``.pvd`` index): the ``post --to`` target and the
``run --also`` roles."""

from .base import AlsoConformance, TargetConformance


class TestVtkTarget(TargetConformance):
    format = "vtk"


class TestVtkAlso(AlsoConformance):
    format = "vtk"
