"""ModelPPChealNess: MUSEN's Hertz-Mindlin particle-particle contact plus Cheal and Ness's
lubrication forces, which act at surface gaps from MIN_THICKNESS to MAX_THICKNESS.

cmusen runs a PP model only for a collision, while the centre distance is below the sum of
the contact radii (CollisionsCalculator.cpp CheckPPCollision).  With contact radius = radius
(other scenes are refused: LAMMPS holds one radius) the law therefore runs only between
touching spheres, whose gap is negative: with MIN_THICKNESS > 0 the lubrication never acts
and MUSEN's law is its Hertz-Mindlin part, which fibrelmp runs (``pair_style musen/hm``, the
same operations up to the order of one subtraction) with a warning that says so.  (The real
cmusen 1.74.2 gives Hertz-Mindlin's results bit for bit on such a scene:
tests/data/real-outputs/musen/models/pp_cheal_ness.)"""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.granular.models.pp_hertz_mindlin_vdw import check_one_radius

HMIN, HMAX, ETA = "MIN_THICKNESS", "MAX_THICKNESS", "FLUID_VISCOSITY"


@register
class PPChealNess(PhysicsModel):
    name = "ModelPPChealNess"
    kind = "PP"
    mdem_key = "B18A4SSSS6D4D44B925A8A04D0D1008"
    parameters = {HMIN: 1e-5, HMAX: 5e-3, ETA: 0.1}
    needs_styles = "pair_style musen/hm"
    raw_coordinate_distance = True

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)
        check_one_radius(model, cls.name, path, line)
        at = f"{path}:{line}" if line is not None else f"{path} (its model manager)"
        model.warn("musen-model-acts-as-hertz-mindlin",
                   f"{at}: {cls.name}: its lubrication acts at surface gaps of "
                   "MIN_THICKNESS to MAX_THICKNESS, beyond touching, where cmusen finds no "
                   "contact between spheres whose contact radius equals their radius; cmusen "
                   "runs its Hertz-Mindlin part alone here, and so does fibrelmp")
        return params

    @classmethod
    def apply(cls, plan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        # with MIN_THICKNESS <= 0 a touching pair's negative gap can fall in the range, where
        # MUSEN takes log(1 / Xi) of a negative Xi: its results turn to nan
        if not (params[HMIN] > 0 and math.isfinite(params[HMIN])):
            raise InputError(path, line, f"{cls.name} parameter {HMIN} must be > 0 in m (got "
                             f"{params[HMIN]:g}; MUSEN's lubrication of touching spheres then "
                             "gives nan)")
        for key, unit in ((HMAX, "m"), (ETA, "Pa*s")):
            if not math.isfinite(params[key]):
                raise InputError(path, line, f"{cls.name} parameter {key} must be a number in "
                                 f"{unit}")

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's Cheal-Ness contact between touching spheres: its "
                           "Hertz-Mindlin part (the lubrication acts only at gaps > 0); "
                           "pair_coeff: E* G* e mu mu_r"), "pair_style      musen/hm"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return "hertz/mindlin"
