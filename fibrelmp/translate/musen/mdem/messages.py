"""The protobuf messages of MUSEN's ``.mdem`` files, defined here from their field numbers.

MUSEN describes its files in ``SimulationDescription.proto`` and ``MaterialsDatabase.proto``
(proto3).  fibrelmp does not ship those files: the table below lists each message's fields as
``name number type`` (the facts a reader needs to decode the wire format), and ``classes()``
builds message classes from it at run time with the ``protobuf`` package's descriptor API.
Enum fields are declared as ``int32`` (same wire format; proto3 enums are open).

Only what a scene and its results need is decoded into fibrelmp's model; everything else
(generators, GUI settings, fields a later MUSEN adds) stays in the messages and is written back
unchanged, so a read-write round trip keeps every field.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

# message -> "name number type[*]" (* = repeated); a capitalised type is a message
_SPEC = {
    # MaterialsDatabase
    "ProtoCompoundFraction": "fractionName 1 string, compoundKey 2 string, diameter 3 double, "
                             "fraction 4 double, contact_diameter 5 double",
    "ProtoMixture": "uniqueKey 1 string, mixtureName 2 string, fraction 3 ProtoCompoundFraction*",
    "ProtoCorrelation": "t1 1 double, t2 2 double, p1 3 double, p2 4 double, corType 5 uint32, "
                        "parameter 6 double*",
    "ProtoTPProperty": "propertyType 1 uint32, correlation 2 ProtoCorrelation*",
    "ProtoConstProperty": "propertyType 1 uint32, value 2 double",
    "ProtoColor": "r 1 float, g 2 float, b 3 float, a 4 float",
    "ProtoDate": "year 1 uint32, month 2 uint32, day 3 uint32",
    "ProtoCompound": "compoundName 1 string, uniqueKey 2 string, authorName 3 string, "
                     "creationDate 4 ProtoDate, color 5 ProtoColor, phase 6 uint32, "
                     "constProperty 7 ProtoConstProperty*, property 8 ProtoTPProperty*",
    "ProtoInteraction": "compoundKey1 1 string, compoundKey2 2 string, property 3 ProtoTPProperty*",
    "ProtoMaterialsDatabase": "compound 1 ProtoCompound*, interaction 2 ProtoInteraction*, "
                              "mixture 3 ProtoMixture*",
    # AgglomeratesDatabase.proto (the .madb file: a bare ProtoAgglomeratesDB); MUSEN's names
    # ProtoQuatern, ProtoVect, ProtoParticle, ProtoBond, ProtoAgglomerate renamed (same wire format)
    "ProtoAgglQuatern": "q0 1 double, q1 2 double, q2 3 double, q3 4 double",
    "ProtoAgglVect": "x 1 double, y 2 double, z 3 double",
    "ProtoAgglParticle": "coord 1 ProtoAgglVect, radius 2 double, compound 3 string, "
                         "orient 4 ProtoAgglVect, quaternion 5 ProtoAgglQuatern, "
                         "contact_radius 6 double",
    "ProtoAgglBond": "leftID 1 int32, rightID 2 int32, radius 3 double, compound 4 string",
    "ProtoAgglomerate": "name 1 string, key 2 string, volume 3 double, "
                        "particles 4 ProtoAgglParticle*, bonds 5 ProtoAgglBond*, type 6 int32",
    "ProtoAgglomeratesDB": "Agglomerate 1 ProtoAgglomerate*",
    # SimulationDescription: scene
    "ProtoSelectiveSaving": "p_coord 1 bool, p_vel 2 bool, p_angvel 3 bool, p_quatern 4 bool, "
                            "p_force 5 bool, p_tensor 6 bool, sb_force 7 bool, sb_tangoverlap 8 bool, "
                            "sb_tottorque 9 bool, lb_force 10 bool, tw_coord 11 bool, tw_force 12 bool, "
                            "tw_vel 13 bool, p_temperature 14 bool",
    "ProtoVector": "x 1 double, y 2 double, z 3 double",
    "ProtoTriangle": "vert1 1 ProtoVector, vert2 2 ProtoVector, vert3 3 ProtoVector",
    "ProtoMatrix": "v1 1 ProtoVector, v2 2 ProtoVector, v3 3 ProtoVector",
    "ProtoQuaternion": "q0 1 double, q1 2 double, q2 3 double, q3 4 double",
    "ProtoTimeDepVel": "time 1 double, velocity 2 ProtoVector, rotVelocity 3 ProtoVector, "
                       "rotCenter 4 ProtoVector",
    "ProtoGeometryMotionInterval": "version 1 uint32, velocity 2 ProtoVector, rot_velocity 3 ProtoVector, "
                                   "rot_center 4 ProtoVector, limit1 5 double, limit2 6 double, "
                                   "limit_type 7 uint32",
    "ProtoGeometryMotion": "version 1 uint32, type 2 uint32, intervals 3 ProtoGeometryMotionInterval*",
    "ProtoBaseGeometry": "version 1 uint32, name 2 string, key 3 string, shape 4 int32, "
                         "color 5 ProtoColor, sizes 7 double*, rotation 8 ProtoMatrix, "
                         "motion 9 ProtoGeometryMotion, scaling 10 double",
    "ProtoAnalysisVolume": "version 1 uint32, base_geometry 2 ProtoBaseGeometry, "
                           "triangles 3 ProtoTriangle*, center 4 ProtoVector",
    "ProtoRealGeometry": "version 1 uint32, base_geometry 2 ProtoBaseGeometry, planes 3 uint64*, "
                         "free_motion 4 ProtoVector, mass 5 double, rotate_around_center 6 bool",
    "ProtoRealGeometry_v0": "name 1 string, key 2 string, analysis 3 int32, planes 4 int32*, "
                            "tdVal 5 ProtoTimeDepVel*, mass 6 double, vFreeMotion 7 ProtoVector, "
                            "type 8 int32, props 9 double*, rotation 10 ProtoMatrix, color 11 ProtoColor, "
                            "rotate_AroundMassCenter 12 bool, forceDependentVel 13 bool",
    "ProtoAnalysisVolume_v0": "name 1 string, key 2 string, triangles 3 ProtoTriangle*, type 4 int32, "
                              "vCenter 5 ProtoVector, vProps 6 double*, rotation 7 ProtoMatrix, "
                              "color 8 ProtoColor, tdVal 9 ProtoTimeDepVel*",
    "ProtoMultisphere": "id 1 int32*",
    # type: 1 sphere, 9 solid bond, 13 liquid bond, 14 triangular wall (an enum in MUSEN)
    "ProtoParticleInfo": "id 1 int32, type 2 int32, compound 3 string, encoded_properties 5 bytes, "
                         "activity_start 6 double, activity_end 7 double",
    "ProtoStopCriteria": "types 2 uint32*, max_broken_bonds 3 uint64",
    "ProtoSimulationInfo": "file_version 1 int32, begin_time 2 double, end_time 3 double, "
                           "simulation_volume_min 4 ProtoVector, simulation_volume_max 5 ProtoVector, "
                           "particles 6 ProtoParticleInfo*, real_geometry_v0 7 ProtoRealGeometry_v0*, "
                           "analysis_volume_v0 8 ProtoAnalysisVolume_v0*, savedTimePoints 9 double*, "
                           "multispheres 10 ProtoMultisphere*, periodic_conditions_min 11 ProtoVector, "
                           "periodic_conditions_max 12 ProtoVector, periodic_conditions_x 13 bool, "
                           "periodic_conditions_y 14 bool, periodic_conditions_z 15 bool, "
                           "periodic_conditions_enabled 17 bool, anisotripy 18 bool, "
                           "contact_radius 19 bool, selective_saving 20 bool, "
                           "periodic_conditions_vel 21 ProtoVector, "
                           "selective_saving_flags 22 ProtoSelectiveSaving, "
                           "stop_criteria 23 ProtoStopCriteria, analysis_volume 24 ProtoAnalysisVolume*, "
                           "version 25 uint32, real_geometry 26 ProtoRealGeometry*",
    "ProtoSimulationStorage": "info 1 ProtoSimulationInfo, modules_data 2 ProtoModulesData, "
                              "data_blocks 3 ProtoBlockDescriptor*",
    "ProtoModulesData": "simulator 1 ProtoModuleSimulator, objects_generator 2 ProtoModuleObjectsGenerator, "
                        "bonds_generator 3 ProtoModuleBondsGenerator, "
                        "package_generator 4 ProtoModulePackageGenerator, "
                        "model_manager 5 ProtoModuleModelManager, "
                        "materials_database 6 ProtoMaterialsDatabase",
    "ProtoModuleSimulator": "start_time 1 double, end_time 2 double, simulation_step 3 double, "
                            "saving_step 4 double, external_acceleration 5 ProtoVector, "
                            "save_collisions 6 bool, simulator_type 7 uint32, max_cells_number 8 uint32, "
                            "verlet_dist_coeff 9 double, verlet_auto_adjust 10 bool, "
                            "flexible_time_step 12 bool, part_move_limit 13 double, "
                            "time_step_factor 14 double, part_velocity_limit 15 double",
    "ProtoModuleObjectsGenerator": "generators 1 ProtoObjectsGenerator*",
    "ProtoObjectsGenerator": "name 1 string, volume_key 2 string, init_velocity 4 ProtoVector, "
                             "mixture_key 5 string, obj_type 6 int32, aggl_key 8 string, "
                             "start_generation_time 9 double, end_generation_time 10 double, "
                             "update_time_step 11 double, generation_rate 12 double, "
                             "aggl_part_materials_alias 13 string*, aggl_part_materials_key 14 string*, "
                             "aggl_bond_materials_alias 15 string*, aggl_bond_materials_key 16 string*, "
                             "scaling_factor 17 double, activity 18 bool, random_velocity_flag 19 bool, "
                             "velocity_magnitude 20 double, inside_geometries 21 bool, version 22 int32, "
                             "max_iterations 23 uint64, rate_type 24 int32, rate_value 25 double",
    "ProtoModuleBondsGenerator": "generators 1 ProtoBondsGenerator*",
    "ProtoBondsGenerator": "name 1 string, material_key 2 string, obj_type 3 uint32, min_length 4 double, "
                           "max_length 5 double, property1 6 double, allow_overlap 7 bool, "
                           "compound_specific 8 bool, partner_compounds1 9 string*, "
                           "partner_compounds2 10 string*, activity 11 bool",
    "ProtoModulePackageGenerator": "generators 1 ProtoPackageGenerator*, simulator_type 2 uint32, "
                                   "verlet_coeff 3 double",
    "ProtoPackageGenerator": "volume_name 1 string, volume_type 2 uint32, volume_center 3 ProtoVector, "
                             "volume_prop1 4 double, volume_prop2 5 double, volume_prop3 6 double, "
                             "volume_visible 7 bool, mixture_key 8 string, volume_index 9 uint32, "
                             "porosity 10 double, max_overlap 11 double, max_iterations 12 uint32, "
                             "init_velocity 13 ProtoVector, volume_stl_index 14 int32, "
                             "volume_active 15 bool, volume_key 16 string, inside_geometry 17 bool",
    "ProtoModuleModelManager": "pp_model 1 ProtoMusenModel, pw_model 2 ProtoMusenModel, "
                               "sb_model 3 ProtoMusenModel, lb_model 4 ProtoMusenModel, "
                               "ef_model 5 ProtoMusenModel, connected_pp_contact 6 bool, "
                               "ht_pp_model 7 ProtoMusenModel, version 8 uint32, "
                               "models 9 ProtoMusenModel*",
    "ProtoMusenModel": "key 1 string, path 2 string, params 4 string",
    # storage_format: 1 plain protobuf, 2 zlib-compressed protobuf (an enum in MUSEN)
    "ProtoBlockDescriptor": "start_time 1 double, offset_in_file 2 int64, size 3 int32, "
                            "uncompressed_size 4 int32, format 5 int32",
    # time-dependent data
    "ProtoTimeDependentProperties": "coord 1 ProtoVector, angles 2 ProtoVector, vel 3 ProtoVector, "
                                    "angle_vel 4 ProtoVector, angle_accl 6 ProtoVector, "
                                    "total_torque 8 double, temperature 9 double, "
                                    "liquid_film_mass 10 double, force 11 ProtoVector, "
                                    "quaternion 12 ProtoQuaternion, stress_tensor 13 ProtoMatrix",
    "ProtoTimePoint": "time 1 double, particles 2 ProtoTimeDependentProperties*",
    "ProtoBlockOfTimePoints": "time_points 2 ProtoTimePoint*",
}

_SCALARS = {"double": 1, "float": 2, "int64": 3, "uint64": 4, "int32": 5, "bool": 8, "string": 9,
            "bytes": 12, "uint32": 13}
_MESSAGE = 11
_PACKAGE = "fibrelmp.mdem"


def fields(message: str) -> list[tuple[str, int, str, bool]]:
    """(name, number, type, repeated) of a message, as the table lists them."""
    out = []
    for item in _SPEC[message].split(","):
        name, number, kind = item.split()
        out.append((name, int(number), kind.rstrip("*"), kind.endswith("*")))
    return out


@lru_cache(maxsize=1)
def classes() -> dict[str, Any]:
    """Message classes by name (built once)."""
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    fdp = descriptor_pb2.FileDescriptorProto(name="fibrelmp_mdem.proto", package=_PACKAGE,
                                             syntax="proto3")
    for message in _SPEC:
        mdp = fdp.message_type.add(name=message)
        for name, number, kind, repeated in fields(message):
            f = mdp.field.add(name=name, number=number, json_name=name,
                              label=3 if repeated else 1)
            if kind in _SCALARS:
                f.type = _SCALARS[kind]
            else:
                f.type = _MESSAGE
                f.type_name = f".{_PACKAGE}.{kind}"
    pool = descriptor_pool.DescriptorPool()
    pool.Add(fdp)
    return {name: message_factory.GetMessageClass(pool.FindMessageTypeByName(f"{_PACKAGE}.{name}"))
            for name in _SPEC}


def new(message: str, data: bytes | None = None) -> Any:
    """A message (parsed from ``data`` if given; raises protobuf's DecodeError if invalid)."""
    msg = classes()[message]()
    if data is not None:
        msg.ParseFromString(data)
    return msg
