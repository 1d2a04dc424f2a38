"""``.mdem`` scenes as the neutral GranularModel (run inputs), and their time points as
GranularFrames (``MdemReader``)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Reader
from fibrelmp.granmodel import GranularFrame, GranularModel
from fibrelmp.translate.musen.scene_record import scene_record

if TYPE_CHECKING:
    from fibrelmp.translate.musen.mdem.document import MdemFile


def read_scene(path: str | os.PathLike, mdem: MdemFile | None = None) -> GranularModel:
    """The scene of a ``.mdem`` file at its first saved time point, where MUSEN's simulator
    starts (it clears every later time point before simulating).  The scene is written as
    MUSEN's text export (17 digits: every double exactly) and read by the text scene reader,
    so both forms of a scene give the same model.  ``mdem``: the file already open."""
    from fibrelmp.translate.musen.mdem.document import MdemFile

    if mdem is None:
        with MdemFile(path) as opened:
            return read_scene(path, opened)
    from fibrelmp.translate.musen import scene
    from fibrelmp.translate.musen.mdem.fields import check_settings
    from fibrelmp.translate.musen.mdem.generators import generation_schedule, read_inlets
    from fibrelmp.translate.musen.mdem.text_export import export

    path = Path(path)
    with tempfile.TemporaryDirectory(prefix="fibrelmp-mdem-") as tmp:
        ignored = check_settings(mdem.scene, path)
        text = Path(tmp) / f"{path.stem}.txt"
        with open(text, "w", newline="\n") as out:
            export(mdem, out, precision=17, spool_dir=Path(tmp), times_limit=1)
        try:
            model = scene.read(text)
        except InputError as exc:
            where = f" (its text form, line {exc.line})" if exc.line else ""
            raise InputError(path, None, f"{exc.message}{where}") from None
        _settings(model, mdem.scene.modules_data)
        _refused_settings(model, mdem.scene)
        # inlets: checked here, scheduled for the job's step and end time by the translation
        inlets = model.plan.inlets = read_inlets(mdem.scene, path)
        model.plan.inlet_schedule = (lambda dt, t_end: generation_schedule(
            [i.generator for i in inlets], dt, t_end, source=str(path)))
    model.warnings.extend(ignored)
    model.source = path
    scene_record(model, keep=True).mdem_source = path
    return model


def _settings(model: GranularModel, modules) -> None:
    """What MUSEN loads with a file besides the scene: the simulator's step, saving step, end
    time and gravity (a job script may set them again) and the selected models."""
    from fibrelmp.translate.musen.script_parse import MUSEN_MODELS, MusenModelSpec

    sim = modules.simulator
    plan = model.plan
    if sim.simulation_step > 0:
        plan.dt = sim.simulation_step
    if sim.saving_step > 0:
        plan.save_every_time = sim.saving_step
    if sim.end_time > 0:
        plan.t_end = sim.end_time
    if sim.max_cells_number:               # CBaseSimulator::LoadConfiguration reads them so
        plan.verlet_coeff = sim.verlet_dist_coeff
        plan.verlet_auto = bool(sim.verlet_auto_adjust)
    if sim.part_velocity_limit > 0:        # MUSEN: 0 (the default) is no limit
        plan.velocity_limit = sim.part_velocity_limit
    if modules.HasField("model_manager"):  # CModelManager::LoadConfiguration (else its true)
        plan.contacts_between_bonded = bool(modules.model_manager.connected_pp_contact)
    if modules.HasField("simulator"):
        g = sim.external_acceleration
        plan.gravity = np.array([g.x, g.y, g.z])
        scene_record(model, keep=True).gravity_set = True
    manager = modules.model_manager
    # CModelManager::LoadConfiguration: version 0 keeps the per-kind slots (the heat slot is
    # refused in fields.py), later versions the list; an entry without a key is empty
    entries = (list(manager.models) if manager.version else
               [manager.pp_model, manager.pw_model, manager.sb_model, manager.lb_model, manager.ef_model])
    specs = []
    for entry in entries:
        name = Path(entry.path.replace("\\", "/")).stem          # a custom model's library path
        if not entry.key or not name:
            continue
        kind = next((k for k, names in MUSEN_MODELS.items() if name in names), name[5:7])
        specs.append(MusenModelSpec(name=name, params=entry.params, kind=kind, line=0))
    if specs:
        scene_record(model, keep=True).file_models = specs


def _refused_settings(model: GranularModel, storage) -> None:
    """Simulator settings of the file that fibrelmp does not simulate (MUSEN's
    ``CBaseSimulator::LoadConfiguration``): kept by name, refused when simulated; and the
    moving periodic box (``SPBC::vVel``), which it does."""
    refused = scene_record(model, keep=True).refused
    sim = storage.modules_data.simulator
    if sim.flexible_time_step:
        if sim.part_move_limit > 0 and sim.time_step_factor > 0:
            model.plan.variable_step = (sim.part_move_limit, sim.time_step_factor)
        else:
            refused["flexible_time_step"] = (
                f"MUSEN's variable time step with part_move_limit {sim.part_move_limit:g} and "
                f"time_step_factor {sim.time_step_factor:g}: both must be > 0 (MUSEN's step "
                "would become 0 or nan)")
    criteria = storage.info.stop_criteria
    if any(t not in (0, 1) for t in criteria.types):                # 0 NONE, 1 BROKEN_BONDS
        refused["stop_criteria"] = (f"stop criterion types {sorted(set(criteria.types))}: MUSEN "
                                    "knows 0 (NONE) and 1 (BROKEN_BONDS) only")
    elif 1 in criteria.types:
        model.plan.stop_broken_bonds = int(criteria.max_broken_bonds)
    v = storage.info.periodic_conditions_vel
    if storage.info.periodic_conditions_enabled and (v.x, v.y, v.z) != (0.0, 0.0, 0.0):
        model.plan.periodic_velocity = np.array([v.x, v.y, v.z])    # fix musen/pbc/move


class MdemReader(Reader):
    """A ``.mdem`` file through the abstract Reader: ``read()`` the scene (``read_scene``),
    iterating its saved time points as ``GranularFrame``s, one block in memory at a time
    (spheres and bonds with an empty entry, MUSEN's mark of inactive objects, are absent /
    not alive); ``MdemFrames`` gives the frames of an open file by number."""

    format = "mdem"
    what = "MUSEN .mdem file"

    def read(self) -> GranularModel:
        return read_scene(self.path)

    def __iter__(self) -> Iterator[GranularFrame]:
        from fibrelmp.translate.musen.mdem.document import MdemFile

        with MdemFile(self.path) as mdem:
            frames = MdemFrames(mdem)
            for step, (time, values, masks) in enumerate(mdem.time_points()):
                yield frames.frame(step, time, values, masks)


class MdemFrames:
    """The time points of an open ``MdemFile`` as ``GranularFrame``s: ``count()``, and
    ``at(i)``, which decodes only the block holding time point ``i``."""

    def __init__(self, mdem: MdemFile):
        from fibrelmp.translate.musen.mdem.objects import SOLID_BOND, SPHERE, WALL, read_objects

        self.mdem = mdem
        obj = read_objects(mdem.info, mdem.version, mdem.path)
        self.spheres = obj.ids[obj.types == SPHERE]
        self.bonds = obj.ids[obj.types == SOLID_BOND]
        self.walls = obj.ids[obj.types == WALL]

    def count(self) -> int:
        return self.mdem.count()

    def at(self, index: int) -> GranularFrame:
        return self.frame(index, *self.mdem.time_point(index))

    def frame(self, step: int, time: float, values: np.ndarray, masks: np.ndarray) -> GranularFrame:
        from fibrelmp.translate.musen.mdem.timepoints import bit, columns

        spheres, bonds, walls = self.spheres, self.bonds, self.walls
        q = columns("quaternion").start
        n = len(values)
        live = np.flatnonzero((spheres < n) & (masks[np.minimum(spheres, n - 1)] != 0)
                              if n else np.zeros(0, bool))
        v = values[spheres[live]]
        frame = GranularFrame(time=time, step=step, sphere_rows=live,
                              position=v[:, columns("coord")], velocity=v[:, columns("vel")],
                              omega=v[:, columns("angle_vel")], force=v[:, columns("force")],
                              quaternion=v[:, columns("quaternion")])
        saved = masks[spheres[live]]
        if len(live) and np.all(saved & bit("temperature")):
            # MUSEN saves temperatures when a heat model ran
            frame.temperature = v[:, columns("temperature").start].copy()
        if len(bonds):
            b = np.zeros((len(bonds), values.shape[1]))
            inside = bonds < n
            b[inside] = values[bonds[inside]]
            frame.bond_alive = np.zeros(len(bonds), bool)
            frame.bond_alive[inside] = masks[bonds[inside]] != 0
            frame.bond_force = b[:, columns("force")]
            frame.bond_tangential_overlap = b[:, columns("angle_vel")]
            frame.bond_torque = b[:, columns("total_torque").start]
        if len(walls):
            w = np.zeros((len(walls), values.shape[1]))      # absent entries: zeros
            inside = walls < n
            w[inside] = values[walls[inside]]
            frame.triangle_vertices = np.stack(
                [w[:, columns("coord")], w[:, q:q + 3], w[:, columns("angle_vel")]], axis=1)
            frame.triangle_velocity = w[:, columns("vel")]
            frame.triangle_force = w[:, columns("force")]
        return frame
