"""ModelPWSimpleViscoElastic: MUSEN's simple viscoelastic particle-wall contact, a normal
force only (spring NORMAL_FORCE_COEFF times the overlap, dashpot NORMAL_DAMPING_PARAMETER on
the normal relative velocity; no friction, no torque).  Only with fibrelmp's
``fix musen/wall/mesh ... law simple/viscoelastic``."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

STIFFNESS, DAMPING = "NORMAL_FORCE_COEFF", "NORMAL_DAMPING_PARAMETER"


@register
class PWSimpleViscoElastic(PhysicsModel):
    name = "ModelPWSimpleViscoElastic"
    kind = "PW"
    mdem_key = "522836B77298445A8FFD02CA55FFF717"
    parameters = {STIFFNESS: 1.0, DAMPING: 0.0}
    needs_styles = "fix musen/wall/mesh law simple/viscoelastic"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        kn, eta = params[STIFFNESS], params[DAMPING]
        if not (kn > 0 and math.isfinite(kn)):
            raise InputError(path, line, f"{cls.name} parameter {STIFFNESS} must be a "
                             f"stiffness > 0 in N/m (got {kn:g})")
        if not (eta >= 0 and math.isfinite(eta)):
            raise InputError(path, line, f"{cls.name} parameter {DAMPING} must be >= 0 in "
                             f"N s/m (got {eta:g})")

        def contact_time(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
            # half period of the undamped spring on the sphere's mass (damping lengthens it)
            return math.pi * math.sqrt(m_eff / kn)

        plan.pw_contact_time = contact_time
        plan.pw_contact_law = "simple viscoelastic"

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        return f"simple/viscoelastic {float_text(params[STIFFNESS])} {float_text(params[DAMPING])}"
