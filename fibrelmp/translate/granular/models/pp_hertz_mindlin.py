"""ModelPPHertzMindlin: MUSEN's Hertz-Mindlin particle-particle contact.  Rendered by
``granular.contacts`` as fibrelmp's ``pair_style musen/hm`` (exact) or, without fibrelmp's
styles, stock ``pair_style granular`` (approximate friction, a named warning)."""

from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register


@register
class PPHertzMindlin(PhysicsModel):
    name = "ModelPPHertzMindlin"
    kind = "PP"
    mdem_key = "B18A46C2786D4D44B925A8A04D0D1008"
    default = True

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if own_styles:
            # fibrelmp's own text, not the user's: a comment as it stands
            return [LammpsText("# MUSEN's Hertz-Mindlin particle-particle contact; pair_coeff: "
                               "E* G* e mu mu_r"), "pair_style      musen/hm"]
        return ["pair_style      granular"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return "hertz/mindlin"
