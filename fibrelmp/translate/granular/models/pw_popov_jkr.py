"""ModelPWPopovJKR: MUSEN's Popov-JKR particle-wall contact, Hertz-Mindlin with an adhesive
normal force from the sphere and wall materials' equivalent surface tension (property 13);
its tangential spring acts on the old tangential overlap (MUSEN's code, kept).  Only with fibrelmp's ``fix musen/wall/mesh ... law popov/jkr``
(src/musen_pw_jkr.cpp); sphere-wall material pairs giving different values are refused."""

from __future__ import annotations

from fibrelmp.translate.granular.models import register
from fibrelmp.translate.granular.models.pp_jkr import SURFACE_TENSION, AdhesivePP


@register
class PWPopovJKR(AdhesivePP):
    name = "ModelPWPopovJKR"
    kind = "PW"
    mdem_key = "5048D3D96D3843949F5B427DF9FCCEDF"
    needs_styles = "fix musen/wall/mesh law popov/jkr"
    pairs = "sphere and wall materials'"
    material_property, what, law, positive = (SURFACE_TENSION, "surface tension [N/m]",
                                              "popov/jkr", True)
