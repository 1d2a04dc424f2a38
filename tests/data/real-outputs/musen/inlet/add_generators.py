"""Add two dynamic generators to cmusen's import of inlet_scene.txt (protobuf edit of the
scene message; the time point is copied as read)."""
import sys
from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter

src, dst = sys.argv[1], sys.argv[2]
with MdemFile(src) as f:
    storage = f.storage
    points = list(f.time_points())
gens = storage.modules_data.objects_generator
del gens.generators[:]
a = gens.generators.add()
a.version, a.name, a.volume_key, a.mixture_key, a.obj_type = 1, "InletA", "VINLET", "MIXONE", 1
a.random_velocity_flag, a.velocity_magnitude = True, 0.5
a.start_generation_time, a.end_generation_time, a.update_time_step = 0.0, 0.015, 1e-3
a.rate_type, a.rate_value, a.max_iterations = 0, 10000.0, 30
a.scaling_factor, a.activity, a.inside_geometries = 1.0, True, True
b = gens.generators.add()
b.version, b.name, b.volume_key, b.mixture_key, b.obj_type = 1, "InletB", "VINLET", "MIXTWO", 1
b.init_velocity.z = -0.5
b.start_generation_time, b.end_generation_time, b.update_time_step = 0.004, 0.012, 2e-3
b.rate_type, b.rate_value, b.max_iterations = 1, 3.0, 30
b.scaling_factor, b.activity, b.inside_geometries = 1.0, True, True
with open(dst, "wb") as fh:
    w = MdemWriter(fh)
    for t, values, masks in points:
        w.add(t, values, masks)
    w.finish(storage)
