"""``MdemResultWriter``: GranularFrames -> a MUSEN ``.mdem`` result that MUSEN opens.

Time points are written as they come (one compressed block each, as MUSEN's simulator saves),
so memory holds one frame.  What MUSEN's simulator stores per save is stored: spheres
``coord vel angle_vel force quaternion``; solid bonds ``force`` (on the first sphere),
tangential overlap (in ``angle_vel``) and ``|total torque|``; walls their vertices (``coord``,
``quaternion``, ``angle_vel``), ``vel`` and ``force``.  Removed spheres and broken bonds get
the empty entry MUSEN writes for inactive objects, and their activity ends at the save that
found them gone.  Stress tensors are not stored: fibrelmp does not compute them (MUSEN shows
zeros, and its text export writes ``42``/``36`` zeros).

The scene message at the end: the source ``.mdem``'s own (materials, geometries, volumes,
generators, GUI data kept as they were) or, for text and dump sources, MUSEN's import of the
same scene text the text result carries; plus the simulator settings and models that ran.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from fibrelmp.granmodel import GranularFrame, GranularModel
from fibrelmp.translate.granular.models import mdem_key
from fibrelmp.translate.musen.mdem import timepoints as tp
from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter
from fibrelmp.translate.musen.scene_record import scene_record
from fibrelmp.translate.musen.writer import MusenResultWriter

SPHERE_FIELDS = tp.bit("coord", "vel", "angle_vel", "force", "quaternion")
BOND_FIELDS = tp.bit("force", "angle_vel", "total_torque")
WALL_FIELDS = tp.bit("coord", "vel", "angle_vel", "force", "quaternion")
_Q = tp.FIELDS["quaternion"][1]
_T = tp.FIELDS["temperature"][1]
_TORQUE = tp.FIELDS["total_torque"][1]


class MdemResultWriter(MusenResultWriter):
    """``add`` every frame, then ``close`` (or ``abort``); ``path`` ends in ``.mdem``."""

    format = "mdem"

    def __init__(self, model: GranularModel, path: str | os.PathLike, precision: int = 6,
                 time_interval: tuple[float, float] | None = None, *, force: bool = True):
        super().__init__(model, path, precision, time_interval, force=force)
        self.fh = self.open(self.path, "w+b")
        self.mdem = MdemWriter(self.fh)
        m = model
        # rows reserved for generated spheres count once made (a time point holds the objects
        # that exist then, as MUSEN's grows with its generators)
        first = model.plan.inlet_rows
        sets = self._id_sets()
        if first is not None:
            sets[0] = sets[0][:first]
        self.n = 1 + max(int(np.max(ids)) if len(ids) else -1 for ids in sets)
        self.sphere_ids = np.asarray(m.spheres.ids, np.int64)
        self.bond_ids = None if m.bonds is None else np.asarray(m.bonds.ids, np.int64)
        self.wall_ids = None if m.triangles is None else np.asarray(m.triangles.ids, np.int64)

    def _id_sets(self) -> list[np.ndarray]:
        m = self.model
        sets = [m.spheres.ids]
        if m.bonds is not None:
            sets.append(m.bonds.ids)
        if m.triangles is not None:
            sets.append(m.triangles.ids)
        liquid = m.liquid_bonds
        if liquid:
            sets.append(np.array([lb.id for lb in liquid], np.int64))
        return sets

    def write(self, frame: GranularFrame) -> None:
        if not self.track_activity(frame):
            return
        rows = np.asarray(frame.sphere_rows, np.int64)
        ids = self.sphere_ids[rows]
        self.n = max(self.n, 1 + int(ids.max()) if len(ids) else 0)
        if self.bond_ids is not None:            # the bonds this time point holds values of
            kept = frame.bonds_as_saved(len(self.bond_ids))
            if np.any(kept):
                self.n = max(self.n, 1 + int(self.bond_ids[kept].max()))
        values = np.zeros((self.n, tp.NCOLS))
        masks = np.zeros(self.n, np.uint32)
        values[ids, 0:3] = frame.position
        values[ids, 6:9] = frame.velocity
        values[ids, 9:12] = frame.omega
        values[ids, 18:21] = frame.sphere_force_as_saved()
        values[ids, _Q:_Q + 4] = frame.quaternion
        masks[ids] = SPHERE_FIELDS
        if frame.temperature is not None:      # a heat model ran (MUSEN saves it then)
            values[ids, _T] = frame.temperature
            masks[ids] |= tp.bit("temperature")
        if frame.stress_tensor is not None:    # MUSEN's stress tensor (granular_run.stress)
            values[ids, tp.columns("stress_tensor")] = frame.stress_tensor
            masks[ids] |= tp.bit("stress_tensor")
        if self.bond_ids is not None:
            alive = frame.bonds_as_saved(len(self.bond_ids))
            ids = self.bond_ids[alive]
            if frame.bond_force is not None:
                values[ids, 18:21] = np.asarray(frame.bond_force, np.float64)[alive]
            if frame.bond_tangential_overlap is not None:
                values[ids, 9:12] = np.asarray(frame.bond_tangential_overlap, np.float64)[alive]
            if frame.bond_torque is not None:
                values[ids, _TORQUE] = np.asarray(frame.bond_torque, np.float64)[alive]
            masks[ids] = BOND_FIELDS
        if self.wall_ids is not None:
            tri = self.model.triangles
            vert = np.asarray(tri.vertices if frame.triangle_vertices is None
                              else frame.triangle_vertices, np.float64).reshape(-1, 9)
            ids = self.wall_ids
            values[ids, 0:3] = vert[:, 0:3]
            values[ids, _Q:_Q + 3] = vert[:, 3:6]
            values[ids, 9:12] = vert[:, 6:9]
            values[ids, 6:9] = tri.velocity if frame.triangle_velocity is None else frame.triangle_velocity
            force = frame.triangle_force_as_saved()
            if force is not None:
                values[ids, 18:21] = force
            masks[ids] = WALL_FIELDS
        try:
            self.mdem.add(float(frame.time), values, masks)
        except OSError as exc:
            exc.output = self.path
            raise
        self.times.append(float(frame.time))

    def finish(self) -> None:
        self.mdem.finish(self.scene())

    def scene(self) -> Any:
        """The scene message: the source ``.mdem``'s, else MUSEN's import of the scene text."""
        source = scene_record(self.model).mdem_source
        if source is not None:
            with MdemFile(source) as mdem:
                storage = mdem.scene
            self._set_activity(storage)
            self._set_scene(storage)
        else:
            storage = self._imported_scene()
        self._set_settings(storage)
        return storage

    def _imported_scene(self) -> Any:
        from fibrelmp.translate.musen.mdem.text_import import import_text

        ids, types, rows = self._objects()
        text = self.spool / "scene.txt"
        with open(text, "w", newline="\n") as out:
            for t in (1, 9, 13, 14):
                sel = types == t
                if sel.any():
                    out.write("".join(h + "\n" for h in self._headers(t, ids[sel], rows[sel])))
            out.write(self._scene_text())
        storage, _ = import_text(text)
        # the text headers hold activity times as MUSEN's text export writes them (%g); the
        # .mdem keeps them exact, as cmusen's does
        self._set_ends(storage.info.particles)
        return storage

    def _set_activity(self, storage: Any) -> None:
        self._add_generated(storage.info.particles)
        self._set_ends(storage.info.particles)

    def _set_ends(self, particles: Any) -> None:
        """Every removed sphere's and broken bond's activity end and every liquid bond's
        (``LiquidBondActivity``), exactly."""
        liquid_ids = np.array([lb.id for lb in self.model.liquid_bonds or []], np.int64)
        for ids, end in ((self.sphere_ids, self.sphere_end), (self.bond_ids, self.bond_end),
                         (liquid_ids, self.liquid.end)):
            if ids is None or end is None:
                continue
            for i in np.flatnonzero(np.isfinite(end)).tolist():
                particles[int(ids[i])].activity_end = float(end[i])
        for i in np.flatnonzero(self.liquid.untyped).tolist():     # as cmusen's result holds it
            particles[int(liquid_ids[i])].type = 0

    def _add_generated(self, particles: Any) -> None:
        """The spheres MUSEN's generators made (rows reserved by translate/granular/inlets.py)
        as sphere objects of the scene: compound, radius and contact radius, activity start."""
        sp, first = self.model.spheres, self.model.plan.inlet_rows
        if first is None:
            return
        for r in np.flatnonzero(np.isfinite(sp.active_start[first:])) + first:
            i = int(sp.ids[r])
            while len(particles) <= i:
                particles.add()
            entry = particles[i]
            entry.type = 1
            entry.compound = self.model.materials[int(sp.material[r])].key
            entry.encoded_properties = np.array([sp.radius[r], sp.contact_radius[r]], "<f8").tobytes()
            entry.activity_start = float(sp.active_start[r])
            entry.activity_end = 1e300
        b = self.model.bonds
        if self.model.plan.inlet_layout is None or b is None:
            return
        from fibrelmp.translate.musen.mdem.objects import SOLID_BOND, encode_bond

        first_bond = min(entry[2] for entry in self.model.plan.inlet_layout)
        for r in np.flatnonzero(np.isfinite(b.active_start[first_bond:])) + first_bond:
            i = int(b.ids[r])           # a generated agglomerate's bond (frames.py gave its id)
            while len(particles) <= i:
                particles.add()
            entry = particles[i]
            entry.id, entry.type = i, SOLID_BOND
            entry.compound = self.model.materials[int(b.material[r])].key
            left, right = (int(sp.ids[k]) for k in b.pair[r])
            entry.encoded_properties = encode_bond(left, right, float(b.diameter[r]), float(b.length0[r]))
            entry.activity_start = float(b.active_start[r])
            entry.activity_end = 1e300

    def _set_scene(self, storage: Any) -> None:
        """What the run changed in a ``.mdem`` source's scene, as the text result writes it:
        materials and interactions (script material lines), domain, periodic boundaries and
        time-dependent geometry motion; version-0 geometries are saved in the current list,
        as MUSEN saves them (the old list stays, unread)."""
        from fibrelmp.translate.musen.mdem.text_export import (ACTIVE_INTERACTIONS, ACTIVE_PROPERTIES,
                                                               property_value)
        from fibrelmp.translate.musen.mdem.text_import import set_constant, set_motion, set_vector
        from fibrelmp.translate.musen.writer import _property

        m, info = self.model, storage.info
        by_key = {mat.key: k for k, mat in enumerate(m.materials)}
        db = storage.modules_data.materials_database
        for c in db.compound:
            if c.uniqueKey not in by_key:
                continue
            mat = m.materials[by_key[c.uniqueKey]]
            for pid in ACTIVE_PROPERTIES:
                want = _property(mat, pid)
                if want == want and want != property_value(c.property, pid, c.constProperty):
                    _replace_property(c.property, pid, want, set_constant)
        inter = scene_record(m).interactions
        for i in db.interaction:
            if i.compoundKey1 not in by_key or i.compoundKey2 not in by_key:
                continue
            a, b = sorted((by_key[i.compoundKey1], by_key[i.compoundKey2]))
            values = dict(inter.get((a, b), {}))
            law = m.contacts.get((a, b))
            if law is not None:
                values.update({200: law.restitution, 201: law.friction, 202: law.rolling_friction})
            for pid in ACTIVE_INTERACTIONS:
                if pid in values and values[pid] != property_value(i.property, pid):
                    _replace_property(i.property, pid, values[pid], set_constant)
        plan = m.plan
        if plan.domain is not None:
            set_vector(info.simulation_volume_min, plan.domain[0])
            set_vector(info.simulation_volume_max, plan.domain[1])
        periodic = tuple(bool(p) for p in plan.periodic)
        info.periodic_conditions_enabled = any(periodic)
        info.periodic_conditions_x, info.periodic_conditions_y, info.periodic_conditions_z = periodic
        if plan.periodic_box is not None:
            set_vector(info.periodic_conditions_min, plan.periodic_box[0])
            set_vector(info.periodic_conditions_max, plan.periodic_box[1])
        if info.version == 0:
            _geometries_v1(info)
        for geo, g in zip(info.real_geometry, m.geometries):
            if g.motion_type == 1:
                motion = geo.base_geometry.motion
                motion.Clear()
                set_motion(motion, 1, [(iv.t_begin, iv.t_end, iv.velocity, iv.centre,
                                        iv.angular_velocity) for iv in g.motion])
            elif g.motion_type in (2, 3):       # a script's GEOMETRY_MOTION_FORCE included
                motion = geo.base_geometry.motion
                motion.Clear()
                set_motion(motion, g.motion_type, [(iv.limit, int(iv.limit_max), iv.velocity, iv.centre,
                                                    iv.angular_velocity) for iv in g.force_motion])

    def _set_settings(self, storage: Any) -> None:
        m, plan = self.model, self.model.plan
        sim = storage.modules_data.simulator
        sim.end_time = plan.t_end if np.isfinite(plan.t_end) else (self.times[-1] if self.times else 0.0)
        if np.isfinite(plan.dt):
            sim.simulation_step = plan.dt
        if plan.save_every_time is not None:
            sim.saving_step = plan.save_every_time
        sim.external_acceleration.SetInParent()
        sim.external_acceleration.x, sim.external_acceleration.y, sim.external_acceleration.z = \
            (float(g) for g in plan.gravity)
        sim.simulator_type = sim.simulator_type or 1           # CPU
        sim.part_velocity_limit = plan.velocity_limit or 0.0   # as MUSEN saves it (0: none)
        if plan.variable_step is not None:
            sim.flexible_time_step = True
            sim.part_move_limit, sim.time_step_factor = plan.variable_step
        # MUSEN's SaveConfiguration: its contact-list settings (fix musen/verlet)
        sim.max_cells_number = sim.max_cells_number or 50      # DEFAULT_MAX_CELLS
        sim.verlet_dist_coeff = plan.verlet_coeff
        sim.verlet_auto_adjust = bool(plan.verlet_auto)
        if plan.stop_broken_bonds is not None:                 # MUSEN's SaveConfiguration
            storage.info.stop_criteria.types[:] = [1]
            storage.info.stop_criteria.max_broken_bonds = plan.stop_broken_bonds
        models = m.models
        if models:
            manager = storage.modules_data.model_manager
            manager.version = 1
            del manager.models[:]
            for kind in ("PP", "PW", "SB", "LB", "EF"):
                if kind not in models:
                    continue
                choice = models[kind]
                entry = manager.models.add()
                entry.key = mdem_key(choice.name)
                entry.path = choice.name
                entry.params = _params_text(choice.parameters)
                for later in (c for c in m.later_models if c.kind == kind):   # act after it
                    entry = manager.models.add()
                    entry.key, entry.path = mdem_key(later.name), later.name
                    entry.params = _params_text(later.parameters)
                if kind == "SB":    # the later SB models, which act after it (cmusen's order)
                    for law in plan.then_bond_laws:
                        entry = manager.models.add()
                        entry.key, entry.path = mdem_key(law.model), law.model
                        entry.params = ("".join(f"{k} {v:g} " for k, v in law.parameters.items())
                                        if law.parameters else
                                        f"CONSIDER_BREAKAGE {law.breakage:g} " + (
                                            f"MAX_DAMP_RATIO {law.max_damp_ratio:g} "
                                            if law.form == "kelvin" else ""))
            manager.connected_pp_contact = bool(plan.contacts_between_bonded)




def _params_text(params: dict[str, float]) -> str:
    """A model's parameters as MUSEN stores them ("NAME value " each): %g, or every digit
    where %g would change the value (a seed, a fine viscosity)."""
    return "".join(f"{k} {v:g} " if float(f"{v:g}") == v else f"{k} {v!r} " for k, v in params.items())


def _replace_property(props: Any, pid: int, value: float, set_constant) -> None:
    """A TP property's value as one constant correlation (``SetPropertyValue``)."""
    for prop in props:
        if prop.propertyType == pid:
            set_constant(prop, pid, value)
            return
    set_constant(props.add(), pid, value)


def _geometries_v1(info: Any) -> None:
    """Version-0 geometries and analysis volumes in the current lists (``FlushToStorage``)."""
    from fibrelmp.translate.musen.mdem.text_export import geometries, volumes
    from fibrelmp.translate.musen.mdem.text_import import relevant_sizes, set_motion, set_vector

    del info.real_geometry[:]
    for old, geo in zip(info.real_geometry_v0, geometries(info)):
        new = info.real_geometry.add()
        base = new.base_geometry
        base.name, base.key, base.shape = geo["name"], geo["key"], old.type
        set_motion(base.motion, geo["motion_type"], geo["intervals"])
        if old.HasField("color"):
            base.color.CopyFrom(old.color)
        if old.HasField("rotation"):
            base.rotation.CopyFrom(old.rotation)
        base.sizes.extend(old.props)
        base.scaling = 1.0
        new.planes.extend(geo["planes"])
        set_vector(new.free_motion, geo["free"])
        new.mass = geo["mass"]
        new.rotate_around_center = bool(geo["rotate"])
    del info.analysis_volume[:]
    for vol in volumes(info):
        new = info.analysis_volume.add()
        base = new.base_geometry
        base.name, base.key, base.shape = vol["name"], vol["key"], vol["shape"]
        base.color.r, base.color.g, base.color.b, base.color.a = vol["colour"]
        base.sizes.extend(relevant_sizes(vol["shape"], vol["sizes"]))
        base.scaling = vol["scaling"]
        rot = vol["rotation"]
        for row, msg in enumerate((base.rotation.v1, base.rotation.v2, base.rotation.v3)):
            set_vector(msg, rot[3 * row:3 * row + 3])
        set_motion(base.motion, vol["motion_type"], vol["intervals"])
        for tri in vol["triangles"]:
            t = new.triangles.add()
            set_vector(t.vert1, tri[0:3])
            set_vector(t.vert2, tri[3:6])
            set_vector(t.vert3, tri[6:9])
    info.version = 1
