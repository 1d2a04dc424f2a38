"""BONDS_GENERATOR: MUSEN's bond generator (``Modules/BondsGenerator``, e0ff360), written anew.

For each active bond class, every pair of spheres whose surfaces are between the class's
minimum and maximum distance apart gets a solid bond of the class's compound: diameter
``min(d, 2 r1, 2 r2)``, initial length the surface distance plus both radii.  The pairs are
those ``CContactCalculator`` finds, spheres grown by half the maximum distance overlapping
(strictly); the distances are computed in MUSEN's order of operations, so lengths agree to
the last bit.  Without "overlay", a pair a bond already joins gets no second one.  Bonds are
listed by (left, right) id with left < right (cmusen's order follows its cell grid).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.generators.scene import Scene
from fibrelmp.translate.musen.mdem import timepoints
from fibrelmp.translate.musen.mdem.objects import SOLID_BOND, SPHERE


@dataclass
class BondClass:
    """``SBondClass`` (its defaults are MUSEN's)."""
    name: str = ""
    active: bool = True
    compound: str = ""
    min_distance: float = 0.0
    max_distance: float = 1e-3
    diameter: float = 5e-4
    overlay: bool = False
    compound_specific: bool = False
    partners1: tuple[str, ...] = ()
    partners2: tuple[str, ...] = ()


def bond_pairs(x: np.ndarray, r: np.ndarray, cls: BondClass) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(pairs (k, 2) of sphere rows, surface distances, overlaps of the grown spheres)."""
    from scipy.spatial import cKDTree

    grown = r + cls.max_distance / 2
    cand = cKDTree(x).query_pairs(2 * grown.max(), output_type="ndarray")
    cand = np.sort(cand, axis=1)
    i, j = cand[:, 0], cand[:, 1]
    d = x[j] - x[i]
    length = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
    overlap = grown[i] + grown[j] - length
    hit = overlap > 0
    surface = cls.max_distance - overlap
    keep = hit & (surface <= cls.max_distance) & (surface >= cls.min_distance)
    return cand[keep], surface[keep], overlap[keep]


def generate_bonds(scene: Scene, classes: list[BondClass]) -> list[int]:
    """Adds the bonds of every active class to ``scene``; the number made by each."""
    objs = scene.objects()
    sph = objs.types == SPHERE
    ids = objs.ids[sph]
    x = scene.values[ids][:, timepoints.columns("coord")]
    r = objs.radius[sph]
    compound = np.array(objs.compound, dtype=object)[sph]
    known = {c.uniqueKey for c in scene.modules.materials_database.compound}
    made = []
    for k, cls in enumerate(classes):
        if not cls.active:
            made.append(0)
            continue
        where = f"bond class {k + 1} ({cls.name or 'unnamed'})"
        if not cls.compound:
            raise InputError(scene.path, None, f"{where}: material not specified")
        if cls.compound not in known:
            raise InputError(scene.path, None, f"{where}: compound {cls.compound!r} is not in "
                             "the scene's materials")
        if cls.max_distance < cls.min_distance:
            raise InputError(scene.path, None, f"{where}: max distance is less than min distance")
        pairs, surface, _ = bond_pairs(x, r, cls)
        keep = np.ones(len(pairs), bool)
        if cls.compound_specific:
            c1, c2 = compound[pairs[:, 0]], compound[pairs[:, 1]]
            in1 = np.isin(c1, cls.partners1), np.isin(c2, cls.partners1)
            in2 = np.isin(c1, cls.partners2), np.isin(c2, cls.partners2)
            keep &= (in1[0] & in2[1]) | (in1[1] & in2[0])
        left, right = ids[pairs[:, 0]], ids[pairs[:, 1]]
        if not cls.overlay:
            keep &= ~_joined(scene, left, right)
        pairs, surface, left, right = pairs[keep], surface[keep], left[keep], right[keep]
        r1, r2 = r[pairs[:, 0]], r[pairs[:, 1]]
        diameter = np.minimum(np.minimum(cls.diameter, 2 * r1), 2 * r2)
        scene.add_bonds(left, right, diameter, surface + r1 + r2, cls.compound)
        made.append(len(left))
    return made


def _joined(scene: Scene, left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Whether a solid bond of the scene already joins each pair."""
    objs = scene.objects()
    b = objs.types == SOLID_BOND
    have = {(min(a, c), max(a, c)) for a, c in zip(objs.left[b].tolist(), objs.right[b].tolist())}
    return np.array([(min(a, c), max(a, c)) in have for a, c in zip(left.tolist(), right.tolist())],
                    bool)


def classes_of(scene: Scene) -> list[BondClass]:
    """The bond classes stored in the scene (``LoadConfiguration``)."""
    return [BondClass(g.name, g.activity, g.material_key, g.min_length, g.max_length, g.property1,
                      g.allow_overlap, g.compound_specific, tuple(g.partner_compounds1),
                      tuple(g.partner_compounds2))
            for g in scene.modules.bonds_generator.generators]


def save_classes(scene: Scene, classes: list[BondClass]) -> None:
    """``SaveConfiguration``: the classes as used, back into the scene."""
    gens = scene.modules.bonds_generator.generators
    del gens[:]
    for cls in classes:
        g = gens.add()
        g.name, g.material_key, g.min_length, g.max_length = (cls.name, cls.compound,
                                                              cls.min_distance, cls.max_distance)
        g.property1, g.allow_overlap, g.compound_specific = cls.diameter, cls.overlay, cls.compound_specific
        g.partner_compounds1.extend(cls.partners1)
        g.partner_compounds2.extend(cls.partners2)
        g.activity = cls.active
