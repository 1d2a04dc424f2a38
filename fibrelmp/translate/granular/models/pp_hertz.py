"""ModelPPHertz: MUSEN's Hertz particle-particle contact (Hertz normal force without damping,
an incremental tangential force capped by Coulomb friction, rolling torque).  Only with
fibrelmp's ``pair_style musen/pp hertz``; it keeps MUSEN's tangential force in the contact's
history, so it cannot act together with another PP model."""

from __future__ import annotations

from fibrelmp.errors import InputError
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register


@register
class PPHertz(PhysicsModel):
    name = "ModelPPHertz"
    kind = "PP"
    mdem_key = "B7CBEB0657884100930E6C68E2C438EB"
    needs_styles = "pair_style musen/pp hertz"
    # with another PP model: refused at the later model's line (script_settings)
    acts_alone = True

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's Hertz particle-particle contact (no damping); pair_coeff: "
                           "E* G* e mu mu_r (e unused)"),
                "pair_style      musen/pp hertz"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        # refused before rendering (script_settings, acts_alone); kept as a guard
        raise InputError(None, None, f"{cls.name} acts only as the only PP model (it keeps "
                         "MUSEN's tangential force where the others keep the tangential "
                         "overlap); fibrelmp cannot run it together with another PP model")
