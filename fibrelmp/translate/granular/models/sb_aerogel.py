"""ModelSBAerogel: MUSEN's aerogel bond (normal force elastic up to a plastic strain in
compression and in tension, softening beyond it until the bond is "broken" on that side, after
which it only resists further compression / tension with a hardness ratio; breaks when the
force exceeds BREAK_STRAIN_TENS A E; tangential and moments elastic); only with fibrelmp's
``bond_style musen/elastic ... aerogel``."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.sb_elastic_perfectly_plastic import (check_finite,
                                                                             law_words)

WORDS = ("PLASTIC_STRAIN_COMPR", "PLASTIC_STRAIN_TENS", "SOFTNESS_RATIO_COMPR",
         "SOFTNESS_RATIO_TENS", "BREAK_STRAIN_TENS", "HARDNESS_RATIO_COMPR", "HARDNESS_RATIO_TENS")


@register
class SBAerogel(PhysicsModel):
    name = "ModelSBAerogel"
    kind = "SB"
    law_title = "Aerogel"
    plan_bond_model = "aerogel"
    mdem_key = "4CE31CB89C784476AC1971DFC5C39C12"
    parameters = {"PLASTIC_STRAIN_COMPR": 0.1, "PLASTIC_STRAIN_TENS": 0.05,
                  "SOFTNESS_RATIO_COMPR": -2.0, "SOFTNESS_RATIO_TENS": 0.0,
                  "BREAK_STRAIN_TENS": 0.5, "HARDNESS_RATIO_COMPR": 0.1, "HARDNESS_RATIO_TENS": 0.1}
    needs_styles = "bond_style musen/elastic with MUSEN's aerogel law"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_finite(cls.name, params, WORDS, path, line)
        plan.bond_breakage = 0    # no stress criterion: it breaks by its force
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=0,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return cls.law_title, f"breakage 0 aerogel {law_words(plan.bond_law, WORDS)}"

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then aerogel 0 {law_words(law, WORDS)}"
