"""MUSEN physics models as plug-ins: one module per model in this package, registering itself
by its MUSEN name (``@register``); nothing else lists them.  A model says its kind (PP, PW, SB,
LB, EF), its parameters with MUSEN's names and defaults, whether it needs fibrelmp's own LAMMPS
styles, checks its parameters (``path:line`` errors) and applies them to a ``GranularPlan``.
``find``/``of_kind`` import every module of the package on first use (docs/architecture.md,
"Adding a physics model").  The module's docstring is the model's documentation: ``model_page``
renders the model's own page docs/models/<module>.md from it (``tools/model_pages.py`` writes
the pages; a test fails while a registered model has no page or its page is stale)."""

from __future__ import annotations

import dataclasses
import importlib
import math
import pkgutil
import sys
from pathlib import Path
from typing import Any, ClassVar

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel, GranularPlan, SolidBondLaw
from fibrelmp.lammps_text import LammpsText
from fibrelmp.sanity import hertz_contact_time

KIND_WORDS = {"PP": "particle-particle", "PW": "particle-wall", "SB": "solid-bond",
              "LB": "liquid-bond", "EF": "external-force"}
# what a model of each kind is, in messages ("stock LAMMPS has no such ...")
KIND_NOUNS = {"PP": "particle-particle law", "PW": "particle-wall law", "SB": "solid bond",
              "LB": "liquid bond", "EF": "external force"}

_REGISTRY: dict[str, type[PhysicsModel]] = {}
_loaded = False


class PhysicsModel:
    """One MUSEN model fibrelmp translates.  Subclasses set the class attributes and, where the
    model changes the run, override ``apply``."""

    name: ClassVar[str]                        # MUSEN's name, e.g. "ModelPPHertzMindlin"
    kind: ClassVar[str]                        # "PP" | "PW" | "SB" | "LB" | "EF"
    mdem_key: ClassVar[str] = ""               # MUSEN's unique key (a .mdem's model manager)
    parameters: ClassVar[dict[str, float]] = {}   # MUSEN's AddParameter(...) names and defaults
    # why the model needs fibrelmp's LAMMPS styles (None: stock LAMMPS expresses it)
    needs_styles: ClassVar[str | None] = None
    # the only model of its kind fibrelmp translates with stock LAMMPS (bare scenes use it)
    default: ClassVar[bool] = False
    # SB models: their SolidBondLaw.form (what granular.bonds renders)
    plan_bond_model: ClassVar[str | None] = None
    # SB models: the law's name in the script's comment (None: bond_law's)
    law_title: ClassVar[str | None] = None
    # what the run needs for the model (fields.py, script_settings): a contact heat law
    # (temperatures and fix musen/heat), a PP law that reads the temperatures without heat
    # (d_musen_temperature, ghosts too), a law that keeps its own contact history and so cannot
    # act together with another model of its kind
    contact_heat: ClassVar[bool] = False
    reads_temperature: ClassVar[bool] = False
    acts_alone: ClassVar[bool] = False
    # a PP law whose MUSEN code takes the surface distance from the spheres' stored coordinates
    # (not the contact vector): across a periodic boundary MUSEN sees no touching pair
    raw_coordinate_distance: ClassVar[bool] = False

    @classmethod
    def read_parameters(cls, text: str, path: Path | str | None, line: int | None,
                        model: GranularModel) -> dict[str, float]:
        """MUSEN's defaults updated by ``NAME value`` pairs of ``text`` (a MODEL_*_PARAMS line
        or a .mdem's stored parameters); an unknown name is ignored with a warning, as MUSEN
        does; a value that is not a number is an InputError at ``path``:``line``."""
        params = dict(cls.parameters)
        tok = text.split()
        for j in range(0, len(tok), 2):
            key = tok[j]
            if key not in params:
                at = f"{path}:{line}" if line is not None else f"{path} (its model manager)"
                model.warn("musen-unknown-model-parameter", f"{at}: {cls.name} has no parameter "
                           f"{key}; ignored as MUSEN does")
                continue
            try:
                params[key] = float(tok[j + 1])
            except (IndexError, ValueError):
                raise InputError(path, line, f"{cls.name} parameter {key}: expected "
                                 "a number") from None
        return params

    @classmethod
    def pair_style_lines(cls, params: dict[str, float], own_styles: bool) -> list[str]:
        """PP models: the ``pair_style`` line (and its comment) of the LAMMPS script;
        ``own_styles``: fibrelmp's LAMMPS styles are in use.  Every pair_coeff line gives
        E* G* e mu mu_r (musen styles) or the stock granular law (``granular.contacts``)."""
        raise NotImplementedError(f"{cls.name} is not a particle-particle model")

    @classmethod
    def with_scene(cls, model: GranularModel, params: dict[str, float]) -> dict[str, float]:
        """What the LAMMPS lines render: ``params`` and what the model takes from the scene
        (e.g. its materials' surface energy), under keys that are not MUSEN's."""
        return params

    @classmethod
    def pp_law_words(cls, params: dict[str, float]) -> str:
        """PP models: the law's words after ``then`` in ``pair_style musen/hm`` (NAME
        parameters, musen_pp_law.h), when it acts after another PP model."""
        raise NotImplementedError(f"{cls.name} is not a particle-particle model")

    @classmethod
    def mesh_law_words(cls, params: dict[str, float]) -> str:
        """PW models: the law's words after ``law`` in ``fix musen/wall/mesh FILE``
        (NAME parameters, musen_pw_law.h)."""
        raise NotImplementedError(f"{cls.name} is not a particle-wall model")

    @classmethod
    def mesh_law_args(cls, params: dict[str, float]) -> str:
        """PW models: what follows the file name of ``fix musen/wall/mesh`` ("" for its
        default law, hertz/mindlin; else " law NAME parameters", musen_pw_law.h)."""
        words = cls.mesh_law_words(params)
        return "" if words == "hertz/mindlin" else f" law {words}"

    @classmethod
    def bond_law(cls, plan: GranularPlan) -> tuple[str, str]:
        """SB models with fibrelmp's ``bond_style musen/elastic``: (the law's name in the
        script's comment, the style's law arguments)."""
        raise NotImplementedError(f"{cls.name} is not a solid-bond model of musen/elastic")

    @classmethod
    def then_words(cls, law: SolidBondLaw) -> str:
        """SB models acting after another one: the style's ``then`` words of ``law``."""
        raise NotImplementedError(f"{cls.name} is not a solid-bond model of musen/elastic")

    @classmethod
    def apply(cls, plan: GranularPlan, params: dict[str, float], path: Path | str | None,
              line: int | None) -> None:
        """Check ``params`` and set what the model changes in ``plan`` (nothing by default)."""


def register(model: type[PhysicsModel]) -> type[PhysicsModel]:
    """Class decorator: add ``model`` to the registry under its MUSEN name."""
    if model.kind not in KIND_WORDS:
        raise ValueError(f"{model.__name__}: kind {model.kind!r} is not one of {list(KIND_WORDS)}")
    if model.name in _REGISTRY and _REGISTRY[model.name] is not model:
        raise ValueError(f"two modules register the MUSEN model {model.name}")
    _REGISTRY[model.name] = model
    return model


def _load() -> None:
    global _loaded
    if not _loaded:
        for info in pkgutil.iter_modules(__path__):
            importlib.import_module(f"{__name__}.{info.name}")
        _loaded = True


def find(name: str) -> type[PhysicsModel] | None:
    """The registered model called ``name`` (MUSEN's name), or None."""
    _load()
    return _REGISTRY.get(name)


def of_kind(kind: str) -> list[type[PhysicsModel]]:
    """The registered models of ``kind``: the stock default first, then by name."""
    _load()
    return sorted((m for m in _REGISTRY.values() if m.kind == kind),
                  key=lambda m: (not m.default, m.needs_styles is not None, m.name))


def default_model(kind: str) -> type[PhysicsModel] | None:
    """The model fibrelmp uses for ``kind`` when a scene names none (MUSEN's for a bare scene)."""
    return next((m for m in of_kind(kind) if m.default), None)


def chosen(model: GranularModel, kind: str) -> tuple[type[PhysicsModel], dict[str, float]]:
    """The model of ``kind`` a scene runs and its parameters: the one its settings chose
    (``script_settings``), else the stock default with MUSEN's defaults (a DEMDF scene)."""
    picked = model.models.get(kind)
    if picked is not None:
        return find(picked.name), picked.parameters
    stock = default_model(kind)
    return stock, dict(stock.parameters)


def chosen_all(model: GranularModel, kind: str) -> list[tuple[type[PhysicsModel], dict[str, float]]]:
    """Every model of ``kind`` a scene runs, in the order they act on each contact: the
    chosen one (``chosen``), then the later ones of that kind (``model.later_models``; cmusen
    runs every selected PP / PW model on each contact in turn, forces adding)."""
    return [chosen(model, kind)] + [(find(c.name), c.parameters) for c in model.later_models
                                    if c.kind == kind]


def periodic_contact_warnings(model: GranularModel, periodic: Any) -> list[tuple[str, str]]:
    """A warning for each PP law that MUSEN evaluates with the raw coordinates' distance
    (``raw_coordinate_distance``) in a periodic box: a pair touching across the boundary is
    one contact to LAMMPS (its periodic image) but far apart to MUSEN."""
    if not (model.plan.particle_contacts and any(bool(p) for p in periodic)):
        return []
    return [("musen-periodic-raw-distance",
             f"{m.name}: MUSEN takes the surface distance from the spheres' coordinates, not "
             "the periodic contact vector, so in cmusen spheres touching across a periodic "
             "boundary feel no contact force; fibrelmp (LAMMPS) applies the law to the "
             "periodic image: such contacts differ from cmusen")
            for m, _ in chosen_all(model, "PP") if m.raw_coordinate_distance]


def pair_style_lines(model: GranularModel, own_styles: bool) -> list[str]:
    """The ``pair_style`` line (and its comment) of the PP models a scene runs: the first
    one's, each later model's law after ``then``."""
    (first, params), *later = chosen_all(model, "PP")
    lines = first.pair_style_lines(first.with_scene(model, params), own_styles)
    if later:
        if not own_styles:
            raise RuntimeError("several PP models need fibrelmp's LAMMPS styles (checked earlier)")
        lines[-1] += "".join(f" then {m.pp_law_words(m.with_scene(model, p))}" for m, p in later)
        lines.insert(-1, LammpsText("# and after it, on each contact (cmusen's order, forces add): "
                                    + ", ".join(m.name for m, _ in later)))
    return lines


def mesh_law_args(model: GranularModel) -> str:
    """What follows the file name of ``fix musen/wall/mesh``: the PW models' laws in order
    ("" for MUSEN's Hertz-Mindlin alone, the fix's default)."""
    laws = chosen_all(model, "PW")
    if len(laws) == 1:
        return laws[0][0].mesh_law_args(laws[0][0].with_scene(model, laws[0][1]))
    return "".join(f" law {m.mesh_law_words(m.with_scene(model, p))}" for m, p in laws)


def combine_contact_times(plan: GranularPlan, kind: str, later: list[GranularPlan]) -> None:
    """Several PP (or PW) laws act together: their stiffnesses add, so the contact is shorter
    than each law's own; n springs in parallel are at most n times the stiffest, hence
    (shortest duration) / sqrt(n) bounds it from below (``fibrelmp check``'s figure)."""
    attr = "pp" if kind == "PP" else "pw"
    plans = [plan, *later]
    times = [getattr(p, f"{attr}_contact_time") or hertz_contact_time for p in plans]
    names = [getattr(p, f"{attr}_contact_law") if getattr(p, f"{attr}_contact_time") else "Hertz"
             for p in plans]
    root = math.sqrt(len(times))

    def contact_time(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
        return min(t(m_eff, r_eff, e_star, speed) for t in times) / root

    setattr(plan, f"{attr}_contact_time", contact_time)
    setattr(plan, f"{attr}_contact_law", f"{' + '.join(names)}: shortest / sqrt({len(times)}), "
                                         "a lower bound")


def solid_bond_model(plan: GranularPlan) -> type[PhysicsModel]:
    """The SB model of ``plan.bond_law`` (the form's model when no SB model chose it)."""
    return next(m for m in of_kind("SB") if m.plan_bond_model == plan.bond_law.form)


def add_later_bond_law(plan: GranularPlan, name: str, params: dict[str, float],
                       path: Path | str | None, line: int | None) -> None:
    """An SB model acting after ``plan``'s bond law(s) (cmusen runs every active SB model on
    each bond in turn): checked as its model checks it, appended to ``plan.then_bond_laws``."""
    own = GranularPlan(dt=plan.dt, t_start=plan.t_start, t_end=plan.t_end)
    find(name).apply(own, params, path, line)
    plan.then_bond_laws.append(dataclasses.replace(own.bond_law, breakage=int(own.bond_breakage)))


def bond_style_law(plan: GranularPlan) -> tuple[str, str]:
    """(the laws' names for the script's comment, ``bond_style musen/elastic``'s law words)
    of the first SB law and every later one."""
    name, words = solid_bond_model(plan).bond_law(plan)
    for law in plan.then_bond_laws:
        model = next(m for m in of_kind("SB") if m.plan_bond_model == law.form)
        title = model.law_title if model.law_title else model.bond_law(plan)[0]
        name += f" then {title.lower()}"
        words += f" {model.then_words(law)}"
    return name, words


def mdem_key(name: str) -> str:
    """MUSEN's key of the model called ``name`` ("" for a model fibrelmp does not translate)."""
    model = find(name)
    return model.mdem_key if model is not None else ""


# ------------------------------------------------------------------ docs/models/<module>.md
# Each model's page is its own file (adding a model edits no shared document): a part generated
# from the model module (tools/model_pages.py), then, optionally, text written by hand.
MODEL_PAGES = Path("docs") / "models"
PAGE_END = "<!-- end of the generated part: text below this line is kept by tools/model_pages.py -->"


def module_name(model: type[PhysicsModel]) -> str:
    """The model's module in this package, e.g. ``pp_sintering_temperature``."""
    return model.__module__.rsplit(".", 1)[1]


def model_doc(model: type[PhysicsModel]) -> list[str]:
    """The documentation of ``model``: its module's docstring, each paragraph on one line."""
    text = sys.modules[model.__module__].__doc__ or ""
    return [" ".join(par.split()) for par in text.strip().split("\n\n") if par.strip()]


def model_page(model: type[PhysicsModel]) -> str:
    """The generated part of ``model``'s page docs/models/<module>.md, up to ``PAGE_END``."""
    params = ", ".join(f"`{k}` {v:g}" for k, v in model.parameters.items()) or "none"
    if model.needs_styles:
        lammps = f"`{model.needs_styles}` (fibrelmp's LAMMPS styles only)"
    elif model.default:
        lammps = "fibrelmp's LAMMPS styles, or stock LAMMPS approximately"
    else:
        lammps = "nothing of its own (see below)"
    module = module_name(model)
    rows = [("kind", KIND_WORDS[model.kind]), ("parameters (MUSEN's defaults)", params),
            ("LAMMPS", lammps), ("`.mdem` key", f"`{model.mdem_key}`" if model.mdem_key else "—"),
            ("module", f"`fibrelmp/translate/granular/models/{module}.py`")]
    lines = ["<!-- generated by tools/model_pages.py from the model module: edit its docstring "
             "and attributes, then rerun -->", f"# {model.name}", "", "| | |", "|---|---|"]
    lines += [f"| {k} | {v.replace('|', chr(92) + '|')} |" for k, v in rows]
    return "\n".join(lines + [""] + [par + "\n" for par in model_doc(model)] + [PAGE_END]) + "\n"


def registered_models() -> list[type[PhysicsModel]]:
    """Every registered model, by kind (PP, PW, SB, LB, EF) as ``of_kind`` orders them."""
    return [m for kind in KIND_WORDS for m in of_kind(kind)]
