"""ModelPPJKR (and the base of ModelPPPopovJKR, pp_popov_jkr): MUSEN's adhesive
particle-particle contacts, Hertz-Mindlin with the elastic normal force replaced by JKR's (the materials' surface energy, MUSEN property
11) or Popov's JKR fit (the materials' surface TENSION, property 13, as MUSEN's code reads).
Only with fibrelmp's ``pair_style musen/pp jkr GAMMA`` / ``popov/jkr SIGMA``
(src/musen_pp_jkr.cpp).  The law takes one value, the equivalent sqrt(p1 p2) of the sphere
materials; a scene whose material pairs give different values is refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

SURFACE_ENERGY, SURFACE_TENSION = 11, 13      # MUSEN's PROPERTY_SURFACE_ENERGY / _TENSION ids
MATERIAL_VALUE = "fibrelmp:equivalent_material_value"   # not MUSEN's: with_scene's, never stored


def sphere_material_keys(model: GranularModel) -> set[str]:
    """The keys of the materials spheres are (or will be, through inlets) made of."""
    keys = {model.materials[int(m)].key for m in np.unique(model.spheres.material)}
    for inlet in getattr(model.plan, "inlets", None) or []:
        keys.update(fraction[0] for fraction in inlet.fractions)
    return keys


def wall_material_keys(model: GranularModel) -> set[str]:
    """The keys of the walls' materials (planes and triangles)."""
    walls = {int(p.material) for p in model.planes}
    if model.triangles is not None and model.triangles.count:
        walls |= {int(m) for m in np.unique(model.triangles.material)}
    return {model.materials[m].key for m in walls}


def equivalent_values(model: GranularModel, prop: int, kind: str = "PP") -> set[float]:
    """sqrt(p1 p2) of material property ``prop`` (CalculateInteractionProperty) over every
    pair of sphere materials (PP) or of a sphere and a wall material (PW)."""
    value = {m.key: m.props.get(prop, 0.0) for m in model.materials}
    spheres = [k for k in sorted(sphere_material_keys(model)) if k in value]
    others = spheres if kind == "PP" else [k for k in sorted(wall_material_keys(model)) if k in value]
    return {math.sqrt(value[a] * value[b]) for a in spheres for b in others}


class AdhesivePP(PhysicsModel):
    """A Hertz-Mindlin-shaped PP law with one equivalent material value (not registered)."""

    kind = "PP"
    material_property: int
    what: str              # the property, in messages
    law: str               # the law's name in musen/pp
    positive: bool         # the value must be > 0 (else >= 0)
    pairs = "sphere materials'"    # whose value it is, in messages

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)
        values = equivalent_values(model, cls.material_property, cls.kind)
        if len(values) > 1:
            raise InputError(path, line, f"{cls.name}: the {cls.pairs} {cls.what} "
                             f"(property {cls.material_property}) give different equivalent "
                             "values per material pair; fibrelmp's law takes one value, so it "
                             f"translates the model only for materials of equal {cls.what}")
        value = next(iter(values), 1.0)
        if not (math.isfinite(value) and (value > 0 if cls.positive else value >= 0)):
            bound = "> 0" if cls.positive else ">= 0"
            raise InputError(path, line, f"{cls.name}: the {cls.pairs} {cls.what} must be "
                             f"{bound} (got {value:g}; MUSEN's law would give an infinite or "
                             "nan force)")
        return params

    @classmethod
    def with_scene(cls, model: GranularModel, params: dict[str, float]) -> dict[str, float]:
        return {**params,
                MATERIAL_VALUE: next(iter(equivalent_values(model, cls.material_property, cls.kind)),
                                     1.0)}

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText(f"# MUSEN's {cls.name[7:]} particle-particle contact; pair_style: "
                           f"the equivalent {cls.what}; pair_coeff: E* G* e mu mu_r"),
                f"pair_style      musen/pp {cls.pp_law_words(params)}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return f"{cls.law} {float_text(params[MATERIAL_VALUE])}"

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        return f"{cls.law} {float_text(params[MATERIAL_VALUE])}"


@register
class PPJKR(AdhesivePP):
    name = "ModelPPJKR"
    mdem_key = "8AC39F3E9D054A548CEB9CD44ACFE751"
    needs_styles = "pair_style musen/pp jkr"
    material_property, what, law, positive = SURFACE_ENERGY, "surface energy [J/m2]", "jkr", False

