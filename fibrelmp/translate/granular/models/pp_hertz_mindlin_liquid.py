"""ModelPPHertzMindlinLiquid: MUSEN's Hertz-Mindlin particle-particle contact plus a liquid
bridge (capillary force, normal and tangential viscous forces).  Only with fibrelmp's
``pair_style musen/liquid`` (src/musen_pp_hertz_mindlin_liquid.cpp).

Range: as ModelPPHertzMindlinVdW (pp_hertz_mindlin_vdw.py): cmusen runs the law while the
centre distance is below the sum of the contact radii, so with contact radius = radius (other
scenes are refused) the bridge acts only between touching spheres, with the gap at
MIN_THICKNESS."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, GranularPlan
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.pp_hertz_mindlin_vdw import check_one_radius
from fibrelmp.translate.lammps_format import float_text

HMIN, THETA, SIGMA, ETA = "MIN_THICKNESS", "CONTACT_ANGLE", "SURFACE_TENSION", "DYNAMIC_VISCOSITY"


def law_words(params: dict[str, float]) -> str:
    return " ".join(float_text(params[k]) for k in (HMIN, THETA, SIGMA, ETA))


def check_liquid_parameters(name: str, params: dict[str, float], path: Path | str | None,
                            line: int | None) -> None:
    """MUSEN divides by the gap (>= MIN_THICKNESS) and takes its logarithm: it must be > 0;
    a negative tension or viscosity is no liquid."""
    for key, unit, low in ((HMIN, "m", None), (SIGMA, "N/m", 0.0), (ETA, "Pa*s", 0.0)):
        value = params[key]
        good = math.isfinite(value) and (value > 0 if low is None else value >= low)
        if not good:
            raise InputError(path, line, f"{name} parameter {key} must be "
                             f"{'> 0' if low is None else '>= 0'} in {unit} (got {value:g})")
    if not math.isfinite(params[THETA]):
        raise InputError(path, line, f"{name} parameter {THETA} must be a number of degrees")


class LiquidBridgeModel(PhysicsModel):
    """What ModelPPHertzMindlinLiquid and ModelPWHertzMindlinLiquid share (not a MUSEN model
    itself: unregistered): MUSEN's parameters and defaults, one radius per sphere, the
    parameters' checks."""
    parameters = {HMIN: 1e-5, THETA: 70.0, SIGMA: 0.7, ETA: 0.1}

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


@register
class PPHertzMindlinLiquid(LiquidBridgeModel):
    name = "ModelPPHertzMindlinLiquid"
    kind = "PP"
    mdem_key = "B18A46C2786D4D44B925AASS4D0D1008"
    needs_styles = "pair_style musen/liquid"

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's Hertz-Mindlin contact with a liquid bridge; pair_style: "
                           "MIN_THICKNESS CONTACT_ANGLE SURFACE_TENSION DYNAMIC_VISCOSITY; "
                           "pair_coeff: E* G* e mu mu_r"),
                f"pair_style      musen/liquid {law_words(params)}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return f"hertz/mindlin/liquid {law_words(params)}"
