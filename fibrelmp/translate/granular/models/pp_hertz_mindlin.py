"""ModelPPHertzMindlin: MUSEN's Hertz-Mindlin particle-particle contact.  Rendered by
``granular.contacts`` as fibrelmp's ``pair_style musen/hm`` (exact) or, without fibrelmp's
styles, stock ``pair_style granular`` (approximate friction, a named warning)."""

from fibrelmp.translate.granular.models import PhysicsModel, register


@register
class PPHertzMindlin(PhysicsModel):
    name = "ModelPPHertzMindlin"
    kind = "PP"
    mdem_key = "B18A46C2786D4D44B925A8A04D0D1008"
    default = True
