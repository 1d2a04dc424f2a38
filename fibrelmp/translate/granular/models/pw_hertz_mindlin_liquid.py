"""ModelPWHertzMindlinLiquid: MUSEN's Hertz-Mindlin particle-wall contact plus a liquid bridge
(capillary force, normal and tangential viscous forces).  Only with fibrelmp's
``fix musen/wall/mesh ... law hertz/mindlin/liquid`` (src/musen_pw_hertz_mindlin_liquid.cpp).

Range: cmusen finds sphere-wall contacts with the contact radius, fix musen/wall/mesh with
LAMMPS's one radius: the same with contact radius = radius (other scenes are refused).  The
law's bridge length is MUSEN's max(|rc|, MIN_THICKNESS), |rc| the centre's distance to the
contact point (about the radius, not the gap), kept as MUSEN has it."""

from __future__ import annotations

from fibrelmp.translate.granular.models import register
from fibrelmp.translate.granular.models.pp_hertz_mindlin_liquid import LiquidBridgeModel, law_words


@register
class PWHertzMindlinLiquid(LiquidBridgeModel):
    name = "ModelPWHertzMindlinLiquid"
    kind = "PW"
    mdem_key = "906949ACFFAE4B8C8B1B62209930EA6D"
    needs_styles = "fix musen/wall/mesh law hertz/mindlin/liquid"

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        return f"hertz/mindlin/liquid {law_words(params)}"
