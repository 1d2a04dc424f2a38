"""ModelPPSimpleViscoElastic: MUSEN's simple viscoelastic particle-particle contact: a normal
force -Kn overlap + mu vn (linear spring and dashpot), nothing tangential, no moments.  Only
with fibrelmp's ``pair_style musen/pp simple/viscoelastic``."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text


@register
class PPSimpleViscoElastic(PhysicsModel):
    name = "ModelPPSimpleViscoElastic"
    kind = "PP"
    mdem_key = "5B1DBC037BAE488086159B7731E1D68F"
    parameters = {"NORMAL_FORCE_COEFF": 1.0, "NORMAL_DAMPING_PARAMETER": 0.0}
    needs_styles = "pair_style musen/pp simple/viscoelastic"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        kn, mu = params["NORMAL_FORCE_COEFF"], params["NORMAL_DAMPING_PARAMETER"]
        # MUSEN runs any value; Kn <= 0 lets spheres pass through or attract them and mu < 0
        # feeds energy in: fibrelmp refuses both rather than run a non-contact
        if not (kn > 0 and math.isfinite(kn)):
            raise InputError(path, line, f"{cls.name} parameter NORMAL_FORCE_COEFF must be a "
                             f"stiffness > 0 in N/m (got {kn:g})")
        if not (mu >= 0 and math.isfinite(mu)):
            raise InputError(path, line, f"{cls.name} parameter NORMAL_DAMPING_PARAMETER must "
                             f"be a damping >= 0 in N s/m (got {mu:g})")

        def contact_time(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
            # half period of the undamped spring; damping only lengthens it
            return math.pi * math.sqrt(m_eff / kn)

        plan.pp_contact_time = contact_time
        plan.pp_contact_law = "simple viscoelastic"

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's simple viscoelastic particle-particle contact (normal "
                           "only); pair_coeff: E* G* e mu mu_r (unused)"),
                f"pair_style      musen/pp {cls.pp_law_words(params)}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return (f"simple/viscoelastic {float_text(params['NORMAL_FORCE_COEFF'])} "
                f"{float_text(params['NORMAL_DAMPING_PARAMETER'])}")
