"""ModelSBElasticPerfectlyPlastic: MUSEN's elastic-perfectly-plastic solid bond (normal and
tangential stress capped at the bond material's yield strength, the normal plastic strain
kept per bond; breaks at a fracture strain); only with fibrelmp's ``bond_style musen/elastic
... plastic`` (stock LAMMPS has no such bond).  ModelSBCreep shares its law and checks."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

# the law's parameters in bond_style musen/elastic's order (FT FC TY RC)
YIELD_PARAMETERS = ("FRACTURE_STRAIN_TENSION", "FRACTURE_STRAIN_COMPRESSION", "TANGENTIAL_YIELD",
                    "RATIO_COMPR_TENSILE_YIELD")


def check_finite(model: str, params: dict[str, float], names: tuple[str, ...],
                 path: Path | str | None, line: int | None) -> None:
    """Every one of ``names`` a finite number (MUSEN takes any; nan or inf make every bond's
    force nan or break it at once)."""
    for name in names:
        if not math.isfinite(params[name]):
            raise InputError(path, line, f"{model} parameter {name} must be a finite number "
                             f"(got {params[name]:g})")


def law_words(law: SolidBondLaw, names: tuple[str, ...]) -> str:
    return " ".join(float_text(law.parameters[n]) for n in names)


@register
class SBElasticPerfectlyPlastic(PhysicsModel):
    name = "ModelSBElasticPerfectlyPlastic"
    kind = "SB"
    law_title = "Elastic-perfectly-plastic"
    plan_bond_model = "plastic"
    mdem_key = "CA3CE500F3FE4E37914EC7D544553847"
    parameters = {"FRACTURE_STRAIN_TENSION": 0.1, "FRACTURE_STRAIN_COMPRESSION": 0.0,
                  "TANGENTIAL_YIELD": 1.0, "RATIO_COMPR_TENSILE_YIELD": 1.0}
    needs_styles = "bond_style musen/elastic with MUSEN's elastic-perfectly-plastic law"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_finite(cls.name, params, YIELD_PARAMETERS, path, line)
        plan.bond_breakage = 0    # no stress criterion: it breaks by strain only
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model, breakage=0,
                                     parameters=dict(params))

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return cls.law_title, f"breakage 0 plastic {law_words(plan.bond_law, YIELD_PARAMETERS)}"

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then plastic 0 {law_words(law, YIELD_PARAMETERS)}"
