"""ModelSBThermal: MUSEN's thermal bond: the elastic bond whose rest length grows in time,
L0 (1 + THERM_DIFF alpha t) (alpha: the bond material's TIME_THERM_EXP_COEFF, property 14; t:
the simulation time), with normal damping -MU v_n A E |strain| and tangential damping
-MU (v_t x overlap) G A/L0, each capped at its elastic force, and MUSEN's combined stress
breakage test always on.  Only with fibrelmp's ``bond_style musen/elastic ... thermal``, with
one alpha for all bonds (the law takes one)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

ALPHA = "_TIME_THERM_EXP_COEFF"      # set by set_expansion (the bonds' material)
TIME_THERM_EXP_COEFF = 14            # MUSEN's material property id


@register
class SBThermal(PhysicsModel):
    name = "ModelSBThermal"
    kind = "SB"
    law_title = "Thermal"
    plan_bond_model = "thermal"
    mdem_key = "0CA458A6CCEF45C09BECD0D49306B86D"
    parameters = {"THERM_DIFF": 800.0, "MU": 1.0}
    needs_styles = "bond_style musen/elastic with MUSEN's thermal bond"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        for key in ("THERM_DIFF", "MU"):
            if not math.isfinite(params[key]):
                raise InputError(path, line, f"{cls.name} parameter {key} must be finite "
                                 f"(got {params[key]:g})")
        plan.bond_breakage = 1        # MUSEN tests the stresses always
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=1,
                                     parameters=dict(params))

    @classmethod
    def _words(cls, law: SolidBondLaw) -> str:
        p = law.parameters
        return f"{float_text(p['THERM_DIFF'])} {float_text(p['MU'])} {float_text(p[ALPHA])}"

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return (cls.law_title, f"breakage 1 thermal {cls._words(plan.bond_law)}")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then thermal 1 {cls._words(law)}"


def set_expansion(model: GranularModel) -> None:
    """Give the thermal laws the bonds' TIME_THERM_EXP_COEFF (one for all of them)."""
    plan = model.plan
    laws = [law for law in (plan.bond_law, *plan.then_bond_laws) if law.form == "thermal"]
    if not laws or model.bonds is None or len(model.bonds.material) == 0:
        return
    values = {model.materials[int(m)].props.get(TIME_THERM_EXP_COEFF, math.nan)
              for m in np.unique(model.bonds.material)}
    if len(values) != 1:
        raise InputError(model.source, None, "ModelSBThermal with bonds of different "
                         f"TIME_THERM_EXP_COEFF ({sorted(values)}) is not supported")
    alpha = values.pop()
    if not math.isfinite(alpha):
        raise InputError(model.source, None, "ModelSBThermal needs the bonds' material "
                         "TIME_THERM_EXP_COEFF (property 14)")
    for law in laws:
        law.parameters[ALPHA] = alpha
