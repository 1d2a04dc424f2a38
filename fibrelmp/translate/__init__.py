"""Translators: the simulation formats' homes (``fibrenet``, ``musen`` with ``musen/mdem``,
``demdf``, ``cardioproof``: readers, native writers, input hooks, run plans, post targets,
picture sources) and the LAMMPS job renderers that turn their neutral models into scripts.

``fibrelmp.translate`` is also the Python API's ``translate(path, folder)`` (docs/python.md):
a package cannot be a function, so the module itself is made callable (the one supported way:
its class is a ``ModuleType`` subclass with ``__call__``).
"""

import sys
import types


class _CallableModule(types.ModuleType):
    def __call__(self, path, folder, warn=None):
        """``fibrelmp.translate(path, folder)``: write ``folder/in.lammps`` and its data file
        for the input at ``path``; returns the script's path (``fibrelmp.translate_job``)."""
        from fibrelmp.python_api import translate_job

        return translate_job(path, folder, warn)


sys.modules[__name__].__class__ = _CallableModule
