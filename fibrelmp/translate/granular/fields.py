"""MUSEN's external-force (EF) models as LAMMPS commands: one ``fix musen/field`` per active
model (``plan.external_fields``, in MUSEN's order), and for a heat model the spheres'
temperature as the per-atom property ``d_musen_temperature`` set from the scene (docs/granular.md,
"External-force models")."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.translate.lammps_format import float_text

TEMPERATURE = "d_musen_temperature"      # the frames' column of MUSEN's particle temperature
HEAT_CAPACITY = 1                        # MUSEN's material property id
THERMAL_CONDUCTIVITY = 3                 # MUSEN's material property id


def contact_heat_models(model: GranularModel) -> list[str]:
    """The contact and bond models (PP, PW, SB) that carry heat to the spheres (fix musen/heat)."""
    from fibrelmp.translate.granular import models as physics
    names = [m.name for kind in ("PP", "PW") for m, _ in physics.chosen_all(model, kind)
             if m.contact_heat]
    plan = model.plan
    return names + [law.model for law in (plan.bond_law, *plan.then_bond_laws) if law.form == "heat"]


def _pp_reads_temperature(model: GranularModel) -> bool:
    """A PP law that reads the temperatures without carrying heat (its ``reads_temperature``)."""
    from fibrelmp.translate.granular import models as physics
    return any(m.reads_temperature for m, _ in physics.chosen_all(model, "PP"))


def uses_temperature(model: GranularModel) -> bool:
    return (any(f.heat for f in model.plan.external_fields) or bool(contact_heat_models(model))
            or _pp_reads_temperature(model))


@dataclass
class FieldCommands:
    temperature: bool                  # a heat model: fix property/atom d_musen_temperature
    set_lines: list[str]               # the scene's temperatures
    fixes: list[tuple[str, str, str]]  # each EF model's (name, fix style, its arguments)
    heat_args: str = ""                # contact heat models: fix musen/heat's arguments
    # a contact law reads the temperatures of ghost spheres (fix property/atom ... ghost yes)
    ghost_temperature: bool = False


def field_commands(model: GranularModel, rows: np.ndarray, type_of_mat: dict[int, int],
                   ntypes: int) -> FieldCommands:
    """What the job needs for the plan's EF models, for the simulated sphere ``rows`` (LAMMPS
    id = row + 1; sphere material m has type ``type_of_mat[m]``), in MUSEN's order."""
    heat = uses_temperature(model)
    if model.plan.variable_step is not None:
        for fld in model.plan.external_fields:
            if fld.heat or fld.style != "musen/field":
                # MUSEN: the temperature update takes the current step, the diffusion
                # coefficients the first one; these fixes take LAMMPS's fixed dt
                raise InputError(model.source, None, f"{fld.model} with a variable time step is "
                                 "not supported (its temperature or random-force coefficients "
                                 "depend on the step)")
    lines = _set_temperatures(model, rows) if heat else []
    fixes = []
    for fld in model.plan.external_fields:
        if fld.style == "musen/diffusion":
            _check_diffusion(model, rows)
        fixes.append((fld.model, fld.style, fld.fix_args))
    # one owner of the heat flux and the temperature update for every heat model (EF and
    # contact): fix musen/heat, defined before the EF fixes, which add to its flux
    heat_args = ""
    contact = contact_heat_models(model)
    if contact or any(f.heat for f in model.plan.external_fields):
        cp = _heat_capacities(model, type_of_mat, ntypes)
        heat_args = "cp " + " ".join(float_text(c) for c in cp)
        if contact:
            k = _conductivities(model, type_of_mat, ntypes)
            heat_args += " k " + " ".join(float_text(c) for c in k)
    return FieldCommands(heat, lines, fixes, heat_args,
                         ghost_temperature=bool(contact) or _pp_reads_temperature(model))


def _conductivities(model: GranularModel, type_of_mat: dict[int, int], ntypes: int) -> list[float]:
    """Each LAMMPS type's thermal conductivity (its sphere material's; 1 for wall types, unused)."""
    k = [1.0] * ntypes
    for m, t in type_of_mat.items():
        mat = model.materials[m]
        c = mat.props.get(THERMAL_CONDUCTIVITY, math.nan)
        if not (c > 0 and math.isfinite(c)):
            raise InputError(model.source, None, f"material {mat.key} ({mat.name}): the contact "
                             f"heat model needs its thermal conductivity (property 3) > 0 in "
                             f"W/(m K), got {c:g}")
        k[t - 1] = c
    return k


def _check_diffusion(model: GranularModel, rows: np.ndarray) -> None:
    """ModelEFLiquidDiffusion seeds particle i's generator with MUSEN's i-th seed and reads
    its coefficients at the particle's object id: the same sphere only when the spheres are
    objects 0 .. n-1, all simulated, in id order (fix musen/diffusion takes atom ID - 1)."""
    sp = model.spheres
    if not np.array_equal(sp.ids, np.arange(sp.count)) or len(rows) != sp.count or model.plan.inlets:
        raise InputError(model.source, None, "ModelEFLiquidDiffusion needs the spheres to be "
                         "objects 0 .. n-1, in that order, all simulated from the start and no "
                         "dynamic generators (MUSEN indexes its generators and coefficients by "
                         "these numbers)")


def _heat_capacities(model: GranularModel, type_of_mat: dict[int, int], ntypes: int) -> list[float]:
    """Each LAMMPS type's heat capacity (its sphere material's; 0 for wall types)."""
    cp = [0.0] * ntypes
    for m, t in type_of_mat.items():
        mat = model.materials[m]
        c = mat.props.get(HEAT_CAPACITY, math.nan)
        if not (c > 0 and math.isfinite(c)):
            # MUSEN divides the heat flux by heat capacity x mass
            raise InputError(model.source, None, f"material {mat.key} ({mat.name}): the heat "
                             f"model needs its heat capacity (property 1) > 0 in J/(kg K), got {c:g}")
        cp[t - 1] = c
    return cp


def _set_temperatures(model: GranularModel, rows: np.ndarray) -> list[str]:
    """A `set` per run of ids of equal non-zero temperature (the scene's 37; resuming from a
    checkpoint skips `set`, the restart file holds them)."""
    if model.plan.inlets:
        raise InputError(model.source, None, "ModelEFHeatTransfer with MUSEN's dynamic generators "
                         "is not supported (the generated spheres' temperature is not set)")
    sp = model.spheres
    temp = (np.zeros(sp.count) if sp.temperature is None else np.asarray(sp.temperature, float))[rows]
    lines = []
    ids = np.asarray(rows, np.int64) + 1
    start = 0
    for j in range(1, len(ids) + 1):
        if j == len(ids) or ids[j] != ids[j - 1] + 1 or temp[j] != temp[start]:
            span = str(ids[start]) if j - 1 == start else f"{ids[start]}*{ids[j - 1]}"
            if temp[start] != 0.0:
                lines.append(f"set             atom {span} {TEMPERATURE} {float_text(temp[start])}")
            start = j
    return lines
