"""ModelPWHertzMindlinLiquid: MUSEN's Hertz-Mindlin particle-wall contact plus a liquid bridge
(capillary force, normal and tangential viscous forces).  Only with fibrelmp's
``fix musen/wall/mesh ... law hertz/mindlin/liquid`` (src/musen_pw_hertz_mindlin_liquid.cpp).

Range: cmusen finds sphere-wall contacts with the contact radius, fix musen/wall/mesh with
LAMMPS's one radius: the same with contact radius = radius (other scenes are refused).  The
law's bridge length is MUSEN's max(|rc|, MIN_THICKNESS), |rc| the centre's distance to the
contact point (about the radius, not the gap), kept as MUSEN has it."""

from __future__ import annotations

from pathlib import Path

from fibrelmp.granmodel import GranularModel, GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.pp_hertz_mindlin_liquid import (
    ETA, HMIN, SIGMA, THETA, check_liquid_parameters, law_words)
from fibrelmp.translate.granular.models.pp_hertz_mindlin_vdw import check_one_radius


@register
class PWHertzMindlinLiquid(PhysicsModel):
    name = "ModelPWHertzMindlinLiquid"
    kind = "PW"
    mdem_key = "906949ACFFAE4B8C8B1B62209930EA6D"
    parameters = {HMIN: 1e-5, THETA: 70.0, SIGMA: 0.7, ETA: 0.1}
    needs_styles = "fix musen/wall/mesh law hertz/mindlin/liquid"

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)
        check_one_radius(model, cls.name, path, line)
        return params

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        check_liquid_parameters(cls.name, params, path, line)

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        return f"hertz/mindlin/liquid {law_words(params)}"
