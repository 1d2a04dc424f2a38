"""VTK unstructured-grid meshes (``.vtu`` XML, ``.vtk`` legacy) through meshio."""
