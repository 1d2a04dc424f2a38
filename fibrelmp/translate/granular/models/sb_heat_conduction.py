"""ModelSBHeatConduction: MUSEN's heat conduction along a solid bond (no force): heat flux
CONDUCTION_SCALING_FACTOR A k (T_right - T_left) / |x_right - x_left| into the bond's left
sphere (out of its right one), A = pi d^2/4, k the bond material's thermal conductivity
(property 3).  A later law of ``bond_style musen/elastic`` (``then heat 0 SCALE K``); the
temperatures are updated by ``fix musen/heat`` (src/fix_musen_heat.h).  Only with fibrelmp's
LAMMPS styles, after a force law (MUSEN's SB model order), and with one conductivity for all
bonds (the law takes one)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

SCALE = "CONDUCTION_SCALING_FACTOR"
CONDUCTIVITY = "_BOND_THERMAL_CONDUCTIVITY"   # set by set_conductivity (the bonds' material)


@register
class SBHeatConduction(PhysicsModel):
    name = "ModelSBHeatConduction"
    kind = "SB"
    law_title = "Heat conduction"
    plan_bond_model = "heat"
    mdem_key = "3BF7750E0AC54B8E909126CE48F7D85F"
    parameters = {SCALE: 1.0}
    needs_styles = "bond_style musen/elastic ... then heat, fix musen/heat"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        if not math.isfinite(params[SCALE]):
            raise InputError(path, line, f"{cls.name} parameter {SCALE} must be finite "
                             f"(got {params[SCALE]:g})")
        plan.bond_breakage = 0
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=0,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        raise InputError(None, None, f"{cls.name} as the first (or only) solid-bond model is not "
                         "supported: select a bond force model first (MODEL_SB ModelSBElastic, "
                         f"then MODEL_SB {cls.name})")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return (f"then heat 0 {float_text(law.parameters[SCALE])} "
                f"{float_text(law.parameters[CONDUCTIVITY])}")


def heat_laws(plan: GranularPlan) -> list[SolidBondLaw]:
    return [law for law in (plan.bond_law, *plan.then_bond_laws) if law.form == "heat"]


def set_conductivity(model: GranularModel) -> None:
    """Give the heat laws the bonds' thermal conductivity (one for all of them)."""
    laws = heat_laws(model.plan)
    if not laws or model.bonds is None or len(model.bonds.material) == 0:
        return
    values = {model.materials[int(m)].props.get(3, math.nan)
              for m in np.unique(model.bonds.material)}
    if len(values) != 1:
        raise InputError(model.source, None, "ModelSBHeatConduction with bonds of different "
                         f"thermal conductivities ({sorted(values)}) is not supported")
    k = values.pop()
    if not (k > 0 and math.isfinite(k)):
        raise InputError(model.source, None, "ModelSBHeatConduction needs the bonds' material "
                         f"thermal conductivity (property 3) > 0 in W/(m K), got {k:g}")
    for law in laws:
        law.parameters[CONDUCTIVITY] = k
