"""Any trajectory MDAnalysis reads, as dump Frames (``UniverseReader``)."""

from fibrelmp.post.mdanalysis.reader import UniverseReader, iter_mda_frames, open_universe

__all__ = ["UniverseReader", "iter_mda_frames", "open_universe"]
