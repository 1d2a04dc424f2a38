"""MUSEN's dynamic generators (``plan.inlets``, read by ``translate/musen/mdem/generators.py``)
as fibrelmp's ``fix musen/inlet`` commands: the generation steps and counts of cmusen's clock
for the job's step and end time, each fraction's LAMMPS type, diameter and density."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel

if TYPE_CHECKING:       # the type only: translate/ must not import the format homes
    from fibrelmp.translate.musen.mdem.generators import Inlet

INLET_SEED = 20260          # the job's seed: generator k uses INLET_SEED + k (docs/musen.md §6)
LOG_NAME = "inlets.log"     # fix musen/inlet: "STEP ID" per inserted sphere


def reserve_rows(model: GranularModel, requested: int) -> int:
    """Rows for the spheres the generators may make, appended to ``model.spheres`` once
    (inactive: activity start inf until a frame shows them; LAMMPS ID = row + 1, MUSEN id =
    the next free ids after every object of the scene, in order of success, as MUSEN gives
    them); the first reserved row.  Rows never filled are left out of the results."""
    sp = model.spheres
    if model.plan.inlet_rows is not None:
        return model.plan.inlet_rows
    first = sp.count
    others = [sp.ids] + [np.asarray(o.ids) for o in (model.bonds, model.triangles) if o is not None]
    others.append(np.array([lb.id for lb in model.liquid_bonds or []], np.int64))
    next_id = 1 + max((int(np.max(i)) for i in others if len(i)), default=-1)
    n = int(requested)
    sp.ids = np.r_[sp.ids, next_id + np.arange(n)].astype(np.int64)
    # until made, each row holds one of the kinds the generators make (the time-step checks
    # see every kind); the frames give each sphere its own (frames.py _generated)
    kinds = inlet_spheres(model)
    pick = [kinds[k % len(kinds)] for k in range(n)]
    sp.material = np.r_[sp.material, np.array([m for m, _, _ in pick], np.int64)].astype(sp.material.dtype)
    for name, col in (("radius", 1), ("contact_radius", 1), ("mass", 2)):
        setattr(sp, name, np.r_[getattr(sp, name), np.array([k[col] for k in pick], float)])
    for name in ("position", "velocity", "omega"):
        setattr(sp, name, np.r_[np.asarray(getattr(sp, name), float).reshape(-1, 3), np.zeros((n, 3))])
    sp.quaternion = np.r_[np.asarray(sp.quaternion, float).reshape(-1, 4), np.tile([1.0, 0, 0, 0], (n, 1))]
    sp.active_start = np.r_[sp.active_start, np.full(n, np.inf)]
    sp.active_end = np.r_[sp.active_end, np.full(n, np.inf)]
    if sp.compound_key is not None:
        sp.compound_key = list(sp.compound_key) + [""] * n
    if sp.temperature is not None:
        sp.temperature = np.r_[sp.temperature, np.zeros(n)]
    model.plan.inlet_rows = first
    return first


def _material(model: GranularModel, key: str, generator: str) -> int:
    for m, mat in enumerate(model.materials):
        if mat.key == key:
            return m
    raise InputError(model.source, None, f"dynamic generator '{generator}': mixture_key: "
                     f"compound '{key}' is not among the scene's materials")


def inlet_spheres(model: GranularModel) -> list[tuple[int, float, float]]:
    """(material, radius, mass) of every kind of sphere the generators can make."""
    out = []
    for inlet in model.plan.inlets:
        for key, diameter, _ in inlet.fractions:
            m = _material(model, key, inlet.generator.name)
            r = 0.5 * diameter
            out.append((m, r, 4.0 / 3.0 * math.pi * r ** 3 * model.materials[m].density))
    return out


def inlet_commands(model: GranularModel, type_of_mat: dict[int, int], dt: float, t_start: float,
                   t_end: float, wall_fix: str | None) -> list[str]:
    """One ``fix musen/inlet`` per active generator (in MUSEN's order: the new ids follow it);
    reserves the model's rows for what they may make (``reserve_rows``)."""
    from fibrelmp.translate.lammps_format import float_text

    inlets = model.plan.inlets
    if not inlets:
        return []
    if t_start != 0.0:
        raise InputError(model.source, None, "dynamic generators with a start time > 0 (a "
                         "continued run) are not supported: cmusen's generation clock starts at 0")
    if any(model.plan.periodic):       # fix musen/inlet does not look across periodic faces
        raise InputError(model.source, None, f"dynamic generator '{inlets[0].generator.name}': "
                         "generating in a periodic box is not supported by fibrelmp")
    events = model.plan.inlet_schedule(dt, t_end)     # cmusen's clock (mdem/generators.py)
    first = reserve_rows(model, sum(e.requested for e in events))
    out = []
    for k, inlet in enumerate(inlets):
        g = inlet.generator
        mine = [e for e in events if e.generator == k]
        box = " ".join(f"{float_text(a)} {float_text(b)}" for a, b in zip(inlet.lo, inlet.hi))
        vel = (f"random {float_text(g.velocity_magnitude)}" if g.random_velocity
               else "fixed " + " ".join(float_text(v) for v in g.init_velocity))
        fractions = " ".join(
            f"{type_of_mat[_material(model, key, g.name)]} {float_text(d)} "
            f"{float_text(model.materials[_material(model, key, g.name)].density)} {float_text(share)}"
            for key, d, share in inlet.fractions)
        steps = " ".join(f"{e.step} {e.requested}" for e in mine)
        # the per-type groups m<type> of the script (stock walls act on them)
        groups = " ".join(f"m{type_of_mat[_material(model, key, g.name)]}" for key, _, _ in inlet.fractions)
        out.append(f"fix             fl_inlet{k + 1} spheres musen/inlet {INLET_SEED + k} box {box} "
                   f"tries {g.max_iterations} walls {wall_fix or 'none'} velocity {vel} "
                   f"fractions {len(inlet.fractions)} {fractions} events {len(mine)} {steps} "
                   f"first_id {first + 1} log {LOG_NAME} groups {groups}{_volume_words(inlet)}")
    return out


def _volume_words(inlet: Inlet) -> str:
    """``volume N ...`` (the triangles of a volume that is not an axis-aligned box), or ""."""
    from fibrelmp.translate.lammps_format import float_text

    if inlet.triangles is None:
        return ""
    coords = " ".join(float_text(float(v)) for v in np.asarray(inlet.triangles).ravel())
    return f" volume {len(inlet.triangles)} {coords}"
