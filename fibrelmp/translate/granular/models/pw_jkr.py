"""ModelPWJKR: MUSEN's JKR particle-wall contact, Hertz-Mindlin with an adhesive
normal force from the sphere and wall materials' equivalent surface energy (property 11);
MUSEN scales only the adhesive term by |rc_n . n| (kept).  Only with fibrelmp's ``fix musen/wall/mesh ... law jkr``
(src/musen_pw_jkr.cpp); sphere-wall material pairs giving different values are refused."""

from __future__ import annotations

from fibrelmp.translate.granular.models import register
from fibrelmp.translate.granular.models.pp_jkr import SURFACE_ENERGY, AdhesivePP


@register
class PWJKR(AdhesivePP):
    name = "ModelPWJKR"
    kind = "PW"
    mdem_key = "470A5893541D4204A7F1F2C993C667FB"
    needs_styles = "fix musen/wall/mesh law jkr"
    pairs = "sphere and wall materials'"
    material_property, what, law, positive = (SURFACE_ENERGY, "surface energy [J/m2]",
                                              "jkr", False)
