"""cmusen's generator jobs on a scene, as ``CScriptRunner`` runs them: the scene's stored
generator settings, the script's ``PACK_GEN_*`` / ``BOND_GEN_*`` / ``MIXTURE_PROPERTY`` lines
over them, the generation, the settings saved back (``SaveConfiguration``)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.generators import bonds, mesh, package
from fibrelmp.translate.musen.generators.scene import Scene, read_generator_scene
from fibrelmp.translate.musen.mdem.objects import LIQUID_BOND, SOLID_BOND, SPHERE, WALL

Say = Callable[[str], None]


def _apply_mixture_properties(scene: Scene, job) -> None:
    """``ApplyMaterialParameters``: MIXTURE_PROPERTY sets fractions that exist (1-based)."""
    mixtures = scene.modules.materials_database.mixture
    for imix, ifrac, compound, d, dc, share, _ in job.mixture_properties:
        if imix - 1 < len(mixtures) and ifrac - 1 < len(mixtures[imix - 1].fraction):
            f = mixtures[imix - 1].fraction[ifrac - 1]
            f.compoundKey, f.diameter, f.contact_diameter, f.fraction = compound, d, dc, share


def _package_settings(scene: Scene, job) -> list:
    """The generators with the script's settings over the stored ones (by 1-based index)."""
    from fibrelmp.translate.musen.mdem.text_export import volumes

    gens = scene.modules.package_generator.generators
    by_name = {v["name"]: v["key"] for v in volumes(scene.info)}
    mix_by_name = {m.mixtureName: m.uniqueKey for m in scene.modules.materials_database.mixture}
    for index, values in sorted(job.package_generators.items()):
        while index > len(gens):                      # AddGenerator({}): SPackage's defaults
            g = gens.add()
            g.volume_name, g.volume_active, g.porosity = "Generator", True, 0.5
            g.max_overlap, g.max_iterations = 1e-7, 100000
        g = gens[index - 1]
        if "volume" in values:
            g.volume_key = by_name.get(values["volume"], values["volume"])
        if "mixture" in values:
            g.mixture_key = mix_by_name.get(values["mixture"], values["mixture"])
        for key, attr in (("porosity", "porosity"), ("overlap", "max_overlap")):
            if values.get(key):
                setattr(g, attr, values[key])
        if values.get("iterations"):
            g.max_iterations = int(values["iterations"])
        if "velocity" in values:
            g.init_velocity.x, g.init_velocity.y, g.init_velocity.z = values["velocity"]
        if "inside" in values:
            g.inside_geometry = values["inside"]
    return list(gens)


def run_package_generator(source: Path, job, say: Say, seed: int | None = None) -> Scene:
    """PACKAGE_GENERATOR on the ``.mdem`` ``source``: the scene with its spheres and bonds
    replaced by the generated spheres."""
    from fibrelmp.translate.musen.mdem.text_export import volumes

    scene = read_generator_scene(source)
    _apply_mixture_properties(scene, job)
    if job.contact_radius is not None:
        scene.info.contact_radius = job.contact_radius
    if scene.info.periodic_conditions_enabled or (job.pbc_flags and any(job.pbc_flags)):
        raise InputError(job.path, job.where("COMPONENT"), "PACKAGE_GENERATOR with periodic "
                         "boundaries is not supported by fibrelmp")
    scene.remove((SPHERE, SOLID_BOND, LIQUID_BOND))   # DeleteAllParticles
    gens = _package_settings(scene, job)
    if not gens:
        raise InputError(job.path, job.where("COMPONENT"), f"{source.name}: no package "
                         "generators defined (give PACK_GEN_VOLUME and PACK_GEN_MIXTURE)")
    meshes = {v["key"]: (np.array(v["triangles"], float).reshape(-1, 3, 3), v) for v in volumes(scene.info)}
    rng = np.random.default_rng(seed)
    for k, g in enumerate(gens):
        if g.volume_active:
            _generate(scene, g, k, meshes, job, rng, say)
    return scene


def _generate(scene: Scene, g, k: int, meshes: dict, job, rng, say: Say) -> package.PackResult:
    where = f"{job.path}:{job.where('COMPONENT')}: package generator {k + 1} ({g.volume_name})"
    if g.volume_key not in meshes:
        raise InputError(job.path, job.where("COMPONENT"), f"package generator {k + 1} "
                         f"({g.volume_name}): generation volume {g.volume_key!r} not in the scene")
    if not g.inside_geometry and (scene.objects().types == WALL).any():
        raise InputError(job.path, job.where("COMPONENT"), f"package generator {k + 1}: "
                         "packing around the scene's geometries (PACK_GEN_INSIDE 0 with walls "
                         "in the scene) is not supported by fibrelmp; remove the geometries or "
                         "give PACK_GEN_INSIDE 1 YES")
    fr = package.mixture_fractions(scene, g.mixture_key, where)
    tri, described = meshes[g.volume_key]
    normals = mesh.inward_normals(tri)
    vol = volume_to_fill(described["shape"], described["sizes"], tri)
    largest = float(fr.contact.max())
    if 0.95 * max_inscribed_diameter(described["shape"], described["sizes"], vol) < largest:
        raise InputError(job.path, job.where("COMPONENT"), f"package generator {k + 1} "
                         f"({g.volume_name}): particle diameter ({largest:g} m) is too large for "
                         "the generation volume (cmusen refuses it too)")
    counts = package.particles_per_fraction(fr, vol, g.porosity)
    contact = (fr.contact if scene.info.contact_radius else fr.diameter) / 2
    t0 = time.perf_counter()
    fixed_x, fixed_r = package.existing_spheres(scene, tri)
    try:
        x, frac = package.place(tri, normals, counts, contact, fixed_x, fixed_r, rng)
    except ValueError as exc:
        raise InputError(job.path, job.where("COMPONENT"), f"package generator {k + 1}: {exc}") from None
    n = len(x)
    allx = np.concatenate([x, fixed_x])
    rc = np.concatenate([contact[frac], fixed_r])
    reached, iterations = package.relax(
        allx, rc, n, tri, normals, g.max_overlap, g.max_iterations,
        lambda it, ov: say(f"  iteration {it}: reached overlap {ov:.6g} / {g.max_overlap:g}"))
    velocity = np.array([g.init_velocity.x, g.init_velocity.y, g.init_velocity.z])
    scene.add_spheres(allx[:n], fr.diameter[frac] / 2, rc[:n], [fr.compound[f] for f in frac],
                      np.tile(velocity, (n, 1)), package.random_quaternions(n, rng))
    solid = float((np.pi / 6 * fr.diameter[frac] ** 3).sum())
    result = package.PackResult(g.volume_name, n, [int((frac == f).sum()) for f in range(len(counts))],
                                1.0 - solid / vol, reached, iterations, time.perf_counter() - t0)
    say(f"  generator {k + 1}: {n} spheres, porosity {result.porosity:.6g}, largest overlap "
        f"{reached:.3g} m after {iterations} iterations ({result.seconds:.1f} s)")
    return result


def volume_to_fill(shape: int, sizes: list[float], tri: np.ndarray) -> float:
    """``CAnalysisVolume::Volume``: a shape's own volume (not its facetted mesh's), a mesh's
    for an STL volume."""
    w, d, h, r, ri = sizes
    own = {0: 4.0 * np.pi * r ** 3 / 3.0, 1: w * d * h, 2: np.pi * r * r * h,
           3: 4.0 * np.pi / 3.0 * (r ** 3 - ri ** 3)}
    return float(own[shape]) if shape in own else mesh.volume(tri)


def max_inscribed_diameter(shape: int, sizes: list[float], volume: float) -> float:
    """``CAnalysisVolume::MaxInscribedDiameter`` (MUSEN's own rule, radius for a sphere)."""
    w, d, h, r, ri = sizes
    own = {0: r, 3: r - ri, 2: min(r, h), 1: min(w, d, h)}
    return own.get(shape, (volume / np.pi * 3 / 4) ** (1 / 3) * 2)


def _bond_classes(scene: Scene, job) -> list[bonds.BondClass]:
    classes = bonds.classes_of(scene)
    by_name = {c.compoundName: c.uniqueKey for c in scene.modules.materials_database.compound}
    for index, values in sorted(job.bond_generators.items()):
        while index > len(classes):
            classes.append(bonds.BondClass())
        cls = classes[index - 1]
        if "material" in values:
            cls.compound = by_name.get(values["material"], values["material"])
        if "min" in values:
            cls.min_distance = values["min"]
        if "max" in values:
            cls.max_distance = values["max"]
        if values.get("diameter"):
            cls.diameter = values["diameter"]
        if "overlay" in values:
            cls.overlay = values["overlay"]
    return classes


def run_bonds_generator(source: Path, job, say: Say) -> Scene:
    """BONDS_GENERATOR on the ``.mdem`` ``source``: its bonds replaced by generated ones."""
    scene = read_generator_scene(source)
    if scene.info.periodic_conditions_enabled:
        raise InputError(job.path, job.where("COMPONENT"), "BONDS_GENERATOR with periodic "
                         "boundaries is not supported by fibrelmp")
    scene.remove((SOLID_BOND,))                      # DeleteAllBonds
    classes = _bond_classes(scene, job)
    if not classes:
        raise InputError(job.path, job.where("COMPONENT"), f"{source.name}: no bond classes "
                         "defined (give BOND_GEN_MATERIAL)")
    made = bonds.generate_bonds(scene, classes)
    bonds.save_classes(scene, classes)
    say(f"  bonds generated: {sum(made)}")
    return scene
