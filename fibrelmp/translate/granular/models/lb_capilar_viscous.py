"""ModelLBCapilarViscous: MUSEN's capillary-viscous liquid bond (Mikami's law).  At MUSEN
commit e0ff360 (cmusen 1.74.2) its CalculateLB and ConsolidatePart bodies are commented out:
a liquid bond exerts no force and never breaks, and its result records hold times only
(tests/data/real-outputs/musen/models/lb_capilar_viscous).  fibrelmp reproduces that: the
model adds nothing to the LAMMPS run, with a warning that its law is a no-op."""

from __future__ import annotations

import math
from pathlib import Path

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.translate.granular.models import PhysicsModel, register

NO_OP = ("its law is a no-op at MUSEN commit e0ff360 (cmusen 1.74.2: CalculateLB and "
         "ConsolidatePart are commented out): liquid bonds exert no force and never break, "
         "in cmusen and in fibrelmp")


@register
class LBCapilarViscous(PhysicsModel):
    name = "ModelLBCapilarViscous"
    kind = "LB"
    mdem_key = "2A1C321B41ED44138C826EE8322441E5"
    parameters = {"MIN_THICKNESS": 1e-5, "CONTACT_ANGLE": 70.0}

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)
        at = f"{path}:{line}" if line is not None else f"{path} (its model manager)"
        model.warn("musen-liquid-bond-no-op", f"{at}: {cls.name}: {NO_OP}")
        return params

    @classmethod
    def apply(cls, plan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        # MUSEN does not use them either; a value that is not a number is refused as for
        # every model, so a job that runs here also runs in a cmusen with the law restored
        for key in cls.parameters:
            if not math.isfinite(params[key]):
                raise InputError(path, line, f"{cls.name} parameter {key} must be finite "
                                 f"(got {params[key]:g})")
