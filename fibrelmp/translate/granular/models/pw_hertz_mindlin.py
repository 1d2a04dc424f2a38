"""ModelPWHertzMindlin: MUSEN's Hertz-Mindlin particle-wall contact.  Rendered by
``granular.walls`` / ``granular.mesh`` (``fix musen/wall/mesh``, or stock ``fix wall/gran``
and wall particles)."""

from fibrelmp.translate.granular.models import PhysicsModel, register


@register
class PWHertzMindlin(PhysicsModel):
    name = "ModelPWHertzMindlin"
    kind = "PW"
    mdem_key = "906949ACFFAE4B8C8B1B65509930EA6D"
    default = True

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        return "hertz/mindlin"      # the fix's default law
