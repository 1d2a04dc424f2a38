"""ModelEFHeatTransfer: MUSEN's heating of every sphere by the surrounding air (convection and
MUSEN's radiation term), its temperature a per-sphere state read from the scene (MUSEN 37) and
saved in the results (``fix musen/field heat``, src/fix_musen_field.h).  Only with fibrelmp's
LAMMPS styles."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ExternalField, GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

T_INIT, T_FINAL, TIME = "AIR_TEMPERATURE_INIT", "AIR_TEMPERATURE_FINAL", "HEATING_TIME"
ALPHA, EPSILON, SCALE = "HEAT_TRANSFER_COEFFICIENT", "SURFACE_EMISSIVITY", "SCALING_FACTOR"


@register
class EFHeatTransfer(PhysicsModel):
    name = "ModelEFHeatTransfer"
    kind = "EF"
    mdem_key = "1C8F05E051634AA78BF1359006D61003"
    parameters = {T_INIT: 1000.0, T_FINAL: 1000.0, TIME: 1.0, ALPHA: 5.0, EPSILON: 0.8, SCALE: 1.0}
    needs_styles = "fix musen/field heat"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        for key, unit in ((T_INIT, "K"), (T_FINAL, "K"), (ALPHA, "W/(m2 K)"), (EPSILON, "-"),
                          (SCALE, "-")):
            if not (params[key] >= 0 and math.isfinite(params[key])):
                raise InputError(path, line, f"{cls.name} parameter {key} must be >= 0 in {unit} "
                                 f"(got {params[key]:g})")
        # MUSEN divides the temperature rise by HEATING_TIME (0: nan before the first step)
        if not (params[TIME] > 0 and math.isfinite(params[TIME])):
            raise InputError(path, line, f"{cls.name} parameter {TIME} must be > 0 in s "
                             f"(got {params[TIME]:g})")
        words = " ".join(float_text(params[k]) for k in (T_INIT, T_FINAL, TIME, ALPHA, EPSILON, SCALE))
        plan.external_fields.append(ExternalField(cls.name, dict(params), f"heat {words}", heat=True))
