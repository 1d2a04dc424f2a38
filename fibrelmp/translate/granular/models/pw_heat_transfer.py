"""ModelPWHeatTransfer: MUSEN's heat transfer between a sphere and a wall at the constant
temperature WALL_TEMPERATURE (no force): heat flux pi R overlap HEAT_TRANSFER_COEFF
RESISTIVITY_FACTOR (T_wall - T) into the sphere for each wall contact.  ``fix musen/wall/mesh``
law ``heat/transfer``; the temperatures are updated by ``fix musen/heat``
(src/fix_musen_heat.h).  Only with fibrelmp's LAMMPS styles."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

WALL_T, COEFF, RESIST = "WALL_TEMPERATURE", "HEAT_TRANSFER_COEFF", "RESISTIVITY_FACTOR"


@register
class PWHeatTransfer(PhysicsModel):
    name = "ModelPWHeatTransfer"
    kind = "PW"
    mdem_key = "E51F4196FE24495191EA9A1A8E794925"
    parameters = {WALL_T: 1173.0, COEFF: 50.0, RESIST: 0.2}
    needs_styles = "fix musen/wall/mesh law heat/transfer, fix musen/heat"
    contact_heat = True     # fields.py: temperatures, fix musen/heat

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        for key in (WALL_T, COEFF, RESIST):
            if not math.isfinite(params[key]):
                raise InputError(path, line, f"{cls.name} parameter {key} must be finite "
                                 f"(got {params[key]:g})")
        # no force: the walls' contact duration stays the first PW model's
        plan.pw_contact_time = lambda m_eff, r_eff, e_star, speed: math.inf
        plan.pw_contact_law = "heat transfer (no force)"

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        return "heat/transfer " + " ".join(float_text(params[k]) for k in (WALL_T, COEFF, RESIST))
