"""ModelEFLiquidDiffusion: MUSEN's Brownian motion of spheres in a liquid (random force from
MUSEN's own per-particle generators, plus drag; optionally the same for the rotation), with
``fix musen/diffusion`` (src/fix_musen_diffusion.h).  Only with fibrelmp's LAMMPS styles, and
only with a fixed seed: MUSEN seeds from the clock otherwise, which no run can reproduce."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ExternalField, GranularPlan
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text


@register
class EFLiquidDiffusion(PhysicsModel):
    name = "ModelEFLiquidDiffusion"
    kind = "EF"
    mdem_key = "57b926898e00d0c4350a9097fdf9cccdcd57be54"
    parameters = {"TEMPERATURE": 300.0, "DYN_VISCOSITY_OF_LIQUID": 0.000854163, "STOKES_FACTOR": 1.0,
                  "HYDR_SHELL": 0.0, "SEED_CHECK": 0.0, "FIXED_SEED": 0.0, "ORIENT_SWITCH": 0.0,
                  "ANNEALING_TYPE": 0.0, "ANNEALING_MAX_TEMP": 1000.0, "ANNEALING_COOLDOWN_TIME": 8e-07,
                  "ANNEALING_PERIOD": 1e-06, "ANNEALING_FINISHED_TIME": 0.001, "SAVE_FLAG": 0.0,
                  "SAVE_STEP": 1e-08, "SHEAR_RATE": 0.0, "DENSITY_LIQUID": 1000.0}
    needs_styles = "fix musen/diffusion"

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        def refuse(why: str) -> None:
            raise InputError(path, line, f"{cls.name}: {why}")

        seed = params["FIXED_SEED"]
        if seed == 0:
            refuse("without FIXED_SEED MUSEN seeds its generators from std::random_device, so no "
                   "run (not even cmusen's next) repeats it; give FIXED_SEED N (a whole number "
                   ">= 1) and fibrelmp draws MUSEN's numbers")
        if not (seed >= 1 and seed == math.floor(seed) and seed < 2 ** 63):
            refuse(f"FIXED_SEED must be a whole number >= 1 (got {seed:g})")
        if params["ANNEALING_TYPE"] != 0:
            refuse("annealing (ANNEALING_TYPE 1) is not supported; set ANNEALING_TYPE 0")
        if params["SHEAR_RATE"] != 0:
            refuse("the shear flow and its Saffman lift (SHEAR_RATE != 0) are not supported")
        if params["SAVE_FLAG"] != 0:
            refuse("SAVE_FLAG 1 (MUSEN's Post_KineticEnergy.csv and Post_Temperature.csv) is not "
                   "supported; set SAVE_FLAG 0")
        if params["ORIENT_SWITCH"] not in (0.0, 1.0):
            refuse(f"ORIENT_SWITCH must be 0 or 1 (got {params['ORIENT_SWITCH']:g})")
        for key in ("TEMPERATURE", "DYN_VISCOSITY_OF_LIQUID", "STOKES_FACTOR"):
            if not (params[key] > 0 and math.isfinite(params[key])):
                refuse(f"parameter {key} must be > 0 (got {params[key]:g})")
        if not (params["HYDR_SHELL"] >= 0 and math.isfinite(params["HYDR_SHELL"])):
            refuse(f"parameter HYDR_SHELL must be >= 0 (got {params['HYDR_SHELL']:g})")
        words = " ".join(float_text(params[k]) for k in ("TEMPERATURE", "DYN_VISCOSITY_OF_LIQUID",
                                                         "STOKES_FACTOR", "HYDR_SHELL"))
        plan.external_fields.append(ExternalField(
            cls.name, dict(params), f"{words} {int(seed)} {int(params['ORIENT_SWITCH'])}",
            style="musen/diffusion"))
