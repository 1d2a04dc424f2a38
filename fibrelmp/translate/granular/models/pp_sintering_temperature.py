"""ModelPPSinteringTemperature: MUSEN's sintering contact that acts by temperature (MUSEN's
Models/ParticleParticle/SinteringTemperature): with the pair's mean temperature at or above
MINIMAL_TEMPERATURE and the overlap below MAX_OVERLAP_COEFF 2R*, ModelPPSintering's law with the
diffusion parameter ATOMIC_VOLUME/(kB T) GRAINBOUND_DIFFUSION exp(-ACTIVATION_ENERGY/(R T));
below it a Hertz-like spring towards the contact's initial overlap (its overlap at time 0; zero
for a later contact); hot and past the maximum overlap a normal spring towards it.  Only with
fibrelmp's ``pair_style musen/pp sintering/temperature`` (src/musen_pp_sintering_temperature.cpp),
which reads the spheres' temperatures (d_musen_temperature, scene tag 37) and keeps the initial
overlap as its own one-value block of each contact's history.  Range: as ModelPPSintering (one radius)."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import register
from fibrelmp.translate.granular.models.pp_hertz_mindlin_vdw import GAMMA, SurfaceEnergyModel
from fibrelmp.translate.lammps_format import float_text

NAMES = ("GRAINBOUND_DIFFUSION", "VISCOUS_PARAMETER", "ATOMIC_VOLUME", "ACTIVATION_ENERGY",
         "MINIMAL_TEMPERATURE", "MAX_OVERLAP_COEFF")


@register
class PPSinteringTemperature(SurfaceEnergyModel):
    name = "ModelPPSinteringTemperature"
    kind = "PP"
    mdem_key = "A41AB40D3A074FE9AAE0B0ADB27XBFBA"
    parameters = {"GRAINBOUND_DIFFUSION": 1.3e-8, "VISCOUS_PARAMETER": 0.01,
                  "ATOMIC_VOLUME": 8.47e-30, "ACTIVATION_ENERGY": 475000,
                  "MINIMAL_TEMPERATURE": 1000, "MAX_OVERLAP_COEFF": 0.2784}
    needs_styles = "pair_style musen/pp sintering/temperature"
    # fields.uses_temperature: the spheres' temperatures as d_musen_temperature
    reads_temperature = True

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)      # radius, surface energy
        for key in NAMES:
            if not math.isfinite(params[key]):
                raise InputError(path, line, f"{cls.name} parameter {key} must be finite")
        # MUSEN divides by the diffusion parameter (ATOMIC_VOLUME ... ): 0 gives inf/nan there
        if not params["ATOMIC_VOLUME"] > 0:
            raise InputError(path, line, f"{cls.name} parameter ATOMIC_VOLUME must be > 0 "
                             f"(got {params['ATOMIC_VOLUME']:g})")
        if not params["MAX_OVERLAP_COEFF"] >= 0:
            raise InputError(path, line, f"{cls.name} parameter MAX_OVERLAP_COEFF must be >= 0")
        return params

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's sintering contact by temperature; law: "
                           + " ".join(NAMES) + " and the equivalent surface energy [J/m2]; "
                           "pair_coeff: E* G* e mu mu_r (mu, mu_r unused)"),
                f"pair_style      musen/pp {cls.pp_law_words(params)}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return "sintering/temperature " + " ".join(float_text(params[k]) for k in (*NAMES, GAMMA))
