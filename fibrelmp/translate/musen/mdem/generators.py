"""MUSEN's dynamic generators (inlets) stored in a ``.mdem``: the settings, MUSEN's
generation schedule, and the refusal of a run that needs them.

A dynamic generator (``ProtoObjectsGenerator`` in the modules data; MUSEN's
``CObjectsGenerator``, ``CGenerationManager``) inserts spheres of a mixture, or agglomerates of
the agglomerates database, into an analysis volume while the simulation runs.  cmusen asks
every generator before every step (``PreCalculationStep``, before the step's save):

- it generates at time *t* if it is active, ``start <= t <= end + 0.1 update``,
  ``t >= last + update`` and the number below is at least 1; *last* (the time of its last
  generation, attempted or not) starts at 0;
- the number is ``floor((t - (last - start)) * rate)``: with a start time > 0 the first
  generation makes ``2 start rate`` objects and each later one ``(update + start) rate``, not
  ``update rate`` (MUSEN's arithmetic, reproduced: the stored cmusen reference shows it);
- the rate in objects per second is ``rate_value`` (rate type 0), ``rate_value / update``
  (type 1: per update step) or ``rate_value / (end - start)`` (type 2: in total);
- *t* is cmusen's time, accumulated as ``t += dt`` from 0 (the first step runs twice at 0,
  as MUSEN's prediction step), so the generation steps drift from multiples of the update
  step by the rounding of that sum (``generation_schedule`` reproduces the sum exactly);
- each object gets at most ``max_iterations`` random positions (C ``rand()``, seeded with the
  wall-clock time: not reproducible) and is dropped if none is totally inside the volume,
  free of the other spheres' contact radii and of the walls; a failure does not move the count
  of later generations.  New objects get the next free ids (after every object of the scene and
  those generated before), ``activity_start = t``, and the fixed initial velocity or, with a
  random velocity, a direction uniform on the sphere times the magnitude.

fibrelmp reads and checks the settings (``read_inlets``: spheres of a mixture into a box
or any other triangle volume: cylinder, sphere, STL), computes the schedule for the job's own step and end time, and inserts the spheres
with fibrelmp's ``fix musen/inlet`` (one per generator, the schedule's steps and counts
passed to it).  A volume that is not an axis-aligned box is passed as its triangles and
tested with MUSEN's 15-point ray-parity test.  A generator of agglomerates gets its
agglomerate from the job's ``AGGLOMERATES_DB`` (``attach_agglomerates``) and inserts it
whole, with its solid bonds (docs/musen.md section 6).  Moving volumes and
``inside_geometries`` off are refused with the generator's and the field's name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import MAX_GENERATED

SPHERES, AGGLOMERATES = 1, 2            # ProtoObjectsGenerator.obj_type
RATE_PER_SECOND, RATE_PER_UPDATE, RATE_TOTAL = 0, 1, 2
MUSEN_DEFAULT_STEP = 1e-6              # BaseSimulator.h: a scene's step when none is set
_CHUNK = 1 << 20                        # time steps accumulated per numpy call


@dataclass(frozen=True)
class DynamicGenerator:
    """One ``ProtoObjectsGenerator`` as MUSEN's ``LoadConfiguration`` reads it."""

    name: str
    volume_key: str
    mixture_key: str
    objects: int                   # SPHERES (a mixture) or AGGLOMERATES
    agglomerate_key: str
    init_velocity: tuple[float, float, float]
    random_velocity: bool
    velocity_magnitude: float
    start: float
    end: float
    update_step: float
    rate_type: int
    rate_value: float
    max_iterations: int
    inside_geometries: bool
    active: bool
    # agglomerates: the database key's compound aliases -> compound keys; scaling factor
    part_materials: tuple[tuple[str, str], ...] = ()
    bond_materials: tuple[tuple[str, str], ...] = ()
    scaling_factor: float = 1.0

    @property
    def rate(self) -> float:
        """Objects per second (``CObjectsGenerator::Initialize``)."""
        if self.rate_type == RATE_PER_UPDATE:
            return self.rate_value / self.update_step
        if self.rate_type == RATE_TOTAL:
            return self.rate_value / (self.end - self.start)
        return self.rate_value

    def count_at(self, time: float, last: float) -> int:
        """``NumberToBeGenerated``: objects asked for at ``time`` after a generation at ``last``."""
        return int(math.floor((time - (last - self.start)) * self.rate))


@dataclass(frozen=True)
class GenerationEvent:
    """One generation cmusen attempts: at time step ``step`` (time ``time``, cmusen's
    accumulated value) the generator ``generator`` (its index) asks for ``requested`` objects."""

    step: int
    time: float
    generator: int
    requested: int


def read_generators(storage: Any) -> list[DynamicGenerator]:
    """The dynamic generators of a ``.mdem`` scene message (version 0 files: a rate in objects
    per second and 30 iterations, as MUSEN reads them)."""
    out = []
    for g in storage.modules_data.objects_generator.generators:
        old = g.version == 0
        v = g.init_velocity
        out.append(DynamicGenerator(
            name=g.name, volume_key=g.volume_key, mixture_key=g.mixture_key,
            objects=int(g.obj_type), agglomerate_key=g.aggl_key,
            init_velocity=(v.x, v.y, v.z), random_velocity=bool(g.random_velocity_flag),
            velocity_magnitude=g.velocity_magnitude, start=g.start_generation_time,
            end=g.end_generation_time, update_step=g.update_time_step,
            rate_type=RATE_PER_SECOND if old else int(g.rate_type),
            rate_value=g.generation_rate if old else g.rate_value,
            max_iterations=30 if old else int(g.max_iterations),
            inside_geometries=bool(g.inside_geometries), active=bool(g.activity),
            # CGenerationManager::LoadConfiguration: a std::map, the last alias line wins
            part_materials=tuple(dict(zip(g.aggl_part_materials_alias, g.aggl_part_materials_key)).items()),
            bond_materials=tuple(dict(zip(g.aggl_bond_materials_alias, g.aggl_bond_materials_key)).items()),
            scaling_factor=g.scaling_factor))
    return out


def _field(path: Path, gen: DynamicGenerator, field: str, message: str) -> InputError:
    return InputError(path, None, f"dynamic generator '{gen.name}': {field}: {message}")


def check_generator(gen: DynamicGenerator, storage: Any, path: Path) -> None:
    """What MUSEN's ``IsDataCorrect`` and ``Initialize`` need of an active generator: its
    volume, its mixture (fractions summing to 1) or agglomerate, a usable rate."""
    volumes = {v.base_geometry.key for v in storage.info.analysis_volume}
    volumes |= {v.key for v in storage.info.analysis_volume_v0}
    if gen.volume_key not in volumes:
        raise _field(path, gen, "volume_key", f"no analysis volume '{gen.volume_key}' in the "
                     "scene (MUSEN: 'No generation volume was specified')")
    if gen.objects not in (SPHERES, AGGLOMERATES):
        raise _field(path, gen, "obj_type", f"unknown object type {gen.objects} (1: spheres, "
                     "2: agglomerates)")
    if gen.objects == AGGLOMERATES:
        # the agglomerate itself is checked once the job's AGGLOMERATES_DB is known
        # (attach_agglomerates)
        if not (math.isfinite(gen.scaling_factor) and gen.scaling_factor > 0):
            raise _field(path, gen, "scaling_factor", f"must be > 0, got {gen.scaling_factor!r}")
        _check_rate(gen, path)
        return
    mixtures = {m.uniqueKey: m for m in storage.modules_data.materials_database.mixture}
    mixture = mixtures.get(gen.mixture_key)
    if mixture is None or not len(mixture.fraction):
        raise _field(path, gen, "mixture_key", f"no mixture '{gen.mixture_key}' with fractions "
                     "in the scene's materials database")
    total = sum(f.fraction for f in mixture.fraction)
    if abs(total - 1.0) > 1e-14:             # CMaterialsDatabase::IsMixtureCorrect
        raise _field(path, gen, "mixture_key", f"the fractions of mixture '{gen.mixture_key}' "
                     f"sum to {total:.17g}, not 1 (MUSEN refuses the mixture)")
    _check_rate(gen, path)


def _check_rate(gen: DynamicGenerator, path: Path) -> None:
    if gen.rate_type not in (RATE_PER_SECOND, RATE_PER_UPDATE, RATE_TOTAL):
        raise _field(path, gen, "rate_type", f"unknown rate type {gen.rate_type} (0: objects "
                     "per second, 1: per update step, 2: in total)")
    if not (gen.update_step > 0 and math.isfinite(gen.update_step)):
        raise _field(path, gen, "update_time_step", f"must be > 0, got {gen.update_step!r}")
    if not (math.isfinite(gen.rate) and gen.rate >= 0):
        raise _field(path, gen, "rate_value", f"gives {gen.rate!r} objects per second")


def generation_schedule(generators: list[DynamicGenerator], dt: float, t_end: float,
                        first_only: bool = False, source: str | None = None) -> list[GenerationEvent]:
    """Every generation cmusen attempts in a run of step ``dt`` to ``t_end``, in the order
    cmusen attempts them (by step, then generator order, which is also the order of the new
    ids).  The run's steps are those with t < ``t_end`` before the step (cmusen stops once the
    accumulated time reaches the end time).  ``first_only``: stop at the first chunk of 2^20
    steps holding an event (a long window of tiny steps is not summed to its end)."""
    events: list[GenerationEvent] = []
    active = [(i, g) for i, g in enumerate(generators) if g.active and g.rate > 0]
    if not active:
        return events
    last = {i: 0.0 for i, _ in active}
    first, t0, asked = 0, 0.0, 0
    horizon = max(g.end + 0.1 * g.update_step for _, g in active)
    while t0 < t_end and t0 <= horizon:
        # steps first .. first+_CHUNK-1; the last one starts the next chunk
        times = np.cumsum(np.r_[t0, np.full(_CHUNK - 1, dt)])
        new = _chunk_events(active, last, times, first, t_end)
        events.extend(new)
        asked += sum(e.requested for e in new)
        if asked > MAX_GENERATED:
            raise InputError(source, None, f"the dynamic generators ask for {asked:,}+ objects in "
                             f"this run, more than fibrelmp's limit of {MAX_GENERATED:,} (it reserves "
                             "room for each before the run): lower their rates or shorten the run")
        if first_only and events:
            break
        first += _CHUNK - 1
        t0 = float(times[-1])
    events.sort(key=lambda e: (e.step, e.generator))
    return events


def _chunk_events(active: list[tuple[int, DynamicGenerator]], last: dict[int, float],
                  times: np.ndarray, first: int, t_end: float) -> list[GenerationEvent]:
    """The events among ``times`` (steps ``first ..``; the last entry is the next chunk's
    first), updating ``last``."""
    out: list[GenerationEvent] = []
    stop = int(np.searchsorted(times[:-1], t_end, "left"))    # steps run: t < t_end
    usable = times[:stop]
    for i, g in active:
        limit = g.end + 0.1 * g.update_step
        k = 0
        while True:
            # earliest time the three conditions of IsNeedToBeGenerated can all hold
            need = max(g.start, last[i] + g.update_step, (last[i] - g.start) + 1.0 / g.rate)
            k = int(np.searchsorted(usable, need, "left"))
            while k < len(usable) and (usable[k] < last[i] + g.update_step
                                       or usable[k] < g.start
                                       or g.count_at(float(usable[k]), last[i]) < 1):
                k += 1                       # rounding at the threshold: step on
            if k >= len(usable) or usable[k] > limit:
                break
            t = float(usable[k])
            out.append(GenerationEvent(first + k, t, i, g.count_at(t, last[i])))
            last[i] = t
    return out


def next_fraction(generated: list[int], targets: list[float]) -> int:
    """``MixtureFractionIndexToGenerate``: the mixture fraction of the next sphere, given the
    spheres made so far of each fraction (successes only) and the target number fractions:
    the first fraction below its target, else the first."""
    total = sum(generated)
    if total == 0:
        return 0
    for i, (made, target) in enumerate(zip(generated, targets)):
        if made / total < target:
            return i
    return 0


@dataclass(frozen=True)
class Inlet:
    """An active generator of spheres as fibrelmp runs it: the bounding box of its volume
    (``lo``/``hi``), the volume's triangles when it is not that box (None: an axis-aligned box)
    and its mixture's fractions (compound key, diameter, number share)."""

    generator: DynamicGenerator
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    fractions: tuple[tuple[str, float, float], ...]
    # (n, 3, 3); not compared (an array has no single truth value; lo/hi tell volumes apart)
    triangles: np.ndarray | None = field(default=None, compare=False)
    # a generator of agglomerates: what it inserts, once the job's database is read
    # (attach_agglomerates; None until then)
    agglomerate: InletAgglomerate | None = field(default=None, compare=False)

    @property
    def makes_agglomerates(self) -> bool:
        return self.generator.objects == AGGLOMERATES


@dataclass(frozen=True)
class InletAgglomerate:
    """An agglomerate as a generator inserts it (``CObjectsGenerator::Initialize``): sphere
    positions relative to its volume-weighted centre, scaled; radii; compound keys of the
    spheres and bonds (the generator's alias maps); bond sphere pairs (left, right) and
    diameters (2 x the scaled bond radius)."""

    key: str
    coords: np.ndarray = field(compare=False)
    radius: np.ndarray = field(compare=False)
    part_keys: tuple[str, ...] = ()
    pairs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64), compare=False)
    bond_diameter: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False)
    bond_keys: tuple[str, ...] = ()

    @property
    def spheres(self) -> int:
        return len(self.radius)

    @property
    def bonds(self) -> int:
        return len(self.bond_diameter)


def _volume(storage: Any, gen: DynamicGenerator,
            path: Path) -> tuple[tuple, tuple, np.ndarray | None]:
    """The generator's analysis volume: its bounding box (where MUSEN draws random centres)
    and, unless every vertex lies on a corner of that box (MUSEN's box volume, tested exactly
    as a box), its triangles (a cylinder, sphere or STL volume: MUSEN's
    ``CInsideVolumeChecker``).  Moving volumes are refused."""
    volume = next((v for v in storage.info.analysis_volume if v.base_geometry.key == gen.volume_key),
                  None)
    if volume is None:
        raise _field(path, gen, "volume_key", f"analysis volume '{gen.volume_key}' is stored in "
                     "the old (version 0) form, which fibrelmp does not generate into")
    if volume.base_geometry.motion.ByteSize():
        raise _field(path, gen, "volume_key", f"analysis volume '{gen.volume_key}' moves; "
                     "generating into a moving volume is not supported by fibrelmp")
    tri = np.array([[[t.vert1.x, t.vert1.y, t.vert1.z], [t.vert2.x, t.vert2.y, t.vert2.z],
                     [t.vert3.x, t.vert3.y, t.vert3.z]] for t in volume.triangles], float)
    if not len(tri):
        raise _field(path, gen, "volume_key", f"analysis volume '{gen.volume_key}' has no triangles")
    vertices = tri.reshape(-1, 3)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    if not (hi > lo).all():
        raise _field(path, gen, "volume_key", f"analysis volume '{gen.volume_key}' is flat "
                     "(no extent on some axis); nothing fits inside it")
    box = ((vertices == lo) | (vertices == hi)).all()
    return tuple(map(float, lo)), tuple(map(float, hi)), None if box else tri


def read_inlets(storage: Any, path: Path) -> list[Inlet]:
    """Every active generator of a scene, checked (``check_generator``) and with what
    fibrelmp's ``fix musen/inlet`` needs (a generator of agglomerates: its agglomerate comes
    with the job, ``attach_agglomerates``)."""
    out = []
    for g in read_generators(storage):
        if not g.active:
            continue
        check_generator(g, storage, path)
        if not g.inside_geometries:
            raise _field(path, g, "inside_geometries", "off (no objects inside real geometries) "
                         "is not supported by fibrelmp; switch it on")
        if not (g.max_iterations >= 1):
            raise _field(path, g, "max_iterations", f"must be >= 1, got {g.max_iterations}")
        info = storage.info
        if info.periodic_conditions_enabled and (info.periodic_conditions_x or info.periodic_conditions_y
                                                 or info.periodic_conditions_z):
            raise InputError(path, None, f"dynamic generator '{g.name}': generating in a periodic "
                             "box is not supported by fibrelmp")
        lo, hi, triangles = _volume(storage, g, path)
        if g.objects == AGGLOMERATES:
            out.append(Inlet(g, lo, hi, (), triangles))
            continue
        mixture = next(m for m in storage.modules_data.materials_database.mixture
                       if m.uniqueKey == g.mixture_key)
        fractions = []
        for f in mixture.fraction:
            if f.contact_diameter > 0 and f.contact_diameter != f.diameter:
                raise _field(path, g, "mixture_key", f"fraction '{f.fractionName}' of mixture "
                             f"'{g.mixture_key}' has a contact diameter != its diameter, which "
                             "fibrelmp's generator does not support")
            if not f.diameter > 0:
                raise _field(path, g, "mixture_key", f"fraction '{f.fractionName}' has diameter "
                             f"{f.diameter!r}")
            fractions.append((f.compoundKey, float(f.diameter), float(f.fraction)))
        out.append(Inlet(g, lo, hi, tuple(fractions), triangles))
    return out


def attach_agglomerates(inlets: list[Inlet], db_path: Path | None, materials: dict[str, float],
                        where: Path, line: int | None) -> list[Inlet]:
    """The inlets with each generator of agglomerates given its agglomerate from the
    database ``db_path`` (the job's ``AGGLOMERATES_DB``; ``where``/``line`` name that line),
    checked as MUSEN's ``IsDataCorrect`` checks it (the agglomerate exists; every alias of its
    spheres and bonds maps to a compound of the scene: ``materials`` maps compound key ->
    density) and as fibrelmp needs it (an agglomerate, not a multisphere; contact radius =
    radius; bond spheres in range)."""
    from dataclasses import replace

    from fibrelmp.translate.musen.mdem.agglomerates import MULTISPHERE, prepared_agglomerate, read_database

    if not any(i.makes_agglomerates for i in inlets):
        return inlets
    if db_path is None:
        gen = next(i.generator for i in inlets if i.makes_agglomerates)
        raise InputError(where, line, f"dynamic generator '{gen.name}' makes agglomerates of "
                         f"'{gen.agglomerate_key}', but the job names no AGGLOMERATES_DB (MUSEN: "
                         "'No correct agglomerate has been specified')")
    db = read_database(db_path, where, line)
    out = []
    for inlet in inlets:
        g = inlet.generator
        if not inlet.makes_agglomerates:
            out.append(inlet)
            continue

        def bad(message: str, g=g) -> InputError:
            return InputError(where, line, f"dynamic generator '{g.name}': agglomerate "
                              f"'{g.agglomerate_key}' of {db_path.name}: {message}")
        agg = db.get(g.agglomerate_key)
        if agg is None:
            raise bad("no such key in the database (MUSEN: 'No correct agglomerate has been "
                      "specified')")
        if agg.kind == MULTISPHERE:
            raise bad("a multisphere (rigid clump) is not supported by fibrelmp; only "
                      "agglomerates of spheres and solid bonds")
        if not len(agg.radius):
            raise bad("has no spheres")
        if not (agg.radius > 0).all() or not np.isfinite(agg.coords).all():
            raise bad("needs finite coordinates and radii > 0")
        if (agg.contact_radius != agg.radius).any():
            raise bad("a sphere's contact radius differs from its radius, which fibrelmp's "
                      "generator does not support")
        parts, bonds = dict(g.part_materials), dict(g.bond_materials)
        part_keys = tuple(parts.get(a, "") for a in agg.part_alias)
        bond_keys = tuple(bonds.get(a, "") for a in agg.bond_alias)
        for kind, aliases, keys in (("sphere", agg.part_alias, part_keys),
                                    ("bond", agg.bond_alias, bond_keys)):
            for alias, key in zip(aliases, keys):
                if key not in materials:
                    raise bad(f"{kind} compound alias '{alias}' maps to '{key}', which is not a "
                              f"compound of the scene (MUSEN: 'No correct {'particle' if kind == 'sphere' else 'bond'} "
                              "materials have been specified')")
        n = len(agg.radius)
        pairs = agg.bond_pairs
        if len(pairs) and ((pairs < 0) | (pairs >= n)).any() or (pairs[:, 0] == pairs[:, 1]).any():
            raise bad(f"a bond joins sphere indices outside 0..{n - 1} or a sphere to itself")
        if not (agg.bond_radius > 0).all():
            raise bad("bond radii must be > 0")
        coords, radius, diameter = prepared_agglomerate(agg, g.scaling_factor)
        # a large scaling factor can overflow finite database values
        if not (np.isfinite(coords).all() and np.isfinite(radius).all() and np.isfinite(diameter).all()):
            raise bad(f"scaling by {g.scaling_factor!r} gives coordinates or radii that are not "
                      "finite numbers")
        out.append(replace(inlet, agglomerate=InletAgglomerate(
            agg.key, coords, radius, part_keys, pairs.copy(), diameter, bond_keys)))
    return out
