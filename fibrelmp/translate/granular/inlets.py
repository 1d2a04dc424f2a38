"""MUSEN's dynamic generators (``plan.inlets``, read by ``translate/musen/mdem/generators.py``)
as fibrelmp's ``fix musen/inlet`` commands: the generation steps and counts of cmusen's clock
for the job's step and end time, each fraction's LAMMPS type, diameter and density."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import MAX_GENERATED, GranularModel, SolidBonds

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
    pick = np.arange(n) % len(kinds)
    sp.material = np.r_[sp.material, np.array([m for m, _, _ in kinds], np.int64)[pick]].astype(sp.material.dtype)
    for name, col in (("radius", 1), ("contact_radius", 1), ("mass", 2)):
        setattr(sp, name, np.r_[getattr(sp, name), np.array([k[col] for k in kinds], float)[pick]])
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
        if inlet.makes_agglomerates:
            agg = _agglomerate(model, inlet)
            for key, r in zip(agg.part_keys, agg.radius):
                m = _material(model, key, inlet.generator.name)
                out.append((m, float(r), _mass(float(r), model.materials[m].density)))
            continue
        for key, diameter, _ in inlet.fractions:
            m = _material(model, key, inlet.generator.name)
            r = 0.5 * diameter
            out.append((m, r, 4.0 / 3.0 * math.pi * r ** 3 * model.materials[m].density))
    return out


def _mass(r: float, density: float) -> float:
    return 4.0 / 3.0 * math.pi * r ** 3 * density       # MUSEN's expression (Generate)


def _agglomerate(model: GranularModel, inlet: Inlet):
    """The generator's agglomerate; refused when no job gave it its database."""
    if inlet.agglomerate is None:
        raise InputError(model.source, None, f"dynamic generator '{inlet.generator.name}' makes "
                         f"agglomerates ('{inlet.generator.agglomerate_key}'), which come from the "
                         "agglomerates database: run the scene through a cmusen job script whose "
                         "job names it (AGGLOMERATES_DB)")
    return inlet.agglomerate


def inlet_bond_materials(model: GranularModel) -> list[int]:
    """Material indices of the bonds the generators of agglomerates make (sorted)."""
    mats = set()
    for inlet in model.plan.inlets:
        if inlet.makes_agglomerates:
            mats |= {_material(model, k, inlet.generator.name) for k in _agglomerate(model, inlet).bond_keys}
    return sorted(mats)


def inlet_bond_capacity(model: GranularModel) -> tuple[int, int]:
    """(bonds on one sphere, 1-2 neighbours of one sphere) the generated agglomerates need:
    LAMMPS's extra bond and special room per atom (0, 0 without agglomerates with bonds)."""
    stored = special = 0
    for inlet in model.plan.inlets:
        if inlet.makes_agglomerates and _agglomerate(model, inlet).bonds:
            agg = inlet.agglomerate
            stored = max(stored, int(np.bincount(agg.pairs[:, 0]).max()))
            special = max(special, int(np.bincount(agg.pairs.ravel()).max()))
    return stored, special


def inlet_bond_reach(model: GranularModel) -> float:
    """The longest bond of a generated agglomerate (its spheres' distance at generation)."""
    out = 0.0
    for inlet in model.plan.inlets:
        if inlet.makes_agglomerates and _agglomerate(model, inlet).bonds:
            x = inlet.agglomerate.coords
            out = max(out, float(np.linalg.norm(x[inlet.agglomerate.pairs[:, 0]]
                                                - x[inlet.agglomerate.pairs[:, 1]], axis=1).max()))
    return out


def reserve_agglomerate_rows(model: GranularModel, events: list) -> list[tuple[int, ...]]:
    """Rows for the spheres and bonds the generators of agglomerates may make, appended once:
    generator k's j-th requested agglomerate (over its events) has sphere rows
    first_k + j n_k + p (LAMMPS ID = row + 1, given by the fix whether or not it is made) and
    bond rows bond_first_k + j m_k + b.  Inactive (activity start inf) until a frame shows
    them; MUSEN's ids are given then, in MUSEN's order of success (frames.py).  Returns
    (generator index, first sphere row, first bond row, agglomerates requested, spheres and
    bonds of one) per generator of agglomerates."""
    plan = model.plan
    if plan.inlet_layout is not None:
        return plan.inlet_layout
    if any(not i.makes_agglomerates for i in plan.inlets):
        raise InputError(model.source, None, "a scene with dynamic generators of spheres and of "
                         "agglomerates is not supported by fibrelmp (their new objects' ids would "
                         "interleave); keep one kind")
    sp = model.spheres
    requested = {k: sum(e.requested for e in events if e.generator == k) for k in range(len(plan.inlets))}
    n = sum(requested[k] * _agglomerate(model, g).spheres for k, g in enumerate(plan.inlets))
    if n > MAX_GENERATED:
        raise InputError(model.source, None, f"the generated agglomerates would hold {n:,} spheres, "
                         f"more than fibrelmp's limit of {MAX_GENERATED:,} (it reserves room for each "
                         "before the run): lower the generators' rates or shorten the run")
    layout, part_mat, part_r, pair, bmat, bdiam = [], [], [], [], [], []
    bond_rows = 0 if model.bonds is None else model.bonds.count
    row = sp.count
    for k, inlet in enumerate(plan.inlets):
        agg = _agglomerate(model, inlet)
        count = requested[k]
        layout.append((k, row, bond_rows, count, agg.spheres, agg.bonds))
        # agglomerate j's parts are rows row + j n_k + p, its bonds the database's pairs shifted so
        part_mat.append(np.tile([_material(model, key, inlet.generator.name) for key in agg.part_keys], count))
        part_r.append(np.tile(np.asarray(agg.radius, float), count))
        base = row + agg.spheres * np.arange(count, dtype=np.int64)
        pair.append((base[:, None, None] + np.asarray(agg.pairs, np.int64)[None]).reshape(-1, 2))
        bmat.append(np.tile([_material(model, key, inlet.generator.name) for key in agg.bond_keys], count))
        bdiam.append(np.tile(np.asarray(agg.bond_diameter, float), count))
        row += count * agg.spheres
        bond_rows += count * agg.bonds
    mats = np.concatenate(part_mat).astype(np.int64) if part_mat else np.zeros(0, np.int64)
    r = np.concatenate(part_r) if part_r else np.zeros(0)
    pair = np.concatenate(pair) if pair else np.zeros((0, 2), np.int64)
    bmat = np.concatenate(bmat).astype(np.int64) if bmat else np.zeros(0, np.int64)
    bdiam = np.concatenate(bdiam) if bdiam else np.zeros(0)
    nb = len(pair)
    # the other objects' largest id: placeholder ids after it (frames.py gives MUSEN's)
    others = [sp.ids] + [np.asarray(o.ids) for o in (model.bonds, model.triangles) if o is not None]
    others.append(np.array([lb.id for lb in model.liquid_bonds or []], np.int64))
    next_id = 1 + max((int(np.max(i)) for i in others if len(i)), default=-1)
    plan.inlet_next_id = next_id
    sp.ids = np.r_[sp.ids, next_id + np.arange(n)].astype(np.int64)
    sp.material = np.r_[sp.material, mats].astype(sp.material.dtype)
    sp.radius = np.r_[sp.radius, r]
    sp.contact_radius = np.r_[sp.contact_radius, r]
    density = {m: model.materials[m].density for m in set(mats.tolist())}
    sp.mass = np.r_[sp.mass, [_mass(float(ri), density[int(m)]) for m, ri in zip(mats, r)]]
    for name in ("position", "velocity", "omega"):
        setattr(sp, name, np.r_[np.asarray(getattr(sp, name), float).reshape(-1, 3), np.zeros((n, 3))])
    sp.quaternion = np.r_[np.asarray(sp.quaternion, float).reshape(-1, 4), np.tile([1.0, 0, 0, 0], (n, 1))]
    sp.active_start = np.r_[sp.active_start, np.full(n, np.inf)]
    sp.active_end = np.r_[sp.active_end, np.full(n, np.inf)]
    if sp.compound_key is not None:
        sp.compound_key = list(sp.compound_key) + [model.materials[int(m)].key for m in mats]
    if sp.temperature is not None:
        sp.temperature = np.r_[sp.temperature, np.zeros(n)]
    if nb:
        _append_bonds(model, next_id + n, pair, bmat, bdiam)
    plan.inlet_rows = sp.count - n
    plan.inlet_layout = layout
    return layout


def _append_bonds(model: GranularModel, first_id: int, pair: np.ndarray, bmat: np.ndarray,
                  bdiam: np.ndarray) -> None:
    """The generated agglomerates' bonds appended to ``model.bonds`` (inactive until made),
    with placeholder ids from ``first_id`` on."""
    b = model.bonds
    nb = len(pair)
    new = dict(ids=first_id + np.arange(nb), pair=pair, material=bmat, diameter=bdiam,
               length0=np.zeros(nb), active_start=np.full(nb, np.inf), active_end=np.full(nb, np.inf))
    if b is None:
        model.bonds = SolidBonds(**new)
    else:
        for name, value in new.items():
            setattr(b, name, np.r_[np.asarray(getattr(b, name)), value].astype(
                np.asarray(getattr(b, name)).dtype if len(getattr(b, name)) else value.dtype))
        if b.compound_key is not None:
            b.compound_key = list(b.compound_key) + [model.materials[int(m)].key for m in bmat]
        for name in ("force", "tangential_overlap"):
            if getattr(b, name) is not None:
                setattr(b, name, np.r_[getattr(b, name), np.zeros((nb, 3))])
        if b.source_line is not None:
            b.source_line = np.r_[b.source_line, np.zeros(nb, b.source_line.dtype)]


def inlet_commands(model: GranularModel, type_of_mat: dict[int, int], dt: float, t_start: float,
                   t_end: float, wall_fix: str | None, type_of_bond_mat: dict[int, int] | None = None,
                   geometry_slots: int = 0) -> list[str]:
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
    if any(i.makes_agglomerates for i in inlets):
        return _agglomerate_commands(model, type_of_mat, type_of_bond_mat or {}, events, wall_fix,
                                     geometry_slots)
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


def _agglomerate_commands(model: GranularModel, type_of_mat: dict[int, int], type_of_bond_mat: dict[int, int],
                          events: list, wall_fix: str | None, geometry_slots: int) -> list[str]:
    """``fix musen/inlet ... agglomerate`` per generator of agglomerates."""
    from fibrelmp.translate.granular.bonds import PARTNERS, VALUES
    from fibrelmp.translate.lammps_format import float_text

    layout = reserve_agglomerate_rows(model, events)
    out = []
    for (k, first, *_), inlet in zip(layout, model.plan.inlets):
        g, agg = inlet.generator, inlet.agglomerate
        mine = [e for e in events if e.generator == k]
        box = " ".join(f"{float_text(a)} {float_text(b)}" for a, b in zip(inlet.lo, inlet.hi))
        vel = (f"random {float_text(g.velocity_magnitude)}" if g.random_velocity
               else "fixed " + " ".join(float_text(v) for v in g.init_velocity))
        mats = [_material(model, key, g.name) for key in agg.part_keys]
        parts = " ".join(
            f"{type_of_mat[m]} {float_text(float(r))} {float_text(model.materials[m].density)} "
            + " ".join(float_text(float(c)) for c in x) for m, r, x in zip(mats, agg.radius, agg.coords))
        bonds = " ".join(
            f"{int(a)} {int(b)} {type_of_bond_mat[_material(model, key, g.name)]} {float_text(float(d))}"
            for (a, b), key, d in zip(agg.pairs, agg.bond_keys, agg.bond_diameter))
        steps = " ".join(f"{e.step} {e.requested}" for e in mine)
        groups = " ".join(f"m{type_of_mat[m]}" for m in mats)
        geometry = f" geometry {PARTNERS} {VALUES} {geometry_slots}" if agg.bonds else ""
        time0 = model.plan.inlet_musen_time0
        if time0 is not None:
            geometry += f" musen_rand {int(time0)}"
        out.append(f"fix             fl_inlet{k + 1} spheres musen/inlet {INLET_SEED + k} box {box} "
                   f"tries {g.max_iterations} walls {wall_fix or 'none'} velocity {vel} "
                   f"agglomerate {agg.spheres} {parts} bonds {agg.bonds} {bonds} "
                   f"events {len(mine)} {steps} first_id {first + 1} log {LOG_NAME} groups {groups}"
                   f"{geometry}{_volume_words(inlet)}")
    return out
