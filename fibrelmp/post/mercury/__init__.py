"""MercuryDPM's ``.data``/``.ene``/``.fstat`` files: written from LAMMPS dumps, read back."""

from fibrelmp.post.mercury.reader import (DataFrame, FstatFrame, read_data_file, read_ene,
                                          read_fstat)
from fibrelmp.post.mercury.target import MercuryTarget
from fibrelmp.post.mercury.writer import ENE_HEADER, MercuryFrame, MercuryWriter, g10

__all__ = ["DataFrame", "ENE_HEADER", "FstatFrame", "MercuryFrame", "MercuryTarget", "MercuryWriter",
           "g10", "read_data_file", "read_ene", "read_fstat"]
