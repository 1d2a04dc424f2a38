"""ModelEFCentrifugalCasting: MUSEN's sphere in a liquid turning about the y axis: buoyant
centrifugal force plus Stokes drag towards the liquid's velocity (``fix musen/field
centrifugal``, src/fix_musen_field.h).  Only with fibrelmp's LAMMPS styles."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ExternalField, GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

OMEGA, DENSITY, VISCOSITY = "ROTATION_VELOCITY", "LIQUID_DENSITY", "LIQUID_VISCOSITY"


@register
class EFCentrifugalCasting(PhysicsModel):
    name = "ModelEFCentrifugalCasting"
    kind = "EF"
    mdem_key = "1C8F05E0516329A78BF1359006D61003"
    parameters = {OMEGA: 1.0, DENSITY: 1000.0, VISCOSITY: 0.0018}
    needs_styles = "fix musen/field centrifugal"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        omega, rho, mu = params[OMEGA], params[DENSITY], params[VISCOSITY]
        if not math.isfinite(omega):
            raise InputError(path, line, f"{cls.name} parameter {OMEGA} must be finite in rad/s")
        for key, value, unit in ((DENSITY, rho, "kg/m3"), (VISCOSITY, mu, "Pa s")):
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(path, line, f"{cls.name} parameter {key} must be >= 0 in {unit} "
                                 f"(got {value:g})")
        plan.external_fields.append(ExternalField(
            cls.name, dict(params),
            f"centrifugal {float_text(omega)} {float_text(rho)} {float_text(mu)}"))
