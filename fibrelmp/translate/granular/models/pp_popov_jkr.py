"""ModelPPPopovJKR: MUSEN's Popov-JKR particle-particle contact, Hertz-Mindlin with Popov's fit
of the JKR force from the sphere materials' surface TENSION (property 13, as MUSEN's code
reads).  Only with fibrelmp's ``pair_style musen/pp popov/jkr SIGMA``; see ``pp_jkr``."""

from __future__ import annotations

from fibrelmp.translate.granular.models import register
from fibrelmp.translate.granular.models.pp_jkr import SURFACE_TENSION, AdhesivePP


@register
class PPPopovJKR(AdhesivePP):
    name = "ModelPPPopovJKR"
    mdem_key = "7A4C0DAF1F6D44AE925F4DD84563E36F"
    needs_styles = "pair_style musen/pp popov/jkr"
    material_property, what, law, positive = (SURFACE_TENSION, "surface tension [N/m]",
                                              "popov/jkr", True)
