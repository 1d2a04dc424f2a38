"""ModelSBElastic: MUSEN's elastic solid bond (``bond_style musen/elastic``, or stock
``bpm/rotational`` without fibrelmp's styles; ``granular.bonds``)."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan, SolidBondLaw
from fibrelmp.translate.granular.models import PhysicsModel, register


def apply_breakage(plan: GranularPlan, params: dict[str, float], path: Path | str | None,
                   line: int | None) -> None:
    """CONSIDER_BREAKAGE of a solid bond: 0 none, 1 combined, 2 separate criteria."""
    plan.bond_breakage = int(params["CONSIDER_BREAKAGE"])
    if plan.bond_breakage not in (0, 1, 2) or plan.bond_breakage != params["CONSIDER_BREAKAGE"]:
        raise InputError(path, line, "CONSIDER_BREAKAGE must be "
                         f"0, 1 or 2 (got {params['CONSIDER_BREAKAGE']:g})")


@register
class SBElastic(PhysicsModel):
    name = "ModelSBElastic"
    kind = "SB"
    plan_bond_model = "elastic"
    mdem_key = "4CE31CB89C784476AC1971DFC5C39C10"
    parameters = {"CONSIDER_BREAKAGE": 1.0}
    default = True

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        apply_breakage(plan, params, path, line)
        plan.bond_law = SolidBondLaw(cls.name, cls.plan_bond_model)

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        return "elastic", f"breakage {int(plan.bond_breakage)}"

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        return f"then elastic {int(law.breakage)}"
