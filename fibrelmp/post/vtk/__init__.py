"""ParaView output (``.vtu`` per frame, ``.pvd`` index): written from LAMMPS dumps, read back."""

from fibrelmp.post.vtk.reader import Vtu, read_pvd, read_vtu
from fibrelmp.post.vtk.target import VtkTarget
from fibrelmp.post.vtk.writer import VtkWriter, vtu_text

__all__ = ["Vtu", "VtkTarget", "VtkWriter", "read_pvd", "read_vtu", "vtu_text"]
