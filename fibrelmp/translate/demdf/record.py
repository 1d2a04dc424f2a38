"""What a DEMDF document keeps for its snapshots (``GranularModel.origin``): the parsed
document, the counters and object types the snapshots repeat, where they go."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fibrelmp.granmodel import GranularModel, SourceRecord


@dataclass
class DemdfDocument(SourceRecord):
    document: dict[str, Any]           # the parsed JSON document
    dimensionality: int                # 2 or 3
    particle_rows: list[list[Any]]     # the particle array rows as read (last entry: object type)
    particles_file: str | Path | None  # the separate particles file, if any
    output_location: Any               # where the document names its snapshots
    filename: str                      # the snapshots' base name
    save_count: int
    file_time_step: float
    substeps: int
    time_step_count: int

    def post_facts(self) -> dict[str, Any]:
        """The fields in their order (``WorkFacts.demdf``, data.fibrelmp.json)."""
        return {"document": self.document, "dimensionality": self.dimensionality,
                "particle_rows": self.particle_rows, "particles_file": self.particles_file,
                "output_location": self.output_location, "filename": self.filename,
                "save_count": self.save_count, "file_time_step": self.file_time_step,
                "substeps": self.substeps, "time_step_count": self.time_step_count}


def demdf_record(model: GranularModel) -> DemdfDocument:
    """The model's DEMDF document (every DEMDF model has one: its reader or post target)."""
    if not isinstance(model.origin, DemdfDocument):
        raise TypeError(f"{model.source}: a {model.kind} model has no DEMDF document")
    return model.origin
