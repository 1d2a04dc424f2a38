"""ModelSBCreep: MUSEN's creep solid bond (the elastic-perfectly-plastic law plus a normal
plastic strain and a tangential overlap that creep at A |stress|^m per second; breaks at a
fracture strain and, with FRACTURE_BY_STRESS, at MUSEN's stress criterion); only with
fibrelmp's ``bond_style musen/elastic ... creep``."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.sb_elastic_perfectly_plastic import (
    YIELD_PARAMETERS, check_finite, law_words)

CREEP_PARAMETERS = (*YIELD_PARAMETERS, "CREEP_PARAMATER_A", "CREEP_PARAMATER_m")   # MUSEN's spelling


@register
class SBCreep(PhysicsModel):
    name = "ModelSBCreep"
    kind = "SB"
    law_title = "Creep"
    plan_bond_model = "creep"
    mdem_key = "CA3CE500F3FE4E37914EC7D544333847"
    parameters = {"FRACTURE_STRAIN_TENSION": 0.1, "FRACTURE_STRAIN_COMPRESSION": 0.0,
                  "TANGENTIAL_YIELD": 1.0, "RATIO_COMPR_TENSILE_YIELD": 1.0,
                  "CREEP_PARAMATER_A": 0.01, "CREEP_PARAMATER_m": 0.01, "FRACTURE_BY_STRESS": 0.0}
    needs_styles = "bond_style musen/elastic with MUSEN's creep law"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_finite(cls.name, params, (*CREEP_PARAMETERS, "FRACTURE_BY_STRESS"), path, line)
        # any non-zero FRACTURE_BY_STRESS is MUSEN's stress criterion (the sums, 1)
        plan.bond_breakage = 1 if params["FRACTURE_BY_STRESS"] else 0
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=plan.bond_breakage,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return (cls.law_title, f"breakage {int(plan.bond_breakage)} creep "
                f"{law_words(plan.bond_law, CREEP_PARAMETERS)}")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then creep {int(law.breakage)} {law_words(law, CREEP_PARAMETERS)}"
