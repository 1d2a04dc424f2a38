"""Wall geometry of granular models: moved to ``fibrelmp.translate.granular.geometry``; these
names stay importable from here."""

from fibrelmp.translate.granular.geometry import (AREA_RTOL, BoxShape, CylinderShape, Kinematics, Segment,
                                                  axis_angle, closest_points, detect_box, detect_cylinder,
                                                  detect_oriented_box, geometry_kinematics,
                                                  geometry_triangle_rows, nearest_triangle, particle_side,
                                                  piecewise_expression, tile_triangles, tile_triangles_within,
                                                  triangle_areas, triangle_normals)

__all__ = ["AREA_RTOL", "BoxShape", "CylinderShape", "Kinematics", "Segment", "axis_angle", "closest_points",
           "detect_box", "detect_cylinder", "detect_oriented_box", "geometry_kinematics",
           "geometry_triangle_rows", "nearest_triangle", "particle_side", "piecewise_expression",
           "tile_triangles", "tile_triangles_within", "triangle_areas", "triangle_normals"]
