"""ModelPPLinearElastic: MUSEN's linear elastic particle-particle contact (constant normal and
tangential stiffness Kn, Kt; MUSEN's damping from the restitution, Coulomb friction and
rolling torque as in Hertz-Mindlin).  Only with fibrelmp's ``pair_style musen/linear``."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text


@register
class PPLinearElastic(PhysicsModel):
    name = "ModelPPLinearElastic"
    kind = "PP"
    mdem_key = "B18A46C2786D4D44B925A8A04DAD1008"
    parameters = {"Kn": 1000.0, "Kt": 1000.0}
    needs_styles = "pair_style musen/linear"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        for key in ("Kn", "Kt"):
            # MUSEN divides by Kt when a contact slips: 0 would give nan, so both are > 0
            if not (params[key] > 0 and math.isfinite(params[key])):
                raise InputError(path, line, f"{cls.name} parameter {key} must be a stiffness "
                                 f"> 0 in N/m (got {params[key]:g})")
        kn = params["Kn"]

        def contact_time(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
            # half period of the undamped spring, pi sqrt(m*/Kn): any speed, no E*; damping
            # only lengthens it, so this is the shorter (stricter) figure
            return math.pi * math.sqrt(m_eff / kn)

        plan.pp_contact_time = contact_time
        plan.pp_contact_law = "linear elastic"

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's linear elastic particle-particle contact; pair_style: Kn Kt; "
                           "pair_coeff: E* G* e mu mu_r (E*, G* unused)"),
                f"pair_style      musen/linear {float_text(params['Kn'])} {float_text(params['Kt'])}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return f"linear/elastic {float_text(params['Kn'])} {float_text(params['Kt'])}"
