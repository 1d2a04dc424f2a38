"""fibrelmp: run FibreNet, MUSEN and DEMDF inputs on LAMMPS."""

__version__ = "0.1.0"
