"""Parse cmusen job scripts and apply a SIMULATOR job's settings to a GranularModel.

Syntax follows MUSEN's ``ScriptAnalyzer.cpp`` (e0ff360): one ``KEYWORD values`` per line,
keywords case-insensitive, ``JOB``/``NEW_JOB`` starts a job.  Keywords before the first JOB
form job 1 of their own (cmusen pushes a job for them); they do NOT apply to later jobs.
Where cmusen prints "Unknown script key" and carries on, or silently keeps a default on a
bad value, fibrelmp stops with ``path:line:`` and a did-you-mean.  docs/musen.md lists which
keywords are honoured, ignored (named warning) or refused.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, MotionInterval
from fibrelmp.translate.musen.writer import EXPORT_FLAGS, all_on
from fibrelmp.textio import read_text
from fibrelmp.translate.musen.scene import (INTERACTION_DEFAULTS, _check_material, check_simulable, contact_law,
                    domain_warning)

COMPONENTS = {"SIMULATOR": "SIMULATOR", "IMPORT_FROM_TEXT": "IMPORT_FROM_TEXT",
              "EXPORT_TO_TEXT": "EXPORT_TO_TEXT"}
OTHER_COMPONENTS = ("PACKAGE_GENERATOR", "RESULTS_ANALYZER", "BONDS_GENERATOR",
                    "SNAPSHOT_GENERATOR", "COMPARE_FILES")
_COMPONENT_NUMBERS = ["PACKAGE_GENERATOR", "RESULTS_ANALYZER", "BONDS_GENERATOR", "SIMULATOR",
                      "SNAPSHOT_GENERATOR", "EXPORT_TO_TEXT", "IMPORT_FROM_TEXT", "COMPARE_FILES"]
MATERIAL_PROPERTIES = {"DENSITY": 0, "HEAT_CAPACITY": 1, "DYNAMIC_VISCOSITY": 2,
                       "THERMAL_CONDUCTIVITY": 3, "YOUNG_MODULUS": 7, "NORMAL_STRENGTH": 8,
                       "TANGENTIAL_STRENGTH": 9, "POISSON_RATIO": 10, "SURFACE_ENERGY": 11,
                       "ATOMIC_VOLUME": 12, "SURFACE_TENSION": 13, "TIME_THERM_EXP_COEFF": 14,
                       "YIELD_STRENGTH": 15}
INTERACTION_PROPERTIES = {"RESTITUTION_COEFFICIENT": 200, "SLIDING_FRICTION": 201,
                          "ROLLING_FRICTION": 202}
SUPPORTED_MODELS = {"PP": "ModelPPHertzMindlin", "PW": "ModelPWHertzMindlin", "SB": "ModelSBElastic"}
MUSEN_MODELS = {  # every model in MUSEN's Models/ folder, by kind
    "PP": ("ModelPPChealNess", "ModelPPHeatConduction", "ModelPPHertz", "ModelPPHertzMindlin",
           "ModelPPHertzMindlinLiquid", "ModelPPHertzMindlinVdW", "ModelPPJKR",
           "ModelPPLinearElastic", "ModelPPPopovJKR", "ModelPPSimpleViscoElastic",
           "ModelPPSinteringTemperature", "ModelPPSintering"),
    "PW": ("ModelPWHeatTransfer", "ModelPWHertzMindlin", "ModelPWHertzMindlinLiquid",
           "ModelPWJKR", "ModelPWPopovJKR", "ModelPWSimpleViscoElastic"),
    "SB": ("ModelSBAerogel", "ModelSBCreep", "ModelSBElastic", "ModelSBElasticPerfectlyPlastic",
           "ModelSBHeatConduction", "ModelSBKelvin", "ModelSBLinearPlastic",
           "ModelSBPlasticConcrete", "ModelSBThermal", "ModelSBWeakening"),
    "LB": ("ModelLBCapilarViscous",),
    "EF": ("ModelEFCentrifugalCasting", "ModelEFHeatTransfer", "ModelEFLiquidDiffusion",
           "ModelEFViscousField"),
}
MODEL_PARAMETERS = {"ModelSBElastic": {"CONSIDER_BREAKAGE": 1.0}}   # AddParameter(...) defaults
MUSEN_DEFAULTS = {"dt": 1e-6, "save": 1e-3, "t_end": 1.0, "gravity": (0.0, 0.0, -9.81)}
_EXPORT_KEYS = {"TEXT_EXPORT_OBJECTS": "objectTypes", "TEXT_EXPORT_CONST": "constProps",
                "TEXT_EXPORT_TD_PART": "tdPropsPart", "TEXT_EXPORT_TD_BOND": "tdPropsBond",
                "TEXT_EXPORT_TD_WALL": "tdPropsWall", "TEXT_EXPORT_SCENE": "sceneInfo",
                "TEXT_EXPORT_GEOMETRIES": "geometries", "TEXT_EXPORT_MATERIALS": "materials",
                "TEXT_EXPORT_GENERATORS": "generators"}
# keywords cmusen reads that cannot change a fibrelmp run (named warning, then ignored)
_IGNORED = {
    "LOG_FILE": "fibrelmp prints its log to the terminal",
    "VERLET_AUTO": "neighbour lists are LAMMPS's", "VERLET_COEF": "neighbour lists are LAMMPS's",
    "VERLET_MAX_CELLS": "neighbour lists are LAMMPS's",
    "SAVE_COLLISIONS": "collisions are not saved", "MONITOR": "monitors are not supported",
    "POSTPROCESS": "post-processing commands are not supported",
    "SELECTIVE_SAVING_P": "every field is saved", "SELECTIVE_SAVING_SB": "every field is saved",
    "SELECTIVE_SAVING_LB": "every field is saved", "SELECTIVE_SAVING_TW": "every field is saved",
    "MAX_PART_MOVE": "only for a variable time step", "STEP_INC_FACTOR": "only for a variable time step",
}
# keywords only the generator / analyser / snapshot components read: accepted, no effect
_OTHER_COMPONENT_KEYS = ("AGGLOMERATES_DB", "SNAPSHOT_TIME", "MIXTURE_PROPERTY", "PACK_GEN_VOLUME",
                         "PACK_GEN_MIXTURE", "PACK_GEN_POROSITY", "PACK_GEN_OVERLAP",
                         "PACK_GEN_ITERATIONS", "PACK_GEN_VELOCITY", "PACK_GEN_INSIDE",
                         "BOND_GEN_MATERIAL", "BOND_GEN_MINDIST", "BOND_GEN_MAXDIST",
                         "BOND_GEN_DIAMETER", "BOND_GEN_OVERLAY")


@dataclass
class MusenModelSpec:
    name: str
    params: str
    kind: str          # PP PW SB LB EF, or "" for the generic MODEL keyword
    line: int


@dataclass
class MusenJob:
    """One cmusen job.  Numbers left at 0 / None were not given (cmusen keeps what the
    loaded .mdem has, or its defaults)."""

    path: Path
    index: int
    line: int
    source_file: str | None = None
    result_file: str | None = None
    component: str = "SIMULATOR"            # cmusen's default component
    simulator_type: str | None = None
    models: list[MusenModelSpec] = field(default_factory=list)
    simulation_step: float = 0.0
    saving_step: float = 0.0
    end_time: float = 0.0
    simulation_step_factor: float = 0.0
    saving_step_factor: float = 0.0
    end_time_factor: float = 0.0
    ext_accel: tuple[float, float, float] | None = None
    simulation_domain: tuple[float, ...] | None = None
    pbc_flags: tuple[bool | None, bool | None, bool | None] | None = None
    pbc_domain: tuple[float, ...] | None = None
    connected_pp_contact: bool | None = None
    anisotropy: bool | None = None
    contact_radius: bool | None = None
    reset_bonds: bool | None = None
    variable_time_step: bool | None = None
    material_properties: list[tuple[int, str, float, int]] = field(default_factory=list)
    interaction_properties: list[tuple[int, str, str, float, int]] = field(default_factory=list)
    geometry_motion_time: list[tuple[str, MotionInterval, int]] = field(default_factory=list)
    geometry_motion_force: list[tuple[str, int]] = field(default_factory=list)
    text_export: dict[str, dict[str, bool]] = field(default_factory=all_on)
    precision: int = 6
    time_interval: tuple[float, float] | None = None
    refused: list[tuple[str, int, str]] = field(default_factory=list)   # (keyword, line, why)
    warnings: list[tuple[str, str]] = field(default_factory=list)
    lines: dict[str, int] = field(default_factory=dict)                  # keyword -> last line

    def where(self, keyword: str) -> int:
        return self.lines.get(keyword, self.line)


def _tristate(token: str | None) -> bool | None:
    """CTriState: 1/yes/true, 0/no/false, anything else undefined."""
    if token is None:
        return None
    low = token.lower()
    if token == "1" or low in ("yes", "true"):
        return True
    if token == "0" or low in ("no", "false"):
        return False
    return None


class _Line:
    def __init__(self, path: Path, ln: int, key: str, rest: str):
        self.path, self.ln, self.key, self.rest = path, ln, key, rest
        self.tok = rest.split()

    def error(self, msg: str) -> InputError:
        return InputError(self.path, self.ln, f"{self.key}: {msg}")

    def floats(self, n: int, positive: bool = False) -> tuple[float, ...]:
        if len(self.tok) < n:
            raise self.error(f"needs {n} number(s), got {len(self.tok)}")
        out = []
        for t in self.tok[:n]:
            try:
                v = float(t)
            except ValueError:
                raise self.error(f"expected a number, got {t!r}") from None
            if not math.isfinite(v) or (positive and v <= 0):
                raise self.error(f"expected a {'positive ' if positive else ''}finite number, "
                                 f"got {t!r}")
            out.append(v)
        return tuple(out)

    def flag(self) -> bool:
        value = _tristate(self.tok[0] if self.tok else None)
        if value is None:
            raise self.error("expected 1/0 (or yes/no, true/false)")
        return value

    def text(self) -> str:
        if not self.rest:
            raise self.error("needs a value")
        return self.rest


def read_script(path: str | Path) -> list[MusenJob]:
    """All jobs of a cmusen script, in order."""
    path = Path(path)
    text = read_text(path, "cmusen job script")
    jobs: list[MusenJob] = []
    for ln, raw in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), 1):
        parts = raw.strip().split(None, 1)
        if not parts or parts[0].startswith(("#", "//")):
            continue                     # cmusen: "Unknown script key" and carries on
        key = parts[0].upper()
        line = _Line(path, ln, key, parts[1].strip() if len(parts) > 1 else "")
        if key in ("JOB", "NEW_JOB"):
            jobs.append(MusenJob(path=path, index=len(jobs) + 1, line=ln))
            continue
        if not jobs:                    # ScriptAnalyzer: force a first job
            jobs.append(MusenJob(path=path, index=1, line=ln))
        _keyword(jobs[-1], line)
    if not jobs:
        raise InputError(path, None, "empty cmusen job script (no JOB or keyword lines)")
    return jobs


read = read_script


def _known_keys() -> list[str]:
    return sorted(set(_HANDLERS) | set(_IGNORED) | set(_OTHER_COMPONENT_KEYS) | set(_EXPORT_KEYS)
                  | {"JOB", "NEW_JOB"})


def _keyword(job: MusenJob, line: _Line) -> None:
    key = line.key
    job.lines[key] = line.ln
    if key in _HANDLERS:
        _HANDLERS[key](job, line)
    elif key in _EXPORT_KEYS:
        group = _EXPORT_KEYS[key]
        flags = EXPORT_FLAGS[group]
        for j, name in enumerate(flags):
            token = line.tok[j] if j < len(line.tok) else None
            value = _tristate(token)
            if token is not None and value is None:
                raise line.error(f"flag {j + 1} ({name}): expected 1/0, got {token!r}")
            job.text_export[group][name] = True if value is None else value   # ToBool(true)
    elif key in _IGNORED:
        job.warnings.append(("musen-ignored-keyword", f"{line.path}:{line.ln}: {key} ignored "
                             f"({_IGNORED[key]})"))
    elif key in _OTHER_COMPONENT_KEYS:
        pass                            # read by components fibrelmp refuses; no effect here
    else:
        near = difflib.get_close_matches(key, _known_keys(), n=1, cutoff=0.6)
        hint = f"; did you mean {near[0]}?" if near else ""
        raise InputError(line.path, line.ln, f"unknown cmusen keyword {key!r}{hint}")


def _component(job: MusenJob, line: _Line) -> None:
    value = line.tok[0].upper() if line.tok else ""
    if len(value) == 1 and value.isdigit():           # old numeric syntax
        value = _COMPONENT_NUMBERS[int(value)] if int(value) < len(_COMPONENT_NUMBERS) else value
    if value in COMPONENTS:
        job.component = COMPONENTS[value]
    elif value in OTHER_COMPONENTS:
        raise line.error(f"{value} is not supported by fibrelmp (only SIMULATOR, "
                         "IMPORT_FROM_TEXT and EXPORT_TO_TEXT)")
    else:
        near = difflib.get_close_matches(value, list(COMPONENTS) + list(OTHER_COMPONENTS), n=1)
        raise line.error(f"unknown component {value!r}" + (f"; did you mean {near[0]}?"
                                                           if near else ""))


def _simulator_type(job: MusenJob, line: _Line) -> None:
    value = line.text().upper()
    if value == "CPU":
        job.simulator_type = "CPU"
    elif value in ("GPU", "GPU_FAST", "GPU FAST", "GPUFAST"):
        job.simulator_type = "GPU"
    else:
        raise line.error(f"expected CPU or GPU, got {line.rest!r}")


def _model(kind: str):
    def handler(job: MusenJob, line: _Line) -> None:
        name = line.text()
        if not any(m.name == name for m in job.models):   # cmusen skips repeated names
            job.models.append(MusenModelSpec(name, "", kind, line.ln))
    return handler


def _model_params(kind: str):
    def handler(job: MusenJob, line: _Line) -> None:
        for m in job.models:
            if _kind_of(m) == kind:
                m.params = line.rest
                return
        raise line.error(f"no MODEL_{kind} line before it in this job (cmusen drops the "
                         "parameters then)")
    return handler


def _model_params_generic(job: MusenJob, line: _Line) -> None:
    name = line.tok[0] if line.tok else ""
    for m in job.models:
        if m.name == name:
            m.params = line.rest[len(name):].strip()
            return
    raise line.error(f"model {name!r} is not selected in this job (cmusen drops the parameters)")


def _number(attr: str, positive: bool = True):
    def handler(job: MusenJob, line: _Line) -> None:
        setattr(job, attr, line.floats(1, positive)[0])
    return handler


def _tuple(attr: str, n: int):
    def handler(job: MusenJob, line: _Line) -> None:
        setattr(job, attr, line.floats(n))
    return handler


def _flag(attr: str):
    def handler(job: MusenJob, line: _Line) -> None:
        setattr(job, attr, line.flag())
    return handler


def _refuse(why: str):
    """Keywords that would change the physics in a way fibrelmp cannot follow: stored and
    refused when a SIMULATOR job is applied (an export job ignores them, as cmusen does)."""
    def handler(job: MusenJob, line: _Line) -> None:
        job.refused.append((line.key, line.ln, why))
    return handler


def _variable_step(job: MusenJob, line: _Line) -> None:
    job.variable_time_step = line.flag()
    if job.variable_time_step:
        job.refused.append((line.key, line.ln, "a variable time step is not supported"))


def _stop(job: MusenJob, line: _Line) -> None:
    value = line.tok[0].upper() if line.tok else ""
    if value == "BROKEN_BONDS":
        job.refused.append((line.key, line.ln, "stopping on a number of broken bonds is not "
                            "supported; give END_TIME"))
    elif value != "NONE":
        raise line.error(f"expected NONE or BROKEN_BONDS, got {value!r}")


def _pbc_flags(job: MusenJob, line: _Line) -> None:
    flags = [_tristate(t) for t in line.tok[:3]] + [None] * (3 - len(line.tok[:3]))
    if None in flags:
        raise line.error("needs three flags 1/0 for X Y Z")
    job.pbc_flags = tuple(flags)


def _property_line(line: _Line, table: dict[str, int], what: str, usage: str,
                   nkeys: int) -> tuple[int, list[str], float]:
    """``NAME KEY... VALUE`` of a MATERIAL_PROPERTY / INTERACTION_PROPERTY line."""
    if len(line.tok) < nkeys + 2:
        raise line.error(f"needs {usage}")
    name = line.tok[0].upper()
    if name not in table:
        near = difflib.get_close_matches(name, list(table), n=1)
        raise line.error(f"unknown {what} property {name!r}"
                         + (f"; did you mean {near[0]}?" if near else ""))
    value = _Line(line.path, line.ln, line.key, line.tok[nkeys + 1]).floats(1)[0]
    return table[name], line.tok[1:nkeys + 1], value


def _material_property(job: MusenJob, line: _Line) -> None:
    pid, (key,), value = _property_line(line, MATERIAL_PROPERTIES, "material",
                                        "PROPERTY COMPOUND_KEY VALUE", 1)
    job.material_properties.append((pid, key, value, line.ln))


def _interaction_property(job: MusenJob, line: _Line) -> None:
    pid, (key1, key2), value = _property_line(line, INTERACTION_PROPERTIES, "interaction",
                                              "PROPERTY KEY1 KEY2 VALUE", 2)
    job.interaction_properties.append((pid, key1, key2, value, line.ln))


def _precision(job: MusenJob, line: _Line) -> None:
    value = line.floats(1)[0]
    if value != int(value) or not 1 <= value <= 40:
        raise line.error(f"expected an integer 1..40, got {line.tok[0]!r}")
    job.precision = int(value)


def _time_interval(job: MusenJob, line: _Line) -> None:
    beg, end = line.floats(2)
    job.time_interval = None if -1.0 in (beg, end) else (beg, end)   # -1: all, as cmusen


def _motion_time(job: MusenJob, line: _Line) -> None:
    if not line.tok:
        raise line.error("needs GEOMETRY tBeg tEnd vx vy vz wx wy wz cx cy cz")
    v = _Line(line.path, line.ln, line.key, " ".join(line.tok[1:])).floats(11)
    # script order: velocity, rotation velocity, rotation centre (the text file has v, c, w)
    job.geometry_motion_time.append((line.tok[0], MotionInterval(
        v[0], v[1], np.array(v[2:5]), np.array(v[8:11]), np.array(v[5:8])), line.ln))


def _motion_force(job: MusenJob, line: _Line) -> None:
    job.geometry_motion_force.append((line.tok[0] if line.tok else "", line.ln))


def _set(attr: str):
    def handler(job: MusenJob, line: _Line) -> None:
        setattr(job, attr, line.text())
    return handler


_HANDLERS = {
    "SOURCE_FILE": _set("source_file"), "RESULT_FILE": _set("result_file"),
    "RESULTS_FILE": _set("result_file"), "COMPONENT": _component,
    "SIMULATOR_TYPE": _simulator_type,
    "MODEL_PP": _model("PP"), "MODEL_PW": _model("PW"), "MODEL_SB": _model("SB"),
    "MODEL_LB": _model("LB"), "MODEL_EF": _model("EF"), "MODEL_EXT_FORCE": _model("EF"),
    "MODEL_PPHT": _model("PP"), "MODEL": _model(""),
    "MODEL_PP_PARAMS": _model_params("PP"), "MODEL_PW_PARAMS": _model_params("PW"),
    "MODEL_SB_PARAMS": _model_params("SB"), "MODEL_LB_PARAMS": _model_params("LB"),
    "MODEL_EF_PARAMS": _model_params("EF"), "MODEL_EXT_FORCE_PARAMS": _model_params("EF"),
    "MODEL_PPHT_PARAMS": _model_params("PP"), "MODEL_PARAMS": _model_params_generic,
    "SIMULATION_STEP": _number("simulation_step"), "SIMULATION_TSTEP": _number("simulation_step"),
    "SAVING_STEP": _number("saving_step"), "SAVING_TSTEP": _number("saving_step"),
    "END_TIME": _number("end_time"),
    "SIMULATION_STEP_FACTOR": _number("simulation_step_factor"),
    "SAVING_STEP_FACTOR": _number("saving_step_factor"),
    "END_TIME_FACTOR": _number("end_time_factor"),
    "CONNECTED_PP_CONTACT": _flag("connected_pp_contact"), "ANISOTROPY": _flag("anisotropy"),
    "DIFF_CONTACT_RADIUS": _flag("contact_radius"),
    "RESET_INITIAL_BOND_LENGTH": _flag("reset_bonds"),
    "EXT_ACCEL": _tuple("ext_accel", 3), "SIMULATION_DOMAIN": _tuple("simulation_domain", 6),
    "PBC_FLAGS": _pbc_flags, "PBC_DOMAIN": _tuple("pbc_domain", 6),
    "VARIABLE_TIME_STEP": _variable_step, "STOP_CRITERION": _stop,
    "LIMIT_PARTICLE_VELOCITY": _refuse("limiting particle velocities is not supported"),
    "MATERIAL_PROPERTY": _material_property, "INTERACTION_PROPERTY": _interaction_property,
    "TEXT_EXPORT_PRECISION": _precision, "TIME_INTERVAL": _time_interval,
    "GEOMETRY_MOTION_TIME": _motion_time, "GEOMETRY_MOTION_FORCE": _motion_force,
}


# --------------------------------------------------------------------------- applying

def _kind_of(spec: MusenModelSpec) -> str:
    for kind, names in MUSEN_MODELS.items():
        if spec.name in names:
            return kind
    return spec.kind


def _resolve_models(model: GranularModel, job: MusenJob) -> dict[str, tuple[str, dict]]:
    chosen: dict[str, tuple[str, dict]] = dict(model.passthrough.get("musen_models", {}))
    for spec in job.models:
        kind = _kind_of(spec)
        known = [n for names in MUSEN_MODELS.values() for n in names]
        if spec.name not in known:
            near = difflib.get_close_matches(spec.name, known, n=1)
            raise InputError(job.path, spec.line, f"unknown MUSEN model {spec.name!r}"
                             + (f"; did you mean {near[0]}?" if near else ""))
        if spec.kind and spec.kind != kind:
            raise InputError(job.path, spec.line, f"{spec.name} is a {kind} model, given as "
                             f"MODEL_{spec.kind}")
        if SUPPORTED_MODELS.get(kind) != spec.name:
            what = {"PP": "particle-particle", "PW": "particle-wall", "SB": "solid-bond",
                    "LB": "liquid-bond", "EF": "external-force"}[kind]
            ok = SUPPORTED_MODELS.get(kind)
            raise InputError(job.path, spec.line, f"{spec.name}: this {what} model is not "
                             "supported" + (f"; fibrelmp translates {ok} only" if ok else ""))
        params = dict(MODEL_PARAMETERS.get(spec.name, {}))
        tok = spec.params.split()
        for j in range(0, len(tok), 2):
            name = tok[j]
            if name not in params:
                model.warn("musen-unknown-model-parameter", f"{job.path}:{spec.line}: "
                           f"{spec.name} has no parameter {name}; ignored as MUSEN does")
                continue
            try:
                params[name] = float(tok[j + 1])
            except (IndexError, ValueError):
                raise InputError(job.path, spec.line, f"{spec.name} parameter {name}: expected "
                                 "a number") from None
        chosen[kind] = (spec.name, params)
    return chosen


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
        model.passthrough["anisotropy"] = job.anisotropy
    if job.contact_radius is not None:
        model.passthrough["contact_radius_flag"] = job.contact_radius
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
    models = _resolve_models(model, job)
    model.passthrough["musen_models"] = models
    _check_models(model, job, models)
    if "SB" in models:
        plan.bond_breakage = int(models["SB"][1]["CONSIDER_BREAKAGE"])
        if plan.bond_breakage not in (0, 1, 2):
            raise InputError(job.path, job.where("MODEL_SB_PARAMS"), "CONSIDER_BREAKAGE must be "
                             f"0, 1 or 2 (got {models['SB'][1]['CONSIDER_BREAKAGE']:g})")
    if job.connected_pp_contact is not None:
        plan.contacts_between_bonded = job.connected_pp_contact
    _apply_times(model, job)


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
    inter = model.passthrough.setdefault("interactions", {})
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
            g.motion, g.motion_type = [], 1
            g.raw_lines = [r for r in g.raw_lines if not r.startswith("26")]
            cleared.add(id(g))
        g.motion.append(interval)
    for name, ln in job.geometry_motion_force:
        geometry(name, ln)
        raise InputError(job.path, ln, "GEOMETRY_MOTION_FORCE: force-dependent geometry motion "
                         "is not supported")


def _check_models(model: GranularModel, job: MusenJob, models: dict) -> None:
    """ConsoleSimulator::SimulationPrecheck, made strict where fibrelmp cannot follow."""
    if "PP" not in models:
        raise InputError(job.path, job.line, f"job {job.index}: no particle-particle model "
                         "(MODEL_PP ModelPPHertzMindlin); cmusen would run without particle "
                         "contacts, which fibrelmp does not do")
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
    elif not model.passthrough.get("musen_gravity_set"):
        plan.gravity = np.array(MUSEN_DEFAULTS["gravity"])
        used.append("gravity (0, 0, -9.81)")
    model.passthrough["musen_gravity_set"] = True
    if used:
        model.warn("musen-default-settings", f"{job.path}:{job.line}: job {job.index} does not "
                   f"set {', '.join(used)}: MUSEN's defaults for a freshly imported scene are used")
    if plan.t_end <= plan.t_start:
        raise InputError(job.path, job.where("END_TIME"), f"END_TIME {plan.t_end:g} s is not after "
                         f"the scene's start time {plan.t_start:g} s")
    if plan.dt > plan.t_end - plan.t_start:
        raise InputError(job.path, job.where("SIMULATION_STEP"), f"simulation step {plan.dt:g} s "
                         f"is longer than the run ({plan.t_end - plan.t_start:g} s)")


# values that satisfy every cross-check, put in place of a failing time keyword by
# ``fibrelmp check`` (blanking it would bring in MUSEN's default, which may clash again)
_NEUTRAL_TIMES = {"SIMULATION_STEP": "1e-300", "SIMULATION_TSTEP": "1e-300", "END_TIME": "1e300",
                  "SAVING_STEP": "1", "SAVING_TSTEP": "1"}


def check_patch(err: InputError, line: str | None, attempt: int) -> str | None:
    """What ``textio.collect_errors`` puts in place of a failing script line while ``fibrelmp
    check`` looks for further errors: a model line gets the supported model of its kind (a
    job without one fails on its own), a time keyword a neutral value, a scene line what
    ``musen.check_patch`` gives; a JOB line is never replaced (the jobs around it would merge
    and report errors of their own); anything else is blanked."""
    if line is None:
        return None
    tok = line.split()
    key = tok[0].upper() if tok else ""
    if key in ("JOB", "NEW_JOB"):
        return None
    if key[:1].isdigit():
        from fibrelmp.translate.musen.scene import check_patch as scene_patch

        return scene_patch(err, line, attempt)
    candidates: list[str] = []
    kind = key[len("MODEL_"):] if key.startswith("MODEL_") else ""
    if kind in SUPPORTED_MODELS:
        candidates.append(f"{key} {SUPPORTED_MODELS[kind]}")
    elif key in _NEUTRAL_TIMES:
        candidates.append(f"{key} {_NEUTRAL_TIMES[key]}")
    candidates.append("")
    return candidates[attempt] if attempt < len(candidates) else None
