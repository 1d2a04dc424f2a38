"""Every field of a ``.mdem`` file, classified: honoured, refused (unless at its inert
default), warned (an output choice fibrelmp does not make) or not simulation data.

MUSEN loads a file's settings with the scene (``CBaseSimulator::LoadConfiguration``,
``CModelManager::LoadConfiguration``, ``CGenerationManager::LoadConfiguration``) and
simulates with them; a setting fibrelmp cannot honour is refused here, naming the file and
the field, never dropped.  ``FIELDS`` classifies every field of ``messages._SPEC`` (a test
checks that none is missing, so a field added to the table of messages must be classified);
``REFUSALS`` holds one check per refused setting: an implementation replaces its row.
Unsupported generator settings, the variable time step and unknown stop criteria are refused where their own
items handle them (``generators.read_inlets``, ``model._refused_settings``: a job script
may switch the latter off); the velocity limit and a moving periodic box are simulated.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from fibrelmp.errors import InputError

HONOURED = "honoured"
REFUSED = "refused unless inert"
WARNED = "warned"
NOT_SIMULATION = "not simulation data"

_TEXT = "through the scene's text form (`.mdem` → MUSEN text export → text scene reader)"
_GUI = "GUI / view data"
_DB = "materials database, read through the text form (`32`/`33`)"
# handled where their items put them (issue 26, items 3 and 4), not in REFUSALS below
_STOP = ("BROKEN_BONDS (type 1, max_broken_bonds) stops the run as cmusen does, checked at every "
         "save (model.py `_refused_settings`, lammps_flow.py); an unknown type is refused by name; "
         "a job script's STOP_CRITERION replaces it")
_VARIABLE_STEP = ("MUSEN's variable time step: fix musen/leapfrog variable (its rule, saves and "
                  "end; compared with cmusen in tests/test_musen_variable_time_step.py); a job "
                  "script's VARIABLE_TIME_STEP replaces it")
_INLETS = ("an active dynamic generator (inlet) of spheres or of agglomerates (with their "
           "solid bonds, from the job's AGGLOMERATES_DB) into an analysis volume inserts them "
           "during the run (mdem/generators.py `read_inlets`, fix musen/inlet); moving volumes "
           "and inside_geometries off are refused by name and field; an inactive one is inert, "
           "as in MUSEN")
_AGGLOMERATES_DB = ("the agglomerates database (`.madb`, a job's AGGLOMERATES_DB; not part of "
                    "a `.mdem`): a generator's agglomerate is read from it "
                    "(mdem/agglomerates.py, docs section 6); multispheres and contact radius "
                    "!= radius are refused by generator and key")

# "Message.field" -> (class, why); "Message.*" classifies every field of a message
FIELDS: dict[str, tuple[str, str]] = {
    # ---- materials database (MaterialsDatabase.proto)
    "ProtoCompound.compoundName": (HONOURED, _DB),
    "ProtoCompound.uniqueKey": (HONOURED, _DB),
    "ProtoCompound.constProperty": (HONOURED, _DB),
    "ProtoCompound.property": (HONOURED, _DB + "; a temperature/pressure correlation at MUSEN's "
                               "standard conditions, as MUSEN evaluates it"),
    "ProtoCompound.phase": (NOT_SIMULATION, "the DEM solver does not read a compound's phase"),
    "ProtoCompound.authorName": (NOT_SIMULATION, "bookkeeping"),
    "ProtoCompound.creationDate": (NOT_SIMULATION, "bookkeeping"),
    "ProtoCompound.color": (NOT_SIMULATION, _GUI),
    "ProtoConstProperty.*": (HONOURED, _DB),
    "ProtoTPProperty.*": (HONOURED, _DB),
    "ProtoCorrelation.*": (HONOURED, _DB),
    "ProtoInteraction.*": (HONOURED, _DB),
    "ProtoMaterialsDatabase.compound": (HONOURED, _DB),
    "ProtoMaterialsDatabase.interaction": (HONOURED, _DB),
    "ProtoMaterialsDatabase.mixture": (NOT_SIMULATION, "mixtures feed generators only (`34`, "
                                       "kept in the scene record)"),
    "ProtoMixture.*": (NOT_SIMULATION, "mixtures feed generators only"),
    "ProtoCompoundFraction.*": (NOT_SIMULATION, "mixtures feed generators only"),
    "ProtoColor.*": (NOT_SIMULATION, _GUI),
    "ProtoDate.*": (NOT_SIMULATION, "bookkeeping"),
    # ---- geometric primitives
    "ProtoVector.*": (HONOURED, "a value of the field that holds it"),
    "ProtoTriangle.*": (HONOURED, "a value of the field that holds it"),
    "ProtoMatrix.*": (HONOURED, "a value of the field that holds it"),
    "ProtoQuaternion.*": (HONOURED, "a value of the field that holds it"),
    # ---- scene
    "ProtoSimulationStorage.info": (HONOURED, "the scene"),
    "ProtoSimulationStorage.modules_data": (HONOURED, "the modules' settings (rows below)"),
    "ProtoSimulationStorage.data_blocks": (HONOURED, "where the time points are stored"),
    "ProtoBlockDescriptor.*": (HONOURED, "where the time points are stored"),
    "ProtoSimulationInfo.version": (HONOURED, "chooses the geometry / analysis-volume layout"),
    "ProtoSimulationInfo.file_version": (HONOURED, "chooses the time-point layout"),
    "ProtoSimulationInfo.begin_time": (NOT_SIMULATION, "summary of the saved time points"),
    "ProtoSimulationInfo.end_time": (NOT_SIMULATION, "summary of the saved time points"),
    "ProtoSimulationInfo.savedTimePoints": (HONOURED, "the start state is the first saved "
                                            "time point, where MUSEN's simulator starts"),
    "ProtoSimulationInfo.simulation_volume_min": (HONOURED, "simulation domain (`22`), " + _TEXT),
    "ProtoSimulationInfo.simulation_volume_max": (HONOURED, "simulation domain (`22`), " + _TEXT),
    "ProtoSimulationInfo.particles": (HONOURED, "the objects, " + _TEXT),
    "ProtoSimulationInfo.real_geometry_v0": (HONOURED, "geometries (`25`-`27`), " + _TEXT),
    "ProtoSimulationInfo.real_geometry": (HONOURED, "geometries (`25`-`27`), " + _TEXT),
    "ProtoSimulationInfo.analysis_volume_v0": (NOT_SIMULATION, "analysis volumes (`38`) are "
                                               "used by generators and analysers only"),
    "ProtoSimulationInfo.analysis_volume": (NOT_SIMULATION, "analysis volumes (`38`) are used "
                                            "by generators and analysers only"),
    "ProtoSimulationInfo.multispheres": (REFUSED, "multispheres (rigid clumps) are not simulated"),
    "ProtoSimulationInfo.periodic_conditions_min": (HONOURED, "periodic box (`28`), " + _TEXT),
    "ProtoSimulationInfo.periodic_conditions_max": (HONOURED, "periodic box (`28`), " + _TEXT),
    "ProtoSimulationInfo.periodic_conditions_x": (HONOURED, "periodic box (`28`), " + _TEXT),
    "ProtoSimulationInfo.periodic_conditions_y": (HONOURED, "periodic box (`28`), " + _TEXT),
    "ProtoSimulationInfo.periodic_conditions_z": (HONOURED, "periodic box (`28`), " + _TEXT),
    "ProtoSimulationInfo.periodic_conditions_enabled": (HONOURED, "periodic box (`28`), " + _TEXT),
    "ProtoSimulationInfo.periodic_conditions_vel": (HONOURED, "moving periodic box: "
                                                    "fix musen/pbc/move (model.py "
                                                    "`_refused_settings`, item 4)"),
    "ProtoSimulationInfo.anisotripy": (HONOURED, "anisotropy flag (`29`), " + _TEXT),
    "ProtoSimulationInfo.contact_radius": (HONOURED, "contact-radius flag (`30`), " + _TEXT),
    "ProtoSimulationInfo.selective_saving": (WARNED, "fibrelmp saves every field"),
    "ProtoSimulationInfo.selective_saving_flags": (WARNED, "fibrelmp saves every field"),
    "ProtoSelectiveSaving.*": (WARNED, "fibrelmp saves every field"),
    "ProtoSimulationInfo.stop_criteria": (HONOURED, _STOP),
    "ProtoStopCriteria.*": (HONOURED, _STOP),
    "ProtoParticleInfo.id": (HONOURED, _TEXT),
    "ProtoParticleInfo.type": (HONOURED, _TEXT + "; liquid bonds run as cmusen runs them (no force)"),
    "ProtoParticleInfo.compound": (HONOURED, _TEXT),
    "ProtoParticleInfo.encoded_properties": (HONOURED, "radii, bond ends/diameter/length, " + _TEXT),
    "ProtoParticleInfo.activity_start": (HONOURED, "activity interval (`24`), " + _TEXT),
    "ProtoParticleInfo.activity_end": (HONOURED, "activity interval (`24`), " + _TEXT),
    "ProtoMultisphere.*": (REFUSED, "multispheres (rigid clumps) are not simulated"),
    # ---- geometries and analysis volumes
    "ProtoRealGeometry.version": (HONOURED, "layout version"),
    "ProtoRealGeometry.base_geometry": (HONOURED, "name, key, motion (rows below)"),
    "ProtoRealGeometry.planes": (HONOURED, "the geometry's walls (`27`), " + _TEXT),
    "ProtoRealGeometry.free_motion": (HONOURED, "free motion (`25`), " + _TEXT + "; the wall "
                                      "translator refuses a free-moving geometry with mass"),
    "ProtoRealGeometry.mass": (HONOURED, "(`25`), " + _TEXT),
    "ProtoRealGeometry.rotate_around_center": (HONOURED, "(`25`), " + _TEXT),
    "ProtoRealGeometry_v0.name": (HONOURED, _TEXT),
    "ProtoRealGeometry_v0.key": (HONOURED, _TEXT),
    "ProtoRealGeometry_v0.planes": (HONOURED, _TEXT),
    "ProtoRealGeometry_v0.tdVal": (HONOURED, "motion intervals (`26`), " + _TEXT),
    "ProtoRealGeometry_v0.mass": (HONOURED, _TEXT),
    "ProtoRealGeometry_v0.vFreeMotion": (HONOURED, _TEXT + "; free motion refused by the wall "
                                         "translator"),
    "ProtoRealGeometry_v0.rotate_AroundMassCenter": (HONOURED, _TEXT),
    "ProtoRealGeometry_v0.forceDependentVel": (HONOURED, "motion type 2 (`26`), " + _TEXT + "; "
                                               "force motion refused by the wall translator"),
    "ProtoRealGeometry_v0.analysis": (NOT_SIMULATION, "MUSEN's own converter ignores it"),
    "ProtoRealGeometry_v0.type": (NOT_SIMULATION, "the GUI shape; the walls are what is simulated"),
    "ProtoRealGeometry_v0.props": (NOT_SIMULATION, "the GUI shape's sizes"),
    "ProtoRealGeometry_v0.rotation": (NOT_SIMULATION, "the GUI shape's rotation"),
    "ProtoRealGeometry_v0.color": (NOT_SIMULATION, _GUI),
    "ProtoTimeDepVel.*": (HONOURED, "motion intervals (`26`), " + _TEXT),
    "ProtoBaseGeometry.name": (HONOURED, _TEXT),
    "ProtoBaseGeometry.key": (HONOURED, _TEXT),
    "ProtoBaseGeometry.motion": (HONOURED, "motion (`26`), " + _TEXT + "; force motion refused "
                                 "by the wall translator"),
    "ProtoBaseGeometry.version": (HONOURED, "layout version"),
    "ProtoBaseGeometry.shape": (NOT_SIMULATION, "the GUI shape; the walls are what is simulated"),
    "ProtoBaseGeometry.sizes": (NOT_SIMULATION, "the GUI shape's sizes"),
    "ProtoBaseGeometry.rotation": (NOT_SIMULATION, "the GUI shape's rotation"),
    "ProtoBaseGeometry.scaling": (NOT_SIMULATION, "the GUI shape's scaling"),
    "ProtoBaseGeometry.color": (NOT_SIMULATION, _GUI),
    "ProtoGeometryMotion.*": (HONOURED, "motion (`26`), " + _TEXT),
    "ProtoGeometryMotionInterval.*": (HONOURED, "motion (`26`), " + _TEXT),
    "ProtoAnalysisVolume.*": (NOT_SIMULATION, "analysis volumes are used by generators and "
                              "analysers only"),
    "ProtoAnalysisVolume_v0.*": (NOT_SIMULATION, "analysis volumes are used by generators and "
                                 "analysers only"),
    # ---- modules
    "ProtoModulesData.simulator": (HONOURED, "simulator settings (rows below)"),
    "ProtoModulesData.objects_generator": (HONOURED, _INLETS),
    "ProtoModulesData.bonds_generator": (NOT_SIMULATION, "pre-processing: run only by a "
                                         "script's COMPONENT BONDS_GENERATOR"),
    "ProtoModulesData.package_generator": (NOT_SIMULATION, "pre-processing: run only by a "
                                           "script's COMPONENT PACKAGE_GENERATOR"),
    "ProtoModulesData.model_manager": (HONOURED, "models (rows below)"),
    "ProtoModulesData.materials_database": (HONOURED, _DB),
    "ProtoModuleSimulator.start_time": (NOT_SIMULATION, "MUSEN's simulator does not load it; "
                                        "a run starts at the first saved time point"),
    "ProtoModuleSimulator.end_time": (HONOURED, "end time (a script may set it again)"),
    "ProtoModuleSimulator.simulation_step": (HONOURED, "time step (a script may set it again)"),
    "ProtoModuleSimulator.saving_step": (HONOURED, "saving step (a script may set it again)"),
    "ProtoModuleSimulator.external_acceleration": (HONOURED, "gravity"),
    "ProtoModuleSimulator.save_collisions": (WARNED, "fibrelmp writes no collisions file"),
    "ProtoModuleSimulator.simulator_type": (NOT_SIMULATION, "CPU or GPU: where MUSEN computes"),
    "ProtoModuleSimulator.max_cells_number": (NOT_SIMULATION, "neighbour search: LAMMPS's own"),
    "ProtoModuleSimulator.verlet_dist_coeff": (HONOURED, "when broken bonds' spheres may touch "
                                               "(fix musen/verlet; read with max_cells_number)"),
    "ProtoModuleSimulator.verlet_auto_adjust": (HONOURED, "the same schedule's auto-adjustment"),
    "ProtoModuleSimulator.flexible_time_step": (HONOURED, _VARIABLE_STEP),
    "ProtoModuleSimulator.part_move_limit": (HONOURED, "MOVE of fix musen/leapfrog variable "
                                             "(read only with a variable time step)"),
    "ProtoModuleSimulator.time_step_factor": (HONOURED, "FACTOR of fix musen/leapfrog variable "
                                              "(read only with a variable time step)"),
    "ProtoModuleSimulator.part_velocity_limit": (HONOURED, "fix musen/leapfrog vlimit (> 0; "
                                                 "MUSEN: <= 0 is no limit; item 4)"),
    "ProtoModuleObjectsGenerator.*": (HONOURED, _INLETS),
    "ProtoObjectsGenerator.*": (HONOURED, _INLETS),
    "ProtoAgglQuatern.*": (HONOURED, _AGGLOMERATES_DB),
    "ProtoAgglVect.*": (HONOURED, _AGGLOMERATES_DB),
    "ProtoAgglParticle.*": (HONOURED, _AGGLOMERATES_DB),
    "ProtoAgglBond.*": (HONOURED, _AGGLOMERATES_DB),
    "ProtoAgglomerate.*": (HONOURED, _AGGLOMERATES_DB),
    "ProtoAgglomeratesDB.*": (HONOURED, _AGGLOMERATES_DB),
    "ProtoModuleBondsGenerator.*": (NOT_SIMULATION, "pre-processing (COMPONENT BONDS_GENERATOR)"),
    "ProtoBondsGenerator.*": (NOT_SIMULATION, "pre-processing (COMPONENT BONDS_GENERATOR)"),
    "ProtoModulePackageGenerator.*": (NOT_SIMULATION, "pre-processing (COMPONENT "
                                      "PACKAGE_GENERATOR)"),
    "ProtoPackageGenerator.*": (NOT_SIMULATION, "pre-processing (COMPONENT PACKAGE_GENERATOR)"),
    "ProtoModuleModelManager.version": (HONOURED, "0: the per-kind slots; 1: the model list"),
    "ProtoModuleModelManager.models": (HONOURED, "the models (version 1), merged with a "
                                       "script's as cmusen merges them"),
    "ProtoModuleModelManager.pp_model": (HONOURED, "version 0 slot"),
    "ProtoModuleModelManager.pw_model": (HONOURED, "version 0 slot"),
    "ProtoModuleModelManager.sb_model": (HONOURED, "version 0 slot"),
    "ProtoModuleModelManager.lb_model": (HONOURED, "version 0 slot"),
    "ProtoModuleModelManager.ef_model": (HONOURED, "version 0 slot"),
    "ProtoModuleModelManager.ht_pp_model": (REFUSED, "the old heat-transfer model slot "
                                            "(version 0): heat transfer is not simulated"),
    "ProtoModuleModelManager.connected_pp_contact": (HONOURED, "contacts between bonded "
                                                     "particles (plan.contacts_between_bonded; "
                                                     "a script's CONNECTED_PP_CONTACT overrides "
                                                     "it, as in cmusen)"),
    "ProtoMusenModel.key": (HONOURED, "a model without a library path is refused (MUSEN finds "
                            "it by this key; fibrelmp by its name)"),
    "ProtoMusenModel.path": (HONOURED, "the model's name (its library path's stem)"),
    "ProtoMusenModel.params": (HONOURED, "the model's parameters"),
    # ---- time points
    "ProtoBlockOfTimePoints.*": (HONOURED, "saved time points"),
    "ProtoTimePoint.*": (HONOURED, "saved time points"),
    "ProtoTimeDependentProperties.coord": (HONOURED, "positions / bond midpoints / vertex 1"),
    "ProtoTimeDependentProperties.vel": (HONOURED, "velocities"),
    "ProtoTimeDependentProperties.angle_vel": (HONOURED, "angular velocity / bond tangential "
                                               "overlap / vertex 3"),
    "ProtoTimeDependentProperties.quaternion": (HONOURED, "orientation"),
    "ProtoTimeDependentProperties.force": (HONOURED, "bond force (a bond's state)"),
    "ProtoTimeDependentProperties.angles": (NOT_SIMULATION, "old layout only (refused); walls "
                                            "keep vertex 2 in the quaternion"),
    "ProtoTimeDependentProperties.angle_accl": (NOT_SIMULATION, "old layout only (refused)"),
    "ProtoTimeDependentProperties.total_torque": (HONOURED, "bond torque (a bond's state)"),
    "ProtoTimeDependentProperties.temperature": (HONOURED, "spheres' temperature: the start "
                                                 "state of ModelEFHeatTransfer, saved when it runs"),
    "ProtoTimeDependentProperties.liquid_film_mass": (NOT_SIMULATION, "MUSEN e0ff360's liquid-bond law is a no-op"),
    "ProtoTimeDependentProperties.stress_tensor": (NOT_SIMULATION, "a result (written, not read)"),
}


def classify(message: str, name: str) -> tuple[str, str] | None:
    """The row of ``message.name`` (an exact row first, else its message's ``*`` row)."""
    return FIELDS.get(f"{message}.{name}") or FIELDS.get(f"{message}.*")


# ---- refusals: each returns (field, why) when a file sets a setting fibrelmp cannot honour

def _heat_model_slot(storage: Any) -> tuple[str, str] | None:
    manager = storage.modules_data.model_manager
    # CModelManager::LoadConfiguration reads the old slots only for version 0
    if manager.version == 0 and manager.ht_pp_model.key:
        return ("modules_data.model_manager.ht_pp_model",
                f"the old heat-transfer model slot selects {manager.ht_pp_model.path or manager.ht_pp_model.key!r}; "
                "heat transfer is not simulated by fibrelmp")
    return None


def _multispheres(storage: Any) -> tuple[str, str] | None:
    if len(storage.info.multispheres):
        return ("info.multispheres", f"{len(storage.info.multispheres)} multisphere(s) (rigid "
                "clumps of spheres) are not simulated by fibrelmp")
    return None


def _model_without_path(storage: Any) -> tuple[str, str] | None:
    manager = storage.modules_data.model_manager
    slots = ([(f"models[{i}]", m) for i, m in enumerate(manager.models)] if manager.version
             else [(s, getattr(manager, s)) for s in ("pp_model", "pw_model", "sb_model",
                                                      "lb_model", "ef_model")])
    for where, entry in slots:
        if entry.key and not entry.path:
            return (f"modules_data.model_manager.{where}",
                    f"a model stored by its key only ({entry.key}); fibrelmp identifies models "
                    "by name: name it in a job script (MODEL_...)")
    return None


# refused setting -> its check; an implementation replaces its row
REFUSALS: dict[str, Callable[[Any], tuple[str, str] | None]] = {
    "old heat-model slot": _heat_model_slot,
    "multispheres": _multispheres,
    "model without a name": _model_without_path,
}

# output choices fibrelmp does not make: a named warning, the results are unchanged
def _warnings(storage: Any) -> list[str]:
    out = []
    if storage.info.selective_saving:
        out.append("info.selective_saving: MUSEN saves only the selected fields; fibrelmp "
                   "saves every field")
    if storage.modules_data.simulator.save_collisions:
        out.append("modules_data.simulator.save_collisions: fibrelmp writes no collisions file")
    return out


def check_settings(storage: Any, path: Path) -> list[tuple[str, str]]:
    """Refuse the first setting of ``storage`` fibrelmp cannot honour (InputError
    ``path: field: why``); return the named warnings for output choices it does not make."""
    for check in REFUSALS.values():
        found = check(storage)
        if found is not None:
            raise InputError(path, None, f"{found[0]}: {found[1]}")
    return [("musen-ignored-setting", f"{path}: {text}") for text in _warnings(storage)]
