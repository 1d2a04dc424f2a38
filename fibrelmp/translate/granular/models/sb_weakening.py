"""ModelSBWeakening: MUSEN's bond with weakening (elastic until the normal or tangential stress
exceeds the bond material's yield strength; there MUSEN scales the elastic strain or the
tangential overlap by WEAKENING_FACTOR rand()/RAND_MAX; breaks at BREAKAGE_STRAIN, in
compression at twice it with COMPRESSIVE_BREAK); only with fibrelmp's ``bond_style
musen/elastic ... weakening``.  The random draw cannot be reproduced: with WEAKENING_FACTOR 0
the law is exact (the draw is multiplied by 0); otherwise a run stops with an error at the
first bond beyond its yield strength (until then the law is exact)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.sb_elastic_perfectly_plastic import (check_finite,
                                                                             law_words)

WORDS = ("COMPRESSIVE_BREAK", "BREAKAGE_STRAIN", "WEAKENING_FACTOR")


@register
class SBWeakening(PhysicsModel):
    name = "ModelSBWeakening"
    kind = "SB"
    law_title = "Weakening"
    plan_bond_model = "weakening"
    mdem_key = "CA3CE500F3FE4E33914EC7D544553847"
    parameters = {"CONSIDER_BREAKAGE": 1.0, "COMPRESSIVE_BREAK": 0.0, "BREAKAGE_STRAIN": 0.1,
                  "WEAKENING_FACTOR": 0.5}
    needs_styles = "bond_style musen/elastic with MUSEN's weakening law"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_finite(cls.name, params, ("CONSIDER_BREAKAGE", *WORDS), path, line)
        # CONSIDER_BREAKAGE turns its strain test on (any non-zero value, as MUSEN tests == 0)
        plan.bond_breakage = 1 if params["CONSIDER_BREAKAGE"] else 0
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=plan.bond_breakage,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return (cls.law_title, f"breakage {int(plan.bond_breakage)} weakening "
                f"{law_words(plan.bond_law, WORDS)}")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then weakening {int(law.breakage)} {law_words(law, WORDS)}"
