"""ModelPPHeatConduction: MUSEN's heat conduction through a particle-particle contact (no
force): heat flux 2 a SCALE f k* (T_dst - T_src) into src, a = 2 sqrt(R* overlap), k* = 1/(1/k_i
+ 1/k_j) of the materials' thermal conductivities, f the resistivity factor ramping from
RESISTIVITY_FACTOR (overlap/(4 R*) <= MIN_OVERLAP) to 1 (>= MAX_OVERLAP).  pair musen/hm's law
``heat/conduction`` after the contact law; the temperatures are updated by ``fix musen/heat``
(src/fix_musen_heat.h).  Only with fibrelmp's LAMMPS styles."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

SCALE, RESIST, LO, HI = "CONDUCTION_SCALING_FACTOR", "RESISTIVITY_FACTOR", "MIN_OVERLAP", "MAX_OVERLAP"


@register
class PPHeatConduction(PhysicsModel):
    name = "ModelPPHeatConduction"
    kind = "PP"
    mdem_key = "B18A46C2786D4D44B925A8A04D0D1098"
    parameters = {SCALE: 1.0, RESIST: 0.2, LO: 0.03, HI: 0.05}
    needs_styles = "pair_style musen/hm ... then heat/conduction, fix musen/heat"
    contact_heat = True     # fields.py: temperatures, fix musen/heat

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        for key in (SCALE, RESIST, LO, HI):
            if not math.isfinite(params[key]):
                raise InputError(path, line, f"{cls.name} parameter {key} must be finite "
                                 f"(got {params[key]:g})")
        # MUSEN divides by MAX_OVERLAP - MIN_OVERLAP only between them: equal ones never do
        if params[HI] < params[LO]:
            raise InputError(path, line, f"{cls.name}: MAX_OVERLAP ({params[HI]:g}) below "
                             f"MIN_OVERLAP ({params[LO]:g})")
        # no force: the plan's contact duration stays the first PP model's
        plan.pp_contact_time = lambda m_eff, r_eff, e_star, speed: math.inf
        plan.pp_contact_law = "heat conduction (no force)"

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        raise InputError(None, None, f"{cls.name} as the first (or only) particle-particle model "
                         "is not supported: select a contact law first (MODEL_PP "
                         f"ModelPPHertzMindlin, then MODEL_PP {cls.name})")

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return "heat/conduction " + " ".join(float_text(params[k]) for k in (SCALE, RESIST, LO, HI))
