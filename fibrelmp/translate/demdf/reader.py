"""DEMDF reader: a JSON DEM description (nicorivas/demdf, 2015) as BOS reads it.

BOS (the event-driven hard-sphere code, the format's only user) is the reference for every
field's meaning; fibrelmp runs the description as frictionless soft (Hertz) spheres.  See
docs/demdf.md for the accepted layout, the choices made and the deviations from BOS.

``read`` gives a runnable GranularModel (kind "demdf"); ``read_snapshot`` reads a snapshot a
run wrote (BOS's or fibrelmp's ``<filename>_<saveCount>.json``) without asking it to be
runnable.  ``model.origin`` (a ``DemdfDocument``) keeps the parsed document and what the snapshot
writer needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fibrelmp.granmodel import ContactLaw, GranularModel, Material, Plane, Spheres
from fibrelmp.sanity import close_pairs
from fibrelmp.units import DIMENSIONLESS
from fibrelmp.translate.demdf import contact as hertz
from fibrelmp.translate.json_doc import JsonDoc, describe, load_json
from fibrelmp.translate.demdf.plan import Output, PlanMixin
from fibrelmp.translate.demdf.record import DemdfDocument

DEFAULT_RADIUS = 0.5          # BOS hard-codes this radius
DEFAULT_MASS = 1.0
MAX_OVERLAP = 0.01            # peak overlap / radius at the fastest approach
STEPS_PER_CONTACT = 50
_LAYOUT = {3: "[x, y, z, vx, vy, vz, type]", 2: "[x, y, vx, vy, type]"}
_VECTOR = {3: "[x, y, z]", 2: "[x, y]"}
_EXTENSION_KEYS = ("youngsModulus", "poissonRatio", "maxOverlap", "stepsPerContact")
_KNOWN_KEYS = ("fileFormat", "fileFormatVersion", "name", "dimensionality", "time", "timeEnd",
               "timeStep", "timeStepCount", "timeStepCountEnd", "eventCount", "eventCountEnd",
               "output", "domain", "bodyForce", "objectTypes", "objects", "interactions",
               "particleRadius", "fibrelmp")
# "name": a label only (the schema allows any key; fibrelmp's own DEMDF target names each
# type by its MUSEN material), read for nothing
_PARTICLE_TYPE_KEYS = ("type", "id", "name", "radius", "mass", "restitutionCoefficient")
_WALL_TYPE_KEYS = ("type", "id", "name", "restitutionCoefficient")
_INTERACTION_KEYS = ("name", "objectTypes")
_OBJECT_KEYS = ("particles", "walls")
_WALL_KEYS = ("normal", "point", "objectType", "typename")


def read(path: str | Path, time_end: float | None = None, steps: int | None = None,
         save_every: float | int | str | None = None) -> GranularModel:
    """Read a DEMDF simulation input.  ``time_end`` (absolute time) and ``steps`` (time steps
    of the integration step) replace the document's end; ``save_every`` replaces its save
    period (a float is a time, an int a number of time steps)."""
    path = Path(path)
    with np.errstate(all="ignore"):     # extreme numbers are reported, not warned about
        return _Reader(path, load_json(path, "DEMDF file"), snapshot=False).build(
            time_end=time_end, steps=steps, save_every=save_every)


def read_snapshot(path: str | Path) -> GranularModel:
    """Read a DEMDF snapshot (or any DEMDF document) as a model, without the checks that
    only matter for running it (an end time still ahead, not overwriting itself)."""
    path = Path(path)
    with np.errstate(all="ignore"):
        return _Reader(path, load_json(path, "DEMDF file"), snapshot=True).build()


@dataclass
class _ParticleType:
    position: int        # index in objectTypes
    material: int        # index in the model's materials
    radius: float
    mass: float
    restitution: float | None


class _Reader(PlanMixin):
    def __init__(self, path: Path, doc: Any, snapshot: bool):
        self.path, self.doc, self.snapshot = path, doc, snapshot
        self.j = JsonDoc(path)
        self.notes: list[tuple[str, str]] = []
        self.materials: list[Material] = []

    def warn(self, kind: str, message: str) -> None:
        self.notes.append((kind, message))

    # ------------------------------------------------------------------ document
    def build(self, time_end: float | None = None, steps: int | None = None,
              save_every: float | int | str | None = None) -> GranularModel:
        doc = self._header()
        self.j.check_keys(doc, "", (), _KNOWN_KEYS)
        self.dim = self._dimensionality(doc)
        out = self._output(doc)
        if not self.snapshot:
            self._refuse_snapshot(doc, out)
        self.t0 = self.j.number(doc.get("time", 0.0), "time")
        domain = self._domain(doc)
        gravity = self._vector3(doc["bodyForce"], "bodyForce") if "bodyForce" in doc else np.zeros(3)
        ptypes, type_of_position = self._object_types(doc)
        objects = self.j.obj(doc.get("objects", {}), "objects")
        self.j.check_keys(objects, "objects", ("objects",), _OBJECT_KEYS)
        particle_kind, wall_kind = self._interactions(doc, bool(objects.get("walls")))
        planes = self._walls(objects.get("walls", []), type_of_position)
        table, types, rows, source_file = self._particles(objects, ptypes)
        spheres = self._spheres(table, types, ptypes)
        self.rmax = float(spheres.radius.max(initial=DEFAULT_RADIUS))
        ext = self._extension(doc)
        self._check_placement(spheres, planes, domain)
        if gravity.any() and any(t.mass != 1.0 for t in ptypes):
            self.warn("demdf", "bodyForce is applied as an acceleration, as BOS does (the DEMDF "
                      "text calls it a force; the two differ for masses other than 1)")
        contacts, dt_need = self._contacts(spheres, ptypes, planes, gravity, domain,
                                           particle_kind, wall_kind, ext)
        bad = [law.youngs_eff for law in contacts.values() if not 0 < law.youngs_eff < math.inf]
        if bad or not 0 < dt_need < math.inf:
            self.j.fail("", "the sizes, masses and speeds in the document are too extreme to "
                        f"choose a contact stiffness and time step (E* {bad[0] if bad else '-'}, "
                        f"time step {dt_need:g})")
        plan = self._plan(doc, out, dt_need, gravity, domain, time_end, steps, save_every)
        model = GranularModel(source=self.path, kind="demdf", materials=self.materials,
                              contacts=contacts, spheres=spheres, plan=plan, planes=planes,
                              units=DIMENSIONLESS.name)
        model.origin = DemdfDocument(
            document=doc, dimensionality=self.dim, particle_rows=rows,
            particles_file=source_file, output_location=out.location,
            filename=out.filename, save_count=out.save_count,
            file_time_step=self.file_dt, substeps=self.substeps, time_step_count=self.step0)
        model.warnings.extend(self.notes)
        return model

    def _header(self) -> dict:
        doc = self.doc
        if not isinstance(doc, dict):
            self.j.fail("", f"a DEMDF document is a JSON object {{...}}, got {describe(doc)}")
        if "$schema" in doc:
            self.j.fail("", "this is a JSON Schema (the DEMDF specification), not a DEMDF document")
        if "fileFormat" not in doc:
            if "particles" in doc:
                self.j.fail("", "this is a DEMDF particles file ({\"particles\": [...]}), not a "
                            "stand-alone simulation: a simulation input refers to it with "
                            f"\"objects\": {{\"particles\": \"{self.path.name}\"}}; run that input "
                            "instead")
            self.j.fail("fileFormat", "missing: a DEMDF document starts with \"fileFormat\": \"demdf\"")
        if doc["fileFormat"] != "demdf":
            self.j.fail("fileFormat", f"must be \"demdf\", got {describe(doc['fileFormat'])}")
        if "fileFormatVersion" in doc:
            version = self.j.number(doc["fileFormatVersion"], "fileFormatVersion")
            if version != 0.01:
                self.warn("demdf", f"fileFormatVersion {version:g}: only 0.01 (2015) is known; "
                          "reading it as 0.01")
        if "name" in doc:
            self.j.string(doc["name"], "name")
        return doc

    def _dimensionality(self, doc: dict) -> int:
        dim = self.j.integer(doc.get("dimensionality", 3), "dimensionality")
        if dim not in (2, 3):
            self.j.fail("dimensionality", f"must be 2 or 3, got {dim}")
        return dim

    def _vector(self, value: Any, where: str) -> np.ndarray:
        return self.j.vector(value, self.dim, where, f"{_VECTOR[self.dim]} ({self.dim}D document)")

    def _vector3(self, value: Any, where: str) -> np.ndarray:
        v = self._vector(value, where)
        return np.append(v, 0.0) if self.dim == 2 else v

    def _domain(self, doc: dict) -> tuple[np.ndarray, np.ndarray] | None:
        if "domain" not in doc:
            self.warn("demdf", "no domain: the simulation box is sized from the particles and walls")
            return None
        corners = self.j.array(doc["domain"], "domain")
        if len(corners) != 2:
            self.j.fail("domain", f"expected two opposite corners [{_VECTOR[self.dim]}, "
                        f"{_VECTOR[self.dim]}], got {describe(corners)}")
        a, b = (self._vector3(c, f"domain[{i}]") for i, c in enumerate(corners))
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        flat = (hi - lo)[: self.dim] <= 0
        if flat.any():
            axis = "xyz"[int(np.flatnonzero(flat)[0])]
            self.j.fail("domain", f"the two corners have the same {axis}: the domain is flat")
        return lo, hi

    def _refuse_snapshot(self, doc: dict, out: Output) -> None:
        target = (self.path.parent / f"{out.filename}_{out.save_count}.json").resolve()
        if target == self.path.resolve():
            time = doc.get("time", 0)
            self.j.fail("", f"this file is a DEMDF snapshot, not a stand-alone simulation input: "
                        f"it is output '{out.filename}' number {out.save_count} (time {time}) of a "
                        "BOS or fibrelmp run, and running it would overwrite it with its own first "
                        "snapshot.  To continue from this state, copy it to a new name and run the "
                        "copy")

    # ------------------------------------------------------------------ types and interactions
    def _object_types(self, doc: dict) -> tuple[list[_ParticleType], dict[int, int]]:
        """Particle types in BOS order (position among the particle entries); material index
        of every wall entry by its position in objectTypes."""
        entries = self.j.array(doc.get("objectTypes", []), "objectTypes")
        ptypes: list[_ParticleType] = []
        walls: dict[int, int] = {}
        for i, entry in enumerate(entries):
            where = f"objectTypes[{i}]"
            entry = self.j.obj(entry, where)
            kind = self.j.string(entry.get("type"), f"{where}.type") if "type" in entry else None
            ident = self.j.integer(entry["id"], f"{where}.id") if "id" in entry else None
            if kind not in ("particle", "wall"):
                self.warn("demdf", f"{where}: type {describe(kind)} is neither \"particle\" nor "
                          "\"wall\"; ignored")
                continue
            self.j.check_keys(entry, where, ("objectTypes", i),
                              _PARTICLE_TYPE_KEYS if kind == "particle" else _WALL_TYPE_KEYS)
            self.materials.append(Material(key=str(ident if ident is not None else i),
                                           name=f"{kind} {ident if ident is not None else i}"))
            material = len(self.materials) - 1
            if kind == "wall":
                walls[i] = material
                if "restitutionCoefficient" in entry:
                    self._restitution(entry["restitutionCoefficient"], f"{where}.restitutionCoefficient")
                continue
            index = len(ptypes)
            if ident is not None and ident != index:
                self.warn("demdf", f"{where} has id {ident} but is particle type {index}: particles "
                          "name their type by its position among the particle objectTypes, as "
                          "BOS counts, not by id")
            if "radius" in entry:
                radius = self.j.number(entry["radius"], f"{where}.radius", positive=True)
                if radius != DEFAULT_RADIUS:
                    self.warn("demdf", f"{where}.radius {radius:g}: BOS ignores it and always "
                              f"uses {DEFAULT_RADIUS}; fibrelmp uses {radius:g}")
            else:
                radius = DEFAULT_RADIUS
                self.warn("demdf", f"{where} has no radius: using {DEFAULT_RADIUS} (BOS's fixed radius)")
            if "mass" in entry:
                mass = self.j.number(entry["mass"], f"{where}.mass", positive=True)
            else:
                mass = DEFAULT_MASS
                self.warn("demdf", f"{where} has no mass: using {DEFAULT_MASS:g} (BOS's elastic "
                          "collisions do not need one)")
            e = None
            if "restitutionCoefficient" in entry:
                e = self._restitution(entry["restitutionCoefficient"], f"{where}.restitutionCoefficient")
            ptypes.append(_ParticleType(i, material, radius, mass, e))
        return ptypes, walls

    def _restitution(self, value: Any, where: str) -> float:
        e = self.j.number(value, where)
        if not 0 < e <= 1:
            self.j.fail(where, f"a restitution coefficient must be in (0, 1], got {value!r}")
        return e

    def _interactions(self, doc: dict, walls: bool) -> tuple[str, str]:
        if "interactions" not in doc:
            self.warn("demdf", "no interactions: elastic collisions, as BOS assumes")
            return "particleElastic", "wallElastic"
        particle = wall = None
        for i, entry in enumerate(self.j.array(doc["interactions"], "interactions")):
            where = f"interactions[{i}]"
            entry = self.j.obj(entry, where)
            name = self.j.string(entry.get("name"), f"{where}.name")
            if name in ("particleElastic", "particleInelastic", "wallElastic", "wallInelastic"):
                self.j.check_keys(entry, where, ("interactions", i), _INTERACTION_KEYS)
            if name in ("particleElastic", "particleInelastic"):
                if particle is not None and particle != name:
                    self.warn("demdf", f"{where}: a second particle interaction; as in BOS the last "
                              f"one ({name}) applies to every particle pair")
                particle = name
            elif name in ("wallElastic", "wallInelastic"):
                if wall is not None and wall != name:
                    self.warn("demdf", f"{where}: a second wall interaction; as in BOS the last one "
                              f"({name}) applies to every wall")
                wall = name
            else:
                self.warn("demdf", f"{where}: interaction {name!r} is not one BOS knows "
                          "(particleElastic/Inelastic, wallElastic/Inelastic); ignored")
        if particle is None:
            self.warn("demdf", "no particleElastic/particleInelastic interaction: elastic particle "
                      "collisions")
        if wall is None and walls:
            self.warn("demdf", "no wallElastic/wallInelastic interaction: elastic wall collisions")
        return particle or "particleElastic", wall or "wallElastic"

    # ------------------------------------------------------------------ objects
    def _walls(self, walls: Any, wall_types: dict[int, int]) -> list[Plane]:
        planes = []
        shared: dict[str, int] = {}
        for i, wall in enumerate(self.j.array(walls, "objects.walls")):
            where = f"objects.walls[{i}]"
            wall = self.j.obj(wall, where)
            self.j.check_keys(wall, where, ("objects", "walls", i), _WALL_KEYS)
            for key in ("normal", "point"):
                if key not in wall:
                    self.j.fail(where, f"a wall needs \"normal\" and \"point\" ({_VECTOR[self.dim]}); "
                                f"\"{key}\" is missing")
            normal = self._vector3(wall["normal"], f"{where}.normal")
            point = self._vector3(wall["point"], f"{where}.point")
            length = float(np.linalg.norm(normal))
            if not 0 < length < math.inf:
                self.j.fail(f"{where}.normal", f"the normal's length is {length:g}")
            if abs(length - 1) > 1e-9:
                self.warn("demdf", f"{where}.normal has length {length:g}; normalised")
            if "objectType" in wall:
                k = self.j.integer(wall["objectType"], f"{where}.objectType")
                if k not in wall_types:
                    self.j.fail(f"{where}.objectType", f"{k} is not a wall entry of objectTypes (walls "
                                "name their type by its position in objectTypes; wall entries: "
                                f"{sorted(wall_types) or 'none'})")
                material = wall_types[k]
            else:
                label = "wall"
                if "typename" in wall:
                    label = self.j.string(wall["typename"], f"{where}.typename")
                if label not in shared:
                    self.materials.append(Material(key=label, name=f"wall {label}"))
                    shared[label] = len(self.materials) - 1
                material = shared[label]
            planes.append(Plane(normal=normal / length, point=point, material=material))
        return planes

    def _particles(self, objects: dict, ptypes: list[_ParticleType]
                   ) -> tuple[np.ndarray, np.ndarray, list, str | None]:
        ncols = 2 * self.dim + 1
        layout = f"{_LAYOUT[self.dim]} ({self.dim}D document)"
        hint = ""
        if self.dim == 2:
            hint = "; 7 entries is the 3D layout - is dimensionality right?"
        value = objects.get("particles", [])
        j, where, source = self.j, "objects.particles", None
        if isinstance(value, str):
            source = value
            file = self.path.parent / value
            if not file.exists():          # a folder: load_json says "is a directory"
                self.j.fail(where, f"particles file {value!r} not found (looked for {file}; the "
                            "name is relative to the input file's folder)")
            sub = load_json(file, "DEMDF particles file")
            j, where = JsonDoc(file), "particles"
            if not isinstance(sub, dict) or "particles" not in sub:
                j.fail("", "a DEMDF particles file is an object {\"particles\": [...]}, got "
                       f"{describe(sub) if not isinstance(sub, dict) else 'no particles key'}")
            j.check_keys(sub, "", (), ("particles",))
            value = sub["particles"]
        elif not isinstance(value, list):
            self.j.fail(where, f"expected an array of particles or a particles file name, got "
                        f"{describe(value)}")
        table = j.table(value, where, ncols, layout, hint)
        types = table[:, -1] if len(table) else np.zeros(0)
        bad = types != np.round(types)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            j.fail(f"{where}[{i}][{ncols - 1}]", f"the objectType index must be an integer, got "
                   f"{value[i][-1]!r}")
        bad = (types < 0) | (types >= len(ptypes))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            j.fail(f"{where}[{i}][{ncols - 1}]", f"objectType {int(types[i])} does not exist: the "
                   f"document has {len(ptypes)} particle objectType(s); particles name their type "
                   "by its position among the particle entries of objectTypes")
        if not len(table) and not self.snapshot:
            self.j.fail("objects.particles", "no particles: nothing to simulate")
        return table, types.astype(np.int64), value, source

    def _spheres(self, table: np.ndarray, types: np.ndarray, ptypes: list[_ParticleType]) -> Spheres:
        n, d = len(table), self.dim
        pos, vel = np.zeros((n, 3)), np.zeros((n, 3))
        if n:
            pos[:, :d], vel[:, :d] = table[:, :d], table[:, d:2 * d]
        radius = np.array([t.radius for t in ptypes])[types] if n else np.zeros(0)
        mass = np.array([t.mass for t in ptypes])[types] if n else np.zeros(0)
        material = np.array([t.material for t in ptypes], dtype=np.int64)[types] if n else \
            np.zeros(0, dtype=np.int64)
        quat = np.zeros((n, 4))
        quat[:, 0] = 1.0
        return Spheres(ids=np.arange(n, dtype=np.int64), material=material, radius=radius,
                       contact_radius=radius.copy(), mass=mass, position=pos, velocity=vel,
                       omega=np.zeros((n, 3)), quaternion=quat,
                       active_start=np.full(n, self.t0), active_end=np.full(n, np.inf))

    def _check_placement(self, s: Spheres, planes: list[Plane],
                         domain: tuple[np.ndarray, np.ndarray] | None) -> None:
        if not s.count:
            return
        report = self.warn if self.snapshot else (lambda kind, msg: self.j.fail("", msg))
        if domain is not None:
            outside = ((s.position < domain[0]) | (s.position > domain[1]))[:, : self.dim].any(axis=1)
            if outside.any():
                i = int(np.flatnonzero(outside)[0])
                report("demdf", f"objects.particles[{i}]: the centre {s.position[i, :self.dim].tolist()} "
                       f"is outside the domain ({outside.sum()} particle(s) are)")
        for w, plane in enumerate(planes):
            dist = (s.position - plane.point) @ plane.normal
            behind = dist < 0
            if behind.any():
                i = int(np.flatnonzero(behind)[0])
                report("demdf", f"objects.particles[{i}] is behind objects.walls[{w}] (wall normals "
                       f"point into the domain; {behind.sum()} particle(s) are behind it)")
            touching = dist < s.radius
            if touching.any():
                worst = float(np.max((s.radius - dist)[touching] / s.radius[touching]))
                self.warn("demdf", f"{touching.sum()} particle(s) overlap objects.walls[{w}] at the "
                          f"start (up to {100 * worst:.3g}% of the radius)")
        self._check_overlaps(s)

    def _check_overlaps(self, s: Spheres) -> None:
        try:
            # any finite coordinates (a bare cKDTree overflows beyond ~1e154)
            pairs = close_pairs(s.position, 2 * float(s.radius.max()))
        except ImportError:             # pragma: no cover - scipy comes with MDAnalysis
            return
        if not len(pairs):
            return
        gap = np.linalg.norm(s.position[pairs[:, 0]] - s.position[pairs[:, 1]], axis=1) \
            - s.radius[pairs[:, 0]] - s.radius[pairs[:, 1]]
        over = gap < -1e-9 * float(s.radius.min())
        if over.any():
            i, k = pairs[np.argmin(gap)]
            self.warn("demdf", f"{over.sum()} particle pair(s) overlap at the start; the worst is "
                      f"objects.particles[{i}] and [{k}] by {-gap.min():.3g}")

    # ------------------------------------------------------------------ physics
    def _extension(self, doc: dict) -> dict[str, float]:
        ext = self.j.obj(doc.get("fibrelmp", {}), "fibrelmp")
        self.j.check_keys(ext, "fibrelmp", ("fibrelmp",), _EXTENSION_KEYS)
        out: dict[str, float] = {}
        if "youngsModulus" in ext:
            out["youngs"] = self.j.number(ext["youngsModulus"], "fibrelmp.youngsModulus", positive=True)
        out["poisson"] = self.j.number(ext.get("poissonRatio", 0.3), "fibrelmp.poissonRatio", minimum=0)
        if out["poisson"] >= 0.5:
            self.j.fail("fibrelmp.poissonRatio", f"must be below 0.5, got {out['poisson']!r}")
        out["overlap"] = self.j.number(ext.get("maxOverlap", MAX_OVERLAP), "fibrelmp.maxOverlap",
                                       positive=True)
        if out["overlap"] >= 0.5:
            self.j.fail("fibrelmp.maxOverlap", f"is a fraction of the radius below 0.5, got {out['overlap']!r}")
        out["steps"] = self.j.integer(ext.get("stepsPerContact", STEPS_PER_CONTACT),
                                      "fibrelmp.stepsPerContact", minimum=10)
        return out

    def _contacts(self, s: Spheres, ptypes: list[_ParticleType], planes: list[Plane],
                  gravity: np.ndarray, domain, particle_kind: str, wall_kind: str,
                  ext: dict[str, float]) -> tuple[dict[tuple[int, int], ContactLaw], float]:
        """One ContactLaw per particle-type pair and per particle type x wall material, and the
        integration step that resolves the fastest contact."""
        if domain is not None:
            extent = domain[1] - domain[0]
        else:
            points = np.vstack([s.position] + [p.point[None, :] for p in planes])
            extent = points.max(axis=0) - points.min(axis=0) + 2 * float(s.radius.max(initial=0))
        bounds = hertz.speed_bounds(s.velocity, gravity, extent)
        per_type = [bounds[s.material == t.material] for t in ptypes]
        partners: list[hertz.Partner] = []
        for a, ta in enumerate(ptypes):
            for b in range(a, len(ptypes)):
                tb = ptypes[b]
                e = 1.0
                if particle_kind == "particleInelastic":
                    e = 0.5 * (self._needed_e(ta, particle_kind) + self._needed_e(tb, particle_kind))
                key = (min(ta.material, tb.material), max(ta.material, tb.material))
                partners.append(hertz.Partner(
                    key, ta.mass * tb.mass / (ta.mass + tb.mass),
                    ta.radius * tb.radius / (ta.radius + tb.radius), min(ta.radius, tb.radius),
                    hertz.pair_speed(per_type[a], per_type[b] if b != a else per_type[a]), e,
                    f"particle types {a}-{b}"))
            for wm in sorted({p.material for p in planes}):
                e = self._needed_e(ta, wall_kind) if wall_kind == "wallInelastic" else 1.0
                key = (min(ta.material, wm), max(ta.material, wm))
                partners.append(hertz.Partner(key, ta.mass, ta.radius, ta.radius,
                                              hertz.pair_speed(per_type[a], None), e,
                                              f"particle type {a}-{self.materials[wm].name}"))
        fastest = max((p.speed for p in partners), default=0.0)
        if fastest <= 0:
            fastest = 1.0
            if s.count:
                self.warn("physics", "nothing moves and there is no bodyForce: the contact "
                          "stiffness is chosen for an approach speed of 1")
        if "youngs" in ext:
            self._materials_youngs(ext)
        contacts: dict[tuple[int, int], ContactLaw] = {}
        timing: list[tuple[bool, float, float, str]] = []
        for p in partners:
            possible = p.speed > 0           # 0: no such contact can happen (no particles)
            speed = p.speed if possible else fastest
            if "youngs" in ext:
                e_star = ext["youngs"] / (2.0 * (1.0 - ext["poisson"] ** 2))
            else:
                e_star = hertz.modulus_for_overlap(p.m_eff, p.r_eff, speed, ext["overlap"] * p.r_min)
            law = ContactLaw(youngs_eff=e_star, shear_eff=0.0, restitution=p.restitution)
            old = contacts.get(p.key)
            if old is None or old.youngs_eff < e_star:
                contacts[p.key] = law
        for p in partners:
            # with the law that runs (the stiffest of a material pair's): the contact time
            # ``fibrelmp check`` prints (granmodel.contact_time) is this same figure
            possible = p.speed > 0
            speed = p.speed if possible else fastest
            e_star = contacts[p.key].youngs_eff
            ratio = hertz.peak_overlap(p.m_eff, p.r_eff, e_star, speed) / p.r_min
            timing.append((possible, hertz.contact_time(p.m_eff, p.r_eff, e_star, speed), ratio,
                           p.label))
        real = [t for t in timing if t[0]] or timing     # contacts that can happen
        t_min = min((t[1] for t in real), default=1.0)
        worst = max(((t[2], t[3]) for t in real), default=(0.0, ""))
        if "youngs" in ext and worst[0] > ext["overlap"] * (1 + 1e-9):
            self.warn("physics", f"fibrelmp.youngsModulus {ext['youngs']:g} lets {worst[1]} overlap "
                      f"by up to {100 * worst[0]:.3g}% of the radius at the fastest approach")
        self.contact_note = (t_min, worst)
        return contacts, t_min / ext["steps"]

    def _materials_youngs(self, ext: dict[str, float]) -> None:
        for m in self.materials:
            m.youngs, m.poisson = ext["youngs"], ext["poisson"]

    def _needed_e(self, t: _ParticleType, kind: str) -> float:
        if t.restitution is None:
            self.j.fail(f"objectTypes[{t.position}]", f"no restitutionCoefficient, which {kind} needs")
        return t.restitution
