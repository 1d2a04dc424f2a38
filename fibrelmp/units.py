"""Unit systems: which one each input format is written in, which LAMMPS ``units`` style runs
it, and conversions between LAMMPS unit styles.

fibrelmp never converts an input: every format is run in the unit system its numbers are
written in, so the translation only has to be self-consistent.

* FibreNet: no units at all; its numbers are taken as LAMMPS ``lj`` reduced units (mass,
  length and energy scales 1, no Boltzmann constant in any force law fibrelmp uses).
* MUSEN: SI (m, kg, s), run as LAMMPS ``units si``.
* DEMDF: dimensionless (BOS's radius 0.5, mass 1); run as ``units si`` because the granular
  pair styles involve no physical constant, so any consistent set of numbers works there.

Model objects carry ``units`` (the ``name`` below); ``system(model.units)`` gives the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AVOGADRO = 6.02214076e23          # 1/mol (exact, SI 2019)
ELECTRONVOLT = 1.602176634e-19    # J (exact)
KCAL = 4184.0                     # J (thermochemical calorie)


@dataclass(frozen=True)
class UnitSystem:
    name: str            # what ``fibrelmp check`` prints and models store in ``units``
    lammps: str          # the LAMMPS ``units`` style the translation runs in
    length: str
    mass: str
    time: str
    force: str
    note: str            # one line for ``fibrelmp check``

    def describe(self) -> str:
        return (f"{self.name} (length {self.length}, mass {self.mass}, time {self.time}, force "
                f"{self.force}; LAMMPS 'units {self.lammps}'): {self.note}")


LJ = UnitSystem("lj", "lj", "sigma", "m (reduced)", "tau", "epsilon/sigma",
                "FibreNet numbers are used as reduced units, unconverted")
SI = UnitSystem("si", "si", "m", "kg", "s", "N", "MUSEN files are SI")
DIMENSIONLESS = UnitSystem("dimensionless", "si", "1", "1", "1", "1",
                           "DEMDF numbers have no units; run unconverted")

_SYSTEMS = {s.name: s for s in (LJ, SI, DIMENSIONLESS)}


def for_format(name: str) -> UnitSystem:
    """The unit system a format's numbers are in (its registry record's ``units``)."""
    from fibrelmp.registry import get

    return _SYSTEMS[get(name).units]


def system(name: str) -> UnitSystem:
    """A model's ``units`` value as a UnitSystem."""
    try:
        return _SYSTEMS[name]
    except KeyError:
        raise ValueError(f"unknown unit system {name!r} (known: {', '.join(_SYSTEMS)})") from None


# SI value of one unit of each quantity in the LAMMPS unit styles that have physical
# dimensions (LAMMPS manual, ``units`` command).  ``lj`` is reduced: it has no SI scale.
LAMMPS_TO_SI: dict[str, dict[str, float]] = {
    "si": {"length": 1.0, "mass": 1.0, "time": 1.0, "velocity": 1.0, "force": 1.0,
           "energy": 1.0},
    "cgs": {"length": 1e-2, "mass": 1e-3, "time": 1.0, "velocity": 1e-2, "force": 1e-5,
            "energy": 1e-7},
    "metal": {"length": 1e-10, "mass": 1e-3 / AVOGADRO, "time": 1e-12, "velocity": 1e2,
              "force": ELECTRONVOLT / 1e-10, "energy": ELECTRONVOLT},
    "real": {"length": 1e-10, "mass": 1e-3 / AVOGADRO, "time": 1e-15, "velocity": 1e5,
             "force": KCAL / AVOGADRO / 1e-10, "energy": KCAL / AVOGADRO},
    "micro": {"length": 1e-6, "mass": 1e-15, "time": 1e-6, "velocity": 1.0, "force": 1e-9,
              "energy": 1e-15},
    "nano": {"length": 1e-9, "mass": 1e-21, "time": 1e-9, "velocity": 1.0, "force": 1e-9,
             "energy": 1e-18},
}


def convert(value: float | np.ndarray, quantity: str, from_style: str,
            to_style: str) -> float | np.ndarray:
    """``value`` of ``quantity`` (length, mass, time, velocity, force, energy) from one LAMMPS
    unit style to another.  Reduced ``lj`` values convert only to ``lj``."""
    if from_style == to_style:
        return value
    for style in (from_style, to_style):
        if style not in LAMMPS_TO_SI:
            raise ValueError(f"LAMMPS units {style!r} have no SI scale (known: "
                             f"{', '.join(LAMMPS_TO_SI)})")
    scale = LAMMPS_TO_SI[from_style][quantity] / LAMMPS_TO_SI[to_style][quantity]
    return value * scale


def mismatch_note(dump_units: str | None, target: UnitSystem, fmt: str) -> str | None:
    """A warning when a dump written in one LAMMPS unit style is converted into a format whose
    files are in another (``fibrelmp post`` writes values as dumped, unconverted)."""
    if dump_units is None or dump_units == target.lammps:
        return None
    scale = ""
    if dump_units in LAMMPS_TO_SI and target.lammps in LAMMPS_TO_SI:
        factor = convert(1.0, "length", dump_units, target.lammps)
        scale = f" (1 length unit of the dump = {factor:g} {target.length})"
    return (f"the dump is in LAMMPS 'units {dump_units}' but {fmt} files are in "
            f"'units {target.lammps}': values are written as dumped, unconverted{scale}")
