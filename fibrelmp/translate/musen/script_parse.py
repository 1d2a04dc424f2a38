"""Parse cmusen job scripts: keywords, jobs, line numbers (``read_script``).

Syntax follows MUSEN's ``ScriptAnalyzer.cpp`` (e0ff360): one ``KEYWORD values`` per line,
keywords case-insensitive, ``JOB``/``NEW_JOB`` starts a job.  Keywords before the first JOB
form job 1 of their own (cmusen pushes a job for them); they do NOT apply to later jobs.
Where cmusen prints "Unknown script key" and carries on, or silently keeps a default on a
bad value, fibrelmp stops with ``path:line:`` and a did-you-mean.  docs/musen.md lists which
keywords are honoured, ignored (named warning) or refused.  Applying a SIMULATOR job to a
scene is ``script_settings``.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ForceInterval, MotionInterval
from fibrelmp.translate.granular import models as physics
from fibrelmp.translate.musen.text_writer import EXPORT_FLAGS, all_on
from fibrelmp.textio import read_text

COMPONENTS = {"SIMULATOR": "SIMULATOR", "IMPORT_FROM_TEXT": "IMPORT_FROM_TEXT",
              "EXPORT_TO_TEXT": "EXPORT_TO_TEXT", "PACKAGE_GENERATOR": "PACKAGE_GENERATOR",
              "BONDS_GENERATOR": "BONDS_GENERATOR", "SNAPSHOT_GENERATOR": "SNAPSHOT_GENERATOR"}
OTHER_COMPONENTS = ("RESULTS_ANALYZER", "COMPARE_FILES")
_COMPONENT_NUMBERS = ["PACKAGE_GENERATOR", "RESULTS_ANALYZER", "BONDS_GENERATOR", "SIMULATOR",
                      "SNAPSHOT_GENERATOR", "EXPORT_TO_TEXT", "IMPORT_FROM_TEXT", "COMPARE_FILES"]
MATERIAL_PROPERTIES = {"DENSITY": 0, "HEAT_CAPACITY": 1, "DYNAMIC_VISCOSITY": 2,
                       "THERMAL_CONDUCTIVITY": 3, "YOUNG_MODULUS": 7, "NORMAL_STRENGTH": 8,
                       "TANGENTIAL_STRENGTH": 9, "POISSON_RATIO": 10, "SURFACE_ENERGY": 11,
                       "ATOMIC_VOLUME": 12, "SURFACE_TENSION": 13, "TIME_THERM_EXP_COEFF": 14,
                       "YIELD_STRENGTH": 15}
INTERACTION_PROPERTIES = {"RESTITUTION_COEFFICIENT": 200, "SLIDING_FRICTION": 201,
                          "ROLLING_FRICTION": 202}
# what ``fibrelmp check`` puts in place of a model line of a kind fibrelmp translates none of
# (LB, EF) after reporting it: the job keeps a model of that kind, so the kind's PARAMS lines
# below it read as cmusen reads them (not as "no MODEL_EF line"), and the settings skip it
REFUSED_MODEL = "fibrelmp:refused-above:"            # + the kind (names must differ per kind)
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
_EXPORT_KEYS = {"TEXT_EXPORT_OBJECTS": "objectTypes", "TEXT_EXPORT_CONST": "constProps",
                "TEXT_EXPORT_TD_PART": "tdPropsPart", "TEXT_EXPORT_TD_BOND": "tdPropsBond",
                "TEXT_EXPORT_TD_WALL": "tdPropsWall", "TEXT_EXPORT_SCENE": "sceneInfo",
                "TEXT_EXPORT_GEOMETRIES": "geometries", "TEXT_EXPORT_MATERIALS": "materials",
                "TEXT_EXPORT_GENERATORS": "generators"}
# keywords cmusen reads that cannot change a fibrelmp run (named warning, then ignored)
_IGNORED = {
    "LOG_FILE": "fibrelmp prints its log to the terminal",
    "VERLET_MAX_CELLS": "neighbour lists are LAMMPS's",
    "SAVE_COLLISIONS": "collisions are not saved", "MONITOR": "monitors are not supported",
    "POSTPROCESS": "post-processing commands are not supported",
    "SELECTIVE_SAVING_P": "every field is saved", "SELECTIVE_SAVING_SB": "every field is saved",
    "SELECTIVE_SAVING_LB": "every field is saved", "SELECTIVE_SAVING_TW": "every field is saved",
}


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
    agglomerates_db: str | None = None       # AGGLOMERATES_DB: the .madb the generators read
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
    max_part_move: float = 0.0               # MAX_PART_MOVE (0: keep the simulator's)
    step_inc_factor: float = 0.0             # STEP_INC_FACTOR (0: keep the simulator's)
    velocity_limit: float | None = None      # LIMIT_PARTICLE_VELOCITY (<= 0: no limit)
    verlet_coef: float = 0.0                 # VERLET_COEF (0: keep the file's, as cmusen)
    verlet_auto: bool | None = None          # VERLET_AUTO
    # STOP_CRITERION lines in order (NONE / BROKEN_BONDS; any replaces a .mdem's criteria) and
    # the last BROKEN_BONDS number (cmusen keeps one value)
    stop_criteria: list[str] = field(default_factory=list)
    stop_max_broken: int = 0
    material_properties: list[tuple[int, str, float, int]] = field(default_factory=list)
    interaction_properties: list[tuple[int, str, str, float, int]] = field(default_factory=list)
    geometry_motion_time: list[tuple[str, MotionInterval, int]] = field(default_factory=list)
    geometry_motion_force: list[tuple[str, ForceInterval, int]] = field(default_factory=list)
    text_export: dict[str, dict[str, bool]] = field(default_factory=all_on)
    precision: int = 6
    time_interval: tuple[float, float] | None = None
    refused: list[tuple[str, int, str]] = field(default_factory=list)   # (keyword, line, why)
    warnings: list[tuple[str, str]] = field(default_factory=list)
    lines: dict[str, int] = field(default_factory=dict)                  # keyword -> last line
    # generator components (PACK_GEN_* / BOND_GEN_* by 1-based generator index)
    package_generators: dict[int, dict] = field(default_factory=dict)
    bond_generators: dict[int, dict] = field(default_factory=dict)
    mixture_properties: list[tuple[int, int, str, float, float, float, int]] = field(default_factory=list)
    snapshot_time: float = 0.0

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
    return sorted(set(_HANDLERS) | set(_IGNORED) | set(_EXPORT_KEYS)
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
    elif not line.tok and not any(ch.isalnum() for ch in key):   # a lone stray mark (Example 6's ´)
        job.warnings.append(("musen-ignored-keyword", f"{line.path}:{line.ln}: {key!r} skipped "
                             "(not a keyword; cmusen skips it as an unknown key)"))
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
        raise line.error(f"{value} is not supported by fibrelmp (MUSEN's examples and "
                         "tutorials use none; fibrelmp runs " + ", ".join(COMPONENTS) + ")")
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
        # cmusen (ScriptAnalyzer's ReadModelParamsOld) gives them to the first model selected
        # by a MODEL_<kind> keyword of this kind; a model named by the generic MODEL keyword
        # does not count
        for m in job.models:
            if m.kind == kind:
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


def _variable_step_setting(attr: str):
    # cmusen: a value other than 0 replaces the simulator's (ConsoleSimulator); a negative one
    # would make MUSEN's step nan
    def handler(job: MusenJob, line: _Line) -> None:
        value = line.floats(1)[0]
        if value < 0:
            raise line.error(f"expected a value >= 0 (0 keeps the simulator's), got {value:g}")
        setattr(job, attr, value)
    return handler


def _velocity_limit(job: MusenJob, line: _Line) -> None:
    # cmusen: a value <= 0 removes the limit (CBaseSimulator::SetPartVelocityLimit)
    job.velocity_limit = line.floats(1)[0]


def _stop(job: MusenJob, line: _Line) -> None:
    value = line.tok[0].upper() if line.tok else ""
    if value not in ("NONE", "BROKEN_BONDS"):
        raise line.error(f"expected NONE or BROKEN_BONDS, got {value!r}")
    if value == "BROKEN_BONDS":
        # cmusen reads a size_t: a count of bonds, >= 0
        count = line.tok[1] if len(line.tok) > 1 else ""
        if not count.isdigit():
            raise line.error(f"BROKEN_BONDS needs the number of broken bonds (an integer >= 0) "
                             f"after which the simulation stops, got {count!r}")
        job.stop_max_broken = int(count)
    job.stop_criteria.append(value)


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
    if len(line.tok) < 3:
        raise line.error("needs GEOMETRY FORCE_LIMIT MIN|MAX vx vy vz wx wy wz cx cy cz")
    limit = _Line(line.path, line.ln, line.key, line.tok[1]).floats(1)[0]
    # ScriptAnalyzer: "MIN" is MIN, any other word MAX
    v = _Line(line.path, line.ln, line.key, " ".join(line.tok[3:])).floats(9)
    # script order: velocity, rotation velocity, rotation centre (the text file has v, c, w)
    job.geometry_motion_force.append((line.tok[0], ForceInterval(
        limit, line.tok[2].upper() != "MIN", np.array(v[0:3]), np.array(v[6:9]), np.array(v[3:6])), line.ln))


def _set(attr: str):
    def handler(job: MusenJob, line: _Line) -> None:
        setattr(job, attr, line.text())
    return handler


# PACK_GEN_<key> / BOND_GEN_<key> INDEX VALUE...: (setting name, how the value reads)
_GENERATOR_KEYS = {
    "PACK_GEN_VOLUME": ("volume", "text"), "PACK_GEN_MIXTURE": ("mixture", "text"),
    "PACK_GEN_POROSITY": ("porosity", 1), "PACK_GEN_OVERLAP": ("overlap", 1),
    "PACK_GEN_ITERATIONS": ("iterations", 1), "PACK_GEN_VELOCITY": ("velocity", 3),
    "PACK_GEN_INSIDE": ("inside", "flag"), "BOND_GEN_MATERIAL": ("material", "text"),
    "BOND_GEN_MINDIST": ("min", 1), "BOND_GEN_MAXDIST": ("max", 1),
    "BOND_GEN_DIAMETER": ("diameter", 1), "BOND_GEN_OVERLAY": ("overlay", "flag"),
}


def _generator_key(job: MusenJob, line: _Line) -> None:
    name, kind = _GENERATOR_KEYS[line.key]
    index = line.tok[0] if line.tok else ""
    if not index.isdigit() or int(index) < 1:
        raise line.error(f"needs the generator's number (1, 2, ...) first, got {line.rest!r}")
    rest = _Line(line.path, line.ln, line.key, line.rest[len(line.tok[0]):].strip())
    if kind == "text":
        value = rest.text()
    elif kind == "flag":
        value = rest.flag()
    else:
        value = rest.floats(kind) if kind > 1 else rest.floats(1)[0]
    table = job.package_generators if line.key.startswith("PACK") else job.bond_generators
    table.setdefault(int(index), {})[name] = value


def _mixture_property(job: MusenJob, line: _Line) -> None:
    if len(line.tok) != 6:
        raise line.error(f"needs 6 values: MIXTURE FRACTION COMPOUND_KEY DIAMETER "
                         f"CONTACT_DIAMETER FRACTION, got {len(line.tok)} (cmusen reads a missing "
                         "value as 0)")
    mix, frac = _Line(line.path, line.ln, line.key, " ".join(line.tok[:2])).floats(2)
    d, dc, share = _Line(line.path, line.ln, line.key, " ".join(line.tok[3:])).floats(3)
    if mix != int(mix) or frac != int(frac) or mix < 1 or frac < 1:
        raise line.error("the mixture and fraction numbers count from 1")
    job.mixture_properties.append((int(mix), int(frac), line.tok[2], d, dc, share, line.ln))


_HANDLERS = {
    **{key: _generator_key for key in _GENERATOR_KEYS},
    "MIXTURE_PROPERTY": _mixture_property, "SNAPSHOT_TIME": _number("snapshot_time", False),
    "SOURCE_FILE": _set("source_file"), "RESULT_FILE": _set("result_file"),
    "AGGLOMERATES_DB": _set("agglomerates_db"),
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
    "VARIABLE_TIME_STEP": _variable_step, "MAX_PART_MOVE": _variable_step_setting("max_part_move"),
    "STEP_INC_FACTOR": _variable_step_setting("step_inc_factor"), "STOP_CRITERION": _stop,
    "LIMIT_PARTICLE_VELOCITY": _velocity_limit,
    "VERLET_COEF": _number("verlet_coef"), "VERLET_AUTO": _flag("verlet_auto"),
    "MATERIAL_PROPERTY": _material_property, "INTERACTION_PROPERTY": _interaction_property,
    "TEXT_EXPORT_PRECISION": _precision, "TIME_INTERVAL": _time_interval,
    "GEOMETRY_MOTION_TIME": _motion_time, "GEOMETRY_MOTION_FORCE": _motion_force,
}


def model_kind(spec: MusenModelSpec) -> str:
    """PP PW SB LB EF of a selected model: from MUSEN's catalogue, else the keyword's kind."""
    for kind, names in MUSEN_MODELS.items():
        if spec.name in names:
            return kind
    return spec.kind


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
    kind = {"EXT_FORCE": "EF", "PPHT": "PP"}.get(kind, kind)
    stock = physics.default_model(kind) if kind in physics.KIND_WORDS else None
    if stock is not None:
        candidates.append(f"{key} {stock.name}")
    elif kind in ("LB", "EF"):
        candidates.append(f"{key} {REFUSED_MODEL}{kind}")
    elif key in _NEUTRAL_TIMES:
        candidates.append(f"{key} {_NEUTRAL_TIMES[key]}")
    candidates.append("")
    return candidates[attempt] if attempt < len(candidates) else None
