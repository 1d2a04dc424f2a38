"""Write agglomerates.madb (three small agglomerates, fibrelmp's write_database: MUSEN's
ProtoAgglomeratesDB) and add two dynamic generators of agglomerates to cmusen's import of
agglo_scene.txt (protobuf edit of the scene message; the time point is copied as read)."""
import sys
from pathlib import Path

from fibrelmp.translate.musen.mdem.agglomerates import write_database
from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter

src, dst, db = sys.argv[1], sys.argv[2], sys.argv[3]
s3 = 0.8e-3 * 3 ** 0.5 / 2
write_database(Path(db), [
    # three touching spheres (r 0.4 mm) on a triangle, three bonds (r 0.2 mm)
    dict(key="AGGTRI", name="Triangle", particles=[
        (0.0, 0.0, 0.0, 0.4e-3, "Part"), (0.8e-3, 0.0, 0.0, 0.4e-3, "Part"),
        (0.4e-3, s3, 0.0, 0.4e-3, "Part")],
        bonds=[(0, 1, 0.2e-3, "Bond"), (1, 2, 0.2e-3, "Bond"), (2, 0, 0.2e-3, "Bond")]),
    # four spheres in a row, two sizes, off the origin (the generator centres it), three bonds
    dict(key="AGGROD", name="Rod", particles=[
        (1e-3, 2e-3, 3e-3, 0.3e-3, "Part"), (1.6e-3, 2e-3, 3e-3, 0.3e-3, "Part"),
        (2.25e-3, 2e-3, 3e-3, 0.35e-3, "Part"), (2.95e-3, 2e-3, 3e-3, 0.35e-3, "Part")],
        bonds=[(0, 1, 0.15e-3, "Bond"), (1, 2, 0.15e-3, "Bond"), (3, 2, 0.15e-3, "Bond")]),
    # a tetrahedron (not generated here)
    dict(key="AGGTET", name="Tetrahedron", particles=[
        (0, 0, 0, 0.3e-3, "Part"), (0.6e-3, 0, 0, 0.3e-3, "Part"),
        (0.3e-3, 0.52e-3, 0, 0.3e-3, "Part"), (0.3e-3, 0.17e-3, 0.49e-3, 0.3e-3, "Part")],
        bonds=[(0, 1, 1e-4, "B"), (0, 2, 1e-4, "B"), (0, 3, 1e-4, "B"), (1, 2, 1e-4, "B"),
               (1, 3, 1e-4, "B"), (2, 3, 1e-4, "B")]),
])
with MdemFile(src) as f:
    storage = f.storage
    points = list(f.time_points())
gens = storage.modules_data.objects_generator
del gens.generators[:]
a = gens.generators.add()
a.version, a.name, a.volume_key, a.obj_type, a.aggl_key = 1, "TriInlet", "VINLET", 2, "AGGTRI"
a.aggl_part_materials_alias.append("Part"), a.aggl_part_materials_key.append("MGLASS")
a.aggl_bond_materials_alias.append("Bond"), a.aggl_bond_materials_key.append("MBOND")
a.random_velocity_flag, a.velocity_magnitude = True, 0.2
a.start_generation_time, a.end_generation_time, a.update_time_step = 0.0, 0.006, 1e-3
a.rate_type, a.rate_value, a.max_iterations = 1, 3.0, 30
a.scaling_factor, a.activity, a.inside_geometries = 1.0, True, True
b = gens.generators.add()
b.version, b.name, b.volume_key, b.obj_type, b.aggl_key = 1, "RodInlet", "VINLET", 2, "AGGROD"
b.aggl_part_materials_alias.append("Part"), b.aggl_part_materials_key.append("MSTEEL")
b.aggl_bond_materials_alias.append("Bond"), b.aggl_bond_materials_key.append("MBOND")
b.init_velocity.z = -0.5
b.start_generation_time, b.end_generation_time, b.update_time_step = 0.002, 0.006, 2e-3
b.rate_type, b.rate_value, b.max_iterations = 1, 2.0, 30
b.scaling_factor, b.activity, b.inside_geometries = 1.25, True, True
with open(dst, "wb") as fh:
    w = MdemWriter(fh)
    for t, values, masks in points:
        w.add(t, values, masks)
    w.finish(storage)
