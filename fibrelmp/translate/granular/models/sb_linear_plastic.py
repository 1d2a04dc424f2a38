"""ModelSBLinearPlastic: MUSEN's linear plastic solid bond (normal force loading with KLoad and
unloading with KUnLoad, times the bond material's Young's modulus as a factor when that is
<= 2, else MUSEN's elastic normal force; tangential and moments elastic; MUSEN's stress
criterion); only with fibrelmp's ``bond_style musen/elastic ... linear/plastic``."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.sb_elastic_perfectly_plastic import (check_finite,
                                                                             law_words)

STIFFNESSES = ("KLoad", "KUnLoad")


@register
class SBLinearPlastic(PhysicsModel):
    name = "ModelSBLinearPlastic"
    kind = "SB"
    law_title = "Linear plastic"
    plan_bond_model = "linear_plastic"
    # MUSEN 1.74.2 gives it ModelSBElastic's key (ModelSBLinearPlastic.cpp)
    mdem_key = "4CE31CB89C784476AC1971DFC5C39C10"
    parameters = {"CONSIDER_BREAKAGE": 1.0, "KLoad": 1e6, "KUnLoad": 1e6}
    needs_styles = "bond_style musen/elastic with MUSEN's linear plastic law"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_finite(cls.name, params, ("CONSIDER_BREAKAGE", *STIFFNESSES), path, line)
        if params["KUnLoad"] == 0:
            raise InputError(path, line, f"{cls.name} parameter KUnLoad must not be 0 (MUSEN "
                             "divides by it)")
        # any non-zero CONSIDER_BREAKAGE is its one criterion (MUSEN's 1)
        plan.bond_breakage = 1 if params["CONSIDER_BREAKAGE"] else 0
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=plan.bond_breakage,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return (cls.law_title, f"breakage {int(plan.bond_breakage)} linear/plastic "
                f"{law_words(plan.bond_law, STIFFNESSES)}")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then linear/plastic {int(law.breakage)} {law_words(law, STIFFNESSES)}"
