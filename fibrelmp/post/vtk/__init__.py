"""ParaView/OVITO output: a ``.pvd`` series of ``.vtp`` particle frames (and ``.vtm`` frames
with bonds), written from LAMMPS dumps or a run's frames (``run_output``: ``run --also
vtk``), and read back."""

from fibrelmp.post.vtk.frame import ViewerFrame, bond_segments, from_dump
from fibrelmp.post.vtk.reader import Piece, read_frame, read_piece, read_pvd, read_vtm
from fibrelmp.post.vtk.target import VtkTarget
from fibrelmp.post.vtk.writer import VtkWriter

__all__ = ["Piece", "ViewerFrame", "VtkTarget", "VtkWriter", "bond_segments", "from_dump",
           "read_frame", "read_piece", "read_pvd", "read_vtm"]
