"""ModelEFViscousField: MUSEN's drag of a medium at rest on every sphere, with a drag
coefficient of three Reynolds-number regimes (``fix musen/field viscous``,
src/fix_musen_field.h).  Only with fibrelmp's LAMMPS styles."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ExternalField, GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

VISCOSITY, DENSITY = "MEDIUM_VISCOSITY", "MEDIUM_DENSITY"


@register
class EFViscousField(PhysicsModel):
    name = "ModelEFViscousField"
    kind = "EF"
    mdem_key = "1C8F05E0516349A78BF1359006D61003"
    parameters = {VISCOSITY: 1.34e-05, DENSITY: 1.28}
    needs_styles = "fix musen/field viscous"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        nu, rho = params[VISCOSITY], params[DENSITY]
        # MUSEN divides by the viscosity (Re = 2 r |v| / nu): 0 gives nan forces, < 0 a push
        if not (nu > 0 and math.isfinite(nu)):
            raise InputError(path, line, f"{cls.name} parameter {VISCOSITY} must be a kinematic "
                             f"viscosity > 0 in m2/s (got {nu:g})")
        if not (rho >= 0 and math.isfinite(rho)):
            raise InputError(path, line, f"{cls.name} parameter {DENSITY} must be >= 0 in kg/m3 "
                             f"(got {rho:g})")
        plan.external_fields.append(ExternalField(
            cls.name, dict(params), f"viscous {float_text(nu)} {float_text(rho)}"))
