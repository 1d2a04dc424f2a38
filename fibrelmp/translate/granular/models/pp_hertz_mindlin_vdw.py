"""ModelPPHertzMindlinVdW: MUSEN's Hertz-Mindlin particle-particle contact plus a van der Waals
attraction from the materials' surface energy (MUSEN property 11).  Only with fibrelmp's
``pair_style musen/vdw`` (src/musen_pp_hertz_mindlin_vdw.cpp).

Range: cmusen evaluates a PP model only for a collision, i.e. while the centre distance is
below the sum of the two *contact* radii (CollisionsCalculator.cpp CheckPPCollision; the
Verlet list only pre-selects candidates), and the law measures the surface distance with the
radii.  LAMMPS holds one radius (the contact radius) and pair musen/hm applies the same test,
so the range is MUSEN's exactly when contact radius = radius; other scenes are refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.lammps_text import LammpsText
from fibrelmp.translate.granular.models import PhysicsModel, register
from fibrelmp.translate.lammps_format import float_text

SURFACE_ENERGY = 11                      # MUSEN's PROPERTY_SURFACE_ENERGY id
GAMMA = "fibrelmp:equivalent_surface_energy"   # not MUSEN's: added by with_scene, never stored


def sphere_material_keys(model: GranularModel) -> list[str]:
    """The keys of the materials spheres are (or will be, through dynamic generators) made of."""
    keys = {model.materials[int(m)].key for m in np.unique(model.spheres.material)}
    for inlet in getattr(model.plan, "inlets", None) or []:
        keys.update(fraction[0] for fraction in inlet.fractions)
    return sorted(keys)


def equivalent_surface_energies(model: GranularModel) -> set[float]:
    """sqrt(gamma1 gamma2) of every pair of sphere materials (CalculateInteractionProperty)."""
    gamma = {m.key: m.props.get(SURFACE_ENERGY, 0.0) for m in model.materials}
    keys = [k for k in sphere_material_keys(model) if k in gamma]
    return {math.sqrt(gamma[a] * gamma[b]) for a in keys for b in keys}


def check_one_radius(model: GranularModel, name: str, path: Path | str | None,
                     line: int | None) -> None:
    """Refuse a scene whose spheres' contact radius differs from their radius: MUSEN's law then
    needs both (its range is the contact radii, its distances the radii); LAMMPS has one."""
    s = model.spheres
    if len(s.radius) and not np.array_equal(s.radius, s.contact_radius):
        raise InputError(path, line, f"{name} acts between the contact radii with distances "
                         "measured from the radii; LAMMPS holds one radius per sphere, so fibrelmp "
                         "translates it only for spheres whose contact radius equals their radius")


def one_surface_energy(model: GranularModel, name: str, path: Path | str | None,
                       line: int | None) -> float:
    """The sphere materials' one equivalent surface energy sqrt(gamma1 gamma2); refused when
    material pairs differ (the law takes one value)."""
    energies = equivalent_surface_energies(model)
    if len(energies) > 1:
        raise InputError(path, line, f"{name}: the sphere materials' surface energies (property "
                         f"{SURFACE_ENERGY}) give different equivalent energies per material "
                         "pair; fibrelmp's law takes one value, so it translates the model only "
                         "for sphere materials of equal surface energy")
    gamma = next(iter(energies), 0.0)
    if not (gamma >= 0 and math.isfinite(gamma)):
        raise InputError(path, line, f"{name}: the sphere materials' surface energy must be "
                         f">= 0 in J/m2 (got {gamma:g})")
    return gamma


class SurfaceEnergyModel(PhysicsModel):
    """What the PP laws of the sphere materials' surface energy share (ModelPPHertzMindlinVdW,
    ModelPPSintering, ModelPPSinteringTemperature; not a MUSEN model itself: unregistered):
    spheres whose contact radius is their radius, one equivalent surface energy, which
    ``with_scene`` adds to the parameters as GAMMA."""

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        params = super().read_parameters(text, path, line, model)
        check_one_radius(model, cls.name, path, line)
        one_surface_energy(model, cls.name, path, line)
        return params

    @classmethod
    def with_scene(cls, model: GranularModel, params: dict[str, float]) -> dict[str, float]:
        return {**params, GAMMA: next(iter(equivalent_surface_energies(model)), 0.0)}


@register
class PPHertzMindlinVdW(SurfaceEnergyModel):
    name = "ModelPPHertzMindlinVdW"
    kind = "PP"
    mdem_key = "B18A46C2786D4D44B925A8V04D0D1008"
    needs_styles = "pair_style musen/vdw"
    raw_coordinate_distance = True

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        if not own_styles:
            raise RuntimeError(f"{cls.name} needs fibrelmp's LAMMPS styles (checked earlier)")
        return [LammpsText("# MUSEN's Hertz-Mindlin contact with van der Waals attraction; "
                           "pair_style: the equivalent surface energy [J/m2]; pair_coeff: "
                           "E* G* e mu mu_r"),
                f"pair_style      musen/vdw {float_text(params[GAMMA])}"]

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        return f"hertz/mindlin/vdw {float_text(params[GAMMA])}"
