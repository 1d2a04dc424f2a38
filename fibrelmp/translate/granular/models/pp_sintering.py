"""ModelPPSintering: MUSEN's sintering particle-particle contact (Bouvard and McMeeking; MUSEN's
Models/ParticleParticle/TestSinteringModel): a constant pull 1.125 pi 2R* gamma* along the normal
from the materials' surface energy (property 11) and normal and tangential viscous forces that
grow with the overlap; no elastic force, no moments.  Only with fibrelmp's
``pair_style musen/sintering`` (src/musen_pp_sintering.cpp).

Range: MUSEN evaluates it only for a collision (centre distance below the sum of the *contact*
radii) and measures the overlap with them; LAMMPS holds one radius, so scenes whose contact
radius differs from the radius are refused, as for ModelPPHertzMindlinVdW."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import register
from fibrelmp.translate.granular.models.pp_hertz_mindlin_vdw import GAMMA, SurfaceEnergyModel
from fibrelmp.translate.lammps_format import float_text


@register
class PPSintering(SurfaceEnergyModel):
    name = "ModelPPSintering"
    kind = "PP"
    mdem_key = "A41AB40D3A074FE9AAE0B0ADB27ABFBA"
    parameters = {"DIFFUSION": 1.28e-34, "VISCOUS_PARAMETER": 0.01}
    needs_styles = "pair_style musen/sintering"

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)      # radius, surface energy
        # MUSEN divides by DIFFUSION: 0 gives inf/nan forces there; refused here
        if not (params["DIFFUSION"] > 0 and math.isfinite(params["DIFFUSION"])):
            raise InputError(path, line, f"{cls.name} parameter DIFFUSION must be > 0 "
                             f"(got {params['DIFFUSION']:g})")
        if not math.isfinite(params["VISCOUS_PARAMETER"]):
            raise InputError(path, line, f"{cls.name} parameter VISCOUS_PARAMETER must be finite")
        return params

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's sintering contact; pair_style: DIFFUSION VISCOUS_PARAMETER "
                           "and the equivalent surface energy [J/m2]; pair_coeff: E* G* e mu mu_r "
                           "(unused by this law)"),
                f"pair_style      musen/sintering {cls._words(params)}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return f"sintering {cls._words(params)}"

    @staticmethod
    def _words(params: dict[str, float]) -> str:
        return " ".join(float_text(params[k]) for k in ("DIFFUSION", "VISCOUS_PARAMETER", GAMMA))
