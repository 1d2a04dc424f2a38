"""Apply a SIMULATOR job of a cmusen script (``script_parse.MusenJob``) to a GranularModel:
materials, scene (domain, PBC, bonds, motion), models and times, in cmusen's order
(``apply_simulator_settings``), with MUSEN's defaults where the job and the scene say nothing.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from pathlib import Path

import numpy as np

from fibrelmp import lammps_styles
from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, GranularPlan, ModelChoice
from fibrelmp.translate.musen.scene import (INTERACTION_DEFAULTS, _check_material, check_simulable, contact_law,
                    domain_warning)
from fibrelmp.translate.granular import models as physics
from fibrelmp.translate.musen.scene_record import scene_record
from fibrelmp.translate.musen.script_parse import MUSEN_MODELS, REFUSED_MODEL, MusenJob, model_kind

MUSEN_DEFAULTS = {"dt": 1e-6, "save": 1e-3, "t_end": 1.0, "gravity": (0.0, 0.0, -9.81)}


def _resolve_models(model: GranularModel, job: MusenJob) -> tuple[dict[str, ModelChoice],
                                                                  list[ModelChoice]]:
    """The models a SIMULATOR job runs, merged as cmusen merges them (ConsoleSimulator: the
    file's models as loaded, then ``AddActiveModel`` for each of the job's: a model already
    active keeps its place and takes the job's parameters on top of the file's).  Every
    active model acts (CPUSimulator runs all models of a kind, in turn): the first of each
    kind, and the later ones (in order), which act after it (``_first_and_later``)."""
    chosen: dict[str, ModelChoice] = dict(model.models)
    active: list[ModelChoice] = []
    by_name: dict[str, int] = {}
    for spec in scene_record(model).file_models:
        # a file may list a model twice (MUSEN loads both); a job's parameters go to the
        # first (CModelManager::SetModelParameters)
        by_name.setdefault(spec.name, len(active))
        active.append(_model_choice(model, spec, model.source, None))
    for spec in job.models:
        if spec.name.startswith(REFUSED_MODEL):    # check's stand-in for a model refused above
            continue
        if spec.name in by_name:
            stored = next(s for s in scene_record(model).file_models if s.name == spec.name)
            if spec.params.strip():                # SetParametersStr: "" changes nothing
                both = dataclasses.replace(spec, params=f"{stored.params} {spec.params}")
                active[by_name[spec.name]] = _model_choice(model, both, job.path, spec.line)
            continue
        by_name[spec.name] = len(active)
        active.append(_model_choice(model, spec, job.path, spec.line))
    first, later = _first_and_later(active, model.source)
    chosen.update(first)
    return chosen, later


_ACTS_ON = {"PP": "particle-particle contact", "PW": "particle-wall contact", "SB": "solid bond",
            "LB": "liquid bond", "EF": "particle"}
# kinds of which fibrelmp runs several models together, as cmusen does (each in turn on every
# contact, bond or particle: PP, PW and EF forces add, SB laws continue the bond's state)
SEVERAL_OF_A_KIND = ("PP", "PW", "SB", "EF")


def _chosen_at(choice: ModelChoice, source) -> str:
    return f"line {choice.line}" if choice.line is not None else f"stored in {Path(source).name}"


def _first_and_later(active: list[ModelChoice], source) -> tuple[dict[str, ModelChoice],
                                                                    list[ModelChoice]]:
    """The first active model of each kind, and the later ones of the kinds that act together
    (``SEVERAL_OF_A_KIND``), in cmusen's order.  Two of another kind (LB) are refused,
    named where the second was selected."""
    seen: dict[str, ModelChoice] = {}
    later: list[ModelChoice] = []
    for choice in active:
        first = seen.setdefault(choice.kind, choice)
        if first is choice:
            continue
        if choice.kind in SEVERAL_OF_A_KIND:
            later.append(choice)
            continue
        hint = ("remove one of the two MODEL_ lines" if first.line is not None else
                "a script cannot drop a file's model: remove it in MUSEN (models tab) and save "
                "the file, or drop this MODEL_ line to run the file's")
        raise InputError(choice.source, choice.line,
                         f"{choice.name} ({_chosen_at(choice, source)}) and {first.name} "
                         f"({_chosen_at(first, source)}) are both {choice.kind} models: cmusen "
                         f"runs every selected model, both acting on each "
                         f"{_ACTS_ON.get(choice.kind, 'object')} in turn; fibrelmp runs several "
                         f"models of a kind only for {', '.join(SEVERAL_OF_A_KIND)} and not two "
                         f"{physics.KIND_WORDS[choice.kind]} models together: {hint}")
    return seen, later


def _apply_later_contact_models(model: GranularModel, plan) -> None:
    """The later PP / PW models: checked as each model checks its parameters (at its MODEL_
    line), only with fibrelmp's LAMMPS styles (pair musen/hm's and fix musen/wall/mesh's law
    lists), and their contact durations joined to the first's for ``fibrelmp check``."""
    for kind in ("PP", "PW"):
        own_plans = []
        for choice in (c for c in model.later_models if c.kind == kind):
            styles = lammps_styles.plugin()
            if not styles.available:
                raise InputError(choice.source, choice.line, f"{choice.name} after "
                                 f"{model.models[kind].name}: several {kind} models acting "
                                 "together need fibrelmp's LAMMPS styles, which are not "
                                 f"available here ({styles.how})")
            # a law that keeps its own contact history (ModelPPHertz: the tangential force)
            alone = [m for m in (model.models[kind].name, choice.name)
                     if physics.find(m).acts_alone]
            if alone:
                raise InputError(choice.source, choice.line, f"{choice.name} after "
                                 f"{model.models[kind].name}: fibrelmp runs {alone[0]} only as "
                                 f"the only {kind} model (it keeps MUSEN's tangential force "
                                 "where the others keep the tangential overlap)")
            own = GranularPlan(dt=plan.dt, t_start=plan.t_start, t_end=plan.t_end)
            physics.find(choice.name).apply(own, choice.parameters, choice.source, choice.line)
            own_plans.append(own)
        if own_plans:
            physics.combine_contact_times(plan, kind, own_plans)


def _names(names: list[str]) -> str:
    """"A", "A and B", "A, B and C"."""
    return " and ".join(filter(None, [", ".join(names[:-1]), *names[-1:]]))


def accepted_models(kind: str) -> list[str]:
    """The MUSEN models of ``kind`` fibrelmp translates (with its LAMMPS styles, if any)."""
    return [m.name for m in physics.of_kind(kind)]


def _model_choice(model: GranularModel, spec, path, line: int | None) -> ModelChoice:
    """One model named at ``path``:``line`` (None: a .mdem's stored model), checked."""
    kind = model_kind(spec)
    where = "" if line is not None else "the file's model "
    known = [n for names in MUSEN_MODELS.values() for n in names]
    if spec.name not in known:
        near = difflib.get_close_matches(spec.name, known, n=1)
        raise InputError(path, line, f"unknown MUSEN model {where}{spec.name!r}"
                         + (f"; did you mean {near[0]}?" if near else ""))
    if spec.kind and spec.kind != kind:
        raise InputError(path, line, f"{spec.name} is a {kind} model, given as "
                         f"MODEL_{spec.kind}")
    found = physics.find(spec.name)
    if found is not None and found.needs_styles:
        styles = lammps_styles.plugin()
        if not styles.available:
            stock = physics.default_model(kind)
            raise InputError(path, line, f"{where}{spec.name} needs fibrelmp's LAMMPS styles "
                             f"({found.needs_styles}), which are not available here "
                             f"({styles.how}); stock LAMMPS has no such "
                             f"{physics.KIND_NOUNS[kind]}"
                             + (f", so fibrelmp translates {stock.name} only without them"
                                if stock is not None else ""))
    elif found is None:
        what = physics.KIND_WORDS[kind]
        plain = [m.name for m in physics.of_kind(kind) if not m.needs_styles]
        styled = [m.name for m in physics.of_kind(kind) if m.needs_styles]
        ok = _names(plain) + (", and with fibrelmp's LAMMPS styles " if plain and styled else
                              "with fibrelmp's LAMMPS styles " if styled else "") + _names(styled)
        raise InputError(path, line, f"{where}{spec.name}: this {what} model is not supported"
                         + (f"; fibrelmp translates {ok}" if ok
                            else f"; fibrelmp translates no {what} model")
                         + ("; name another in the job script (MODEL_" + kind + ")" if line is None else ""))
    params = found.read_parameters(spec.params, path, line, model)
    return ModelChoice(spec.name, kind, params, Path(path), line)


def apply_simulator_settings(model: GranularModel, job: MusenJob) -> None:
    """Fill ``model.plan`` (and materials, geometries, bonds) from a SIMULATOR job, in the
    order cmusen applies them: materials, scene (domain, PBC, bonds, motion), models, times."""
    if job.component != "SIMULATOR":
        raise InputError(job.path, job.where("COMPONENT"), f"job {job.index} is "
                         f"{job.component}, not a SIMULATOR job")
    for key, ln, why in job.refused:
        raise InputError(job.path, ln, f"{key}: {why}")
    check_simulable(model)
    for kind, msg in job.warnings:
        model.warn(kind, msg)
    plan = model.plan
    _apply_materials(model, job)
    if job.anisotropy:
        model.warn("musen-anisotropy", f"{job.path}:{job.where('ANISOTROPY')}: ANISOTROPY 1: "
                   "fibrelmp's spheres are isotropic")
    if job.anisotropy is not None:
        scene_record(model, keep=True).anisotropy = job.anisotropy
    if job.contact_radius is not None:
        scene_record(model, keep=True).contact_radius_flag = job.contact_radius
    if job.simulation_domain is not None:
        d = job.simulation_domain
        if any(d[j] >= d[j + 3] for j in range(3)):
            raise InputError(job.path, job.where("SIMULATION_DOMAIN"), "SIMULATION_DOMAIN: need "
                             "xmin ymin zmin xmax ymax zmax with each min < max")
        plan.domain = (np.array(d[:3]), np.array(d[3:]))
        model.warnings = [w for w in model.warnings if w[0] != "musen-outside-domain"]
        domain_warning(model)
    if job.pbc_flags is not None:
        plan.periodic = tuple(bool(f) for f in job.pbc_flags)
    if job.pbc_domain is not None:
        plan.periodic_box = (np.array(job.pbc_domain[:3]), np.array(job.pbc_domain[3:]))
    if job.reset_bonds:
        reset_bond_lengths(model)
    _apply_motion(model, job)
    models, later = _resolve_models(model, job)
    model.models = models
    _check_models(model, job, models)
    if "PP" in models:                            # the laws stand for the PP model chosen
        for law in model.contacts.values():
            law.model = models["PP"].name
    plan.external_fields = []         # the EF models' apply() add theirs, in cmusen's order
    for kind, choice in models.items():
        # a kind's parameter errors point at its PARAMS line (cmusen reads them there)
        physics.find(choice.name).apply(plan, choice.parameters, job.path,
                                        job.where(f"MODEL_{kind}_PARAMS"))
    plan.then_bond_laws = []
    for choice in later:                # in cmusen's order, after the first of their kind
        if choice.kind == "SB":
            physics.add_later_bond_law(plan, choice.name, choice.parameters, choice.source,
                                       choice.line)
        elif choice.kind == "EF":      # its fix after the first's (plan.external_fields)
            physics.find(choice.name).apply(plan, choice.parameters, choice.source, choice.line)
    model.later_models = [c for c in later if c.kind != "SB"]
    _apply_later_contact_models(model, plan)
    if job.connected_pp_contact is not None:
        plan.contacts_between_bonded = job.connected_pp_contact
    # MUSEN's contact-list schedule (ConsoleSimulator: a coefficient of 0 keeps the file's)
    if job.verlet_coef:
        plan.verlet_coeff = job.verlet_coef
    if job.verlet_auto is not None:
        plan.verlet_auto = job.verlet_auto
    _refuse_file_settings(model, job)
    if job.velocity_limit is not None:
        plan.velocity_limit = job.velocity_limit if job.velocity_limit > 0 else None
        if plan.velocity_limit is not None and not lammps_styles.plugin().available:
            raise InputError(job.path, job.where("LIMIT_PARTICLE_VELOCITY"), "LIMIT_PARTICLE_VELOCITY "
                             "needs fibrelmp's LAMMPS styles (fix musen/leapfrog vlimit)")
    _apply_times(model, job)
    if plan.variable_step is not None:
        from fibrelmp.translate.granular.schedule import variable_step_refusals

        why = variable_step_refusals(model, lammps_styles.plugin().available)
        if why is not None:
            if "VARIABLE_TIME_STEP" in job.lines:
                raise InputError(job.path, job.where("VARIABLE_TIME_STEP"), why)
            raise InputError(scene_record(model).mdem_source or model.source, None,
                             f"flexible_time_step: {why}")


def _apply_materials(model: GranularModel, job: MusenJob) -> None:
    keys = {m.key: i for i, m in enumerate(model.materials)}

    def index(key: str, ln: int) -> int:
        if key not in keys:
            names = {m.name: m.key for m in model.materials}
            hint = (f"; material {key!r} has key {names[key]}" if key in names else
                    f"; known keys: {', '.join(keys)}")
            raise InputError(job.path, ln, f"no material with key {key!r} in the scene "
                             f"(cmusen silently ignores the line){hint}")
        return keys[key]

    changed = False
    for pid, key, value, ln in job.material_properties:
        mat = model.materials[index(key, ln)]
        mat.props[pid] = value
        attr = {0: "density", 7: "youngs", 8: "normal_strength", 9: "shear_strength",
                10: "poisson"}.get(pid)
        if attr:
            setattr(mat, attr, value)
        _check_material(mat.key, mat.name, mat.props, job.path, ln)
        changed = True
    inter = scene_record(model, keep=True).interactions
    for pid, k1, k2, value, ln in job.interaction_properties:
        a, b = sorted((index(k1, ln), index(k2, ln)))
        inter.setdefault((a, b), dict(INTERACTION_DEFAULTS))[pid] = value
        changed = True
    if changed:
        sp = model.spheres
        density = np.array([m.density for m in model.materials])
        sp.mass = density[sp.material] * 4.0 / 3.0 * np.pi * sp.radius ** 3
        for (a, b) in list(model.contacts):
            props = inter.get((a, b), INTERACTION_DEFAULTS)
            model.contacts[(a, b)] = contact_law(model.materials[a], model.materials[b], props)


def reset_bond_lengths(model: GranularModel) -> None:
    """RESET_INITIAL_BOND_LENGTH: L0 = current centre distance (minimum image with PBC).
    MUSEN gives bonds with an inactive sphere length 0; those keep their L0 here."""
    b = model.bonds
    if b is None:
        return
    sp = model.spheres
    d = sp.position[b.pair[:, 1]] - sp.position[b.pair[:, 0]]
    plan = model.plan
    if any(plan.periodic) and plan.periodic_box is not None:
        size = plan.periodic_box[1] - plan.periodic_box[0]
        for k in range(3):
            if plan.periodic[k]:
                d[:, k] -= size[k] * np.round(d[:, k] / size[k])
    t = plan.t_start
    active = ((b.active_start <= t) & (b.active_end > t)
              & (sp.active_start[b.pair].max(axis=1) <= t) & (sp.active_end[b.pair].min(axis=1) > t))
    b.length0 = np.where(active, np.linalg.norm(d, axis=1), b.length0)


def _apply_motion(model: GranularModel, job: MusenJob) -> None:
    def geometry(name: str, ln: int):
        for g in model.geometries:
            if g.name == name:
                return g
        if name.isdigit() and int(name) < len(model.geometries):
            return model.geometries[int(name)]
        raise InputError(job.path, ln, f"no geometry {name!r} in the scene (known: "
                         f"{', '.join(g.name for g in model.geometries) or 'none'}); cmusen "
                         "silently ignores the line")

    cleared = set()
    for name, interval, ln in job.geometry_motion_time:
        g = geometry(name, ln)
        if id(g) not in cleared:
            g.motion, g.force_motion, g.motion_type = [], [], 1
            g.raw_lines = [r for r in g.raw_lines if not r.startswith("26")]
            cleared.add(id(g))
        g.motion.append(interval)
    # ConsoleSimulator: the force intervals replace the motion of the geometries they name
    cleared = set()
    for name, interval, ln in job.geometry_motion_force:
        g = geometry(name, ln)
        if id(g) not in cleared:
            g.motion, g.force_motion, g.motion_type = [], [], 2
            cleared.add(id(g))
        g.force_motion.append(interval)


# MUSEN's defaults (CBaseSimulator: m_partMoveLimit, m_timeStepFactor)
MUSEN_VARIABLE_STEP = (1e-8, 1.01)


def _refuse_file_settings(model: GranularModel, job: MusenJob) -> None:
    """A .mdem's settings fibrelmp cannot simulate (``MusenSceneRecord.refused``), unless the
    job switches them off as cmusen's ConsoleSimulator would (VARIABLE_TIME_STEP 0,
    STOP_CRITERION NONE)."""
    record = scene_record(model)
    if job.variable_time_step is not None:       # cmusen: the script's flag replaces the file's
        model.plan.variable_step = (MUSEN_VARIABLE_STEP if job.variable_time_step else None)
    if model.plan.variable_step is not None:
        move, factor = model.plan.variable_step
        model.plan.variable_step = (job.max_part_move or move, job.step_inc_factor or factor)
    if model.plan.variable_step is None:         # switched off: the file's values do not matter
        record.refused.pop("flexible_time_step", None)
    if job.stop_criteria:       # cmusen: the script's criteria replace the file's
        record.refused.pop("stop_criteria", None)
        model.plan.stop_broken_bonds = (job.stop_max_broken if "BROKEN_BONDS" in job.stop_criteria
                                        else None)
    for name, why in record.refused.items():
        raise InputError(record.mdem_source or model.source, None, f"{name}: {why}")


def _check_models(model: GranularModel, job: MusenJob, models: dict) -> None:
    """ConsoleSimulator::SimulationPrecheck, made strict where fibrelmp cannot follow."""
    if "PP" not in models:
        # the pair style still renders the stock law; the template leaves the pairs out
        model.plan.particle_contacts = False
        model.warn("musen-no-pp-model", f"{job.path}:{job.line}: job {job.index}: no "
                   "particle-particle model (MODEL_PP): spheres pass through each other, as "
                   "in cmusen (its warning: 'Particle-particle contact model is not specified')")
    if model.triangles is not None and model.triangles.count and "PW" not in models:
        raise InputError(job.path, job.line, f"job {job.index}: the scene has walls but no "
                         "MODEL_PW (cmusen: 'Particle-wall contact model is not specified')")
    if model.bonds is not None and model.bonds.count and "SB" not in models:
        raise InputError(job.path, job.line, f"job {job.index}: the scene has solid bonds but no "
                         "MODEL_SB (cmusen: 'Solid bond model is not specified')")


def _round2(value: float) -> float:
    """MixedFunctions.h RoundToDecimalPlaces(value, 2)."""
    factor = 10.0 ** (2 - math.ceil(math.log10(abs(value))))
    return round(value * factor) / factor


def recommended_time_step(model: GranularModel) -> float:
    """CSystemStructure::GetRecommendedTimeStep: 0.1 x the smallest Rayleigh step of spheres
    and bond oscillation step, at the start state."""
    sp = model.spheres
    mats = model.materials
    rho = np.array([m.density for m in mats])
    nu = np.array([m.poisson for m in mats])
    e = np.array([m.youngs for m in mats])
    steps = [10.0]
    if sp.count:
        k = sp.material
        steps.append(float(np.min(np.pi * sp.contact_radius * np.sqrt(2 * rho[k] * (1 + nu[k]) / e[k])
                                  / (0.1631 * nu[k] + 0.8766))))
    b = model.bonds
    if b is not None and b.count:
        t = model.plan.t_start
        d = sp.position[b.pair[:, 1]] - sp.position[b.pair[:, 0]]
        length = np.linalg.norm(d, axis=1)
        ok = ((b.active_start <= t) & (t <= b.active_end) & (length > 0)
              & (sp.active_start[b.pair].max(axis=1) <= t) & (sp.active_end[b.pair].min(axis=1) >= t))
        if ok.any():
            k = b.material[ok]
            area = np.pi * b.diameter[ok] ** 2 / 4
            kb = np.maximum(e[k] * area / length[ok], e[k] * area / (2 * length[ok] * (1 + nu[k])))
            mass = sp.mass[b.pair[ok]].min(axis=1)
            steps.append(float(np.min(2 * np.sqrt(mass / kb))))
    return min(steps) * 0.1


def _apply_times(model: GranularModel, job: MusenJob) -> None:
    plan = model.plan
    used = []
    rec = None
    if job.simulation_step_factor or job.saving_step_factor or job.end_time_factor:
        rec = recommended_time_step(model)
    for attr, factor, value, key in (("dt", job.simulation_step_factor, job.simulation_step, "dt"),
                                     ("save_every_time", job.saving_step_factor, job.saving_step,
                                      "save"),
                                     ("t_end", job.end_time_factor, job.end_time, "t_end")):
        if factor:
            setattr(plan, attr, _round2(factor * rec))
        elif value:
            setattr(plan, attr, value)
        else:
            current = getattr(plan, attr)
            if current is None or not math.isfinite(current):
                setattr(plan, attr, MUSEN_DEFAULTS[key])
                used.append(f"{attr} {MUSEN_DEFAULTS[key]:g}")
    plan.save_every_steps = None
    if job.ext_accel is not None:
        plan.gravity = np.array(job.ext_accel, np.float64)
    elif not scene_record(model).gravity_set:
        plan.gravity = np.array(MUSEN_DEFAULTS["gravity"])
        used.append("gravity (0, 0, -9.81)")
    scene_record(model, keep=True).gravity_set = True
    if used:
        model.warn("musen-default-settings", f"{job.path}:{job.line}: job {job.index} does not "
                   f"set {', '.join(used)}: MUSEN's defaults for a freshly imported scene are used")
    if plan.t_end <= plan.t_start:
        raise InputError(job.path, job.where("END_TIME"), f"END_TIME {plan.t_end:g} s is not after "
                         f"the scene's start time {plan.t_start:g} s")
    if plan.dt > plan.t_end - plan.t_start:
        raise InputError(job.path, job.where("SIMULATION_STEP"), f"simulation step {plan.dt:g} s "
                         f"is longer than the run ({plan.t_end - plan.t_start:g} s)")
