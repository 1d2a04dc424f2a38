"""ModelSBKelvin: MUSEN's Kelvin solid bond (elastic plus damping capped by MAX_DAMP_RATIO);
only with fibrelmp's ``bond_style musen/elastic ... kelvin`` (stock LAMMPS has no such bond)."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.sb_elastic import apply_breakage
from fibrelmp.translate.lammps_format import float_text


@register
class SBKelvin(PhysicsModel):
    name = "ModelSBKelvin"
    kind = "SB"
    plan_bond_model = "kelvin"
    mdem_key = "09405654485642A686561E1FC646DF1E"
    parameters = {"CONSIDER_BREAKAGE": 1.0, "MAX_DAMP_RATIO": 1.0}
    needs_styles = "bond_style musen/elastic with MUSEN's Kelvin damping"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        apply_breakage(plan, params, path, line)
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, float(params["MAX_DAMP_RATIO"]))
        # any non-zero CONSIDER_BREAKAGE is its one criterion (MUSEN's 1)
        plan.bond_breakage = 1 if plan.bond_breakage else 0
        cap = plan.bond_law.max_damp_ratio
        if not (cap >= 0 and math.isfinite(cap)):
            raise InputError(path, line, f"MAX_DAMP_RATIO must be >= 0 (0: no cap; got {cap:g})")

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return ("Kelvin", f"breakage {int(plan.bond_breakage)} kelvin "
                f"{float_text(plan.bond_law.max_damp_ratio)}")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then kelvin {int(law.breakage)} {float_text(law.max_damp_ratio)}"
