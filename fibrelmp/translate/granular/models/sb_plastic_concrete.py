"""ModelSBPlasticConcrete: MUSEN's plastic concrete bond (normal stress capped in tension at
0.7 Y with softening and in compression at Y with hardening, Y the bond material's yield
strength; with CONSIDER_BREAKAGE it breaks when the tension-side stress turns negative; the
tangential force without MUSEN's usual 1/L0; and MUSEN's sign of the normal force: a
stretched bond pushes its spheres apart); only with fibrelmp's ``bond_style musen/elastic ...
concrete``."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.sb_elastic_perfectly_plastic import check_finite


@register
class SBPlasticConcrete(PhysicsModel):
    name = "ModelSBPlasticConcrete"
    kind = "SB"
    law_title = "Plastic concrete"
    plan_bond_model = "concrete"
    mdem_key = "CA3CE500F3FE4E37914SS7D544553847"    # MUSEN's, "SS" and all
    parameters = {"CONSIDER_BREAKAGE": 1.0}
    needs_styles = "bond_style musen/elastic with MUSEN's plastic concrete law"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_finite(cls.name, params, ("CONSIDER_BREAKAGE",), path, line)
        # CONSIDER_BREAKAGE (any non-zero value, as MUSEN tests != 0) turns its test on
        plan.bond_breakage = 1 if params["CONSIDER_BREAKAGE"] else 0
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=plan.bond_breakage,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return cls.law_title, f"breakage {int(plan.bond_breakage)} concrete"

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then concrete {int(law.breakage)}"
