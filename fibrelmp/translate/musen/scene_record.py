"""What a MUSEN scene (text or ``.mdem``) keeps of its source for the result files: the
scene lines fibrelmp does not simulate, the flags and interactions as read, and what a
``.mdem`` brought with it (``GranularModel.origin``; docs/musen.md)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.granmodel import GranularModel, SourceRecord

if TYPE_CHECKING:
    from fibrelmp.translate.musen.script_parse import MusenModelSpec

# MUSEN's periodic boundaries when a scene has no line 28: off, a 1 cm box
NO_PBC: tuple[list[bool], list[float]] = ([False] * 4, [-5e-3] * 3 + [5e-3] * 3)


@dataclass
class MusenSceneRecord(SourceRecord):
    # tokens of scene lines 34, 38..41 (mixtures, analysis volumes, generators), by tag
    raw: dict[int, list[list[str]]] = field(default_factory=dict)
    # material pair (a <= b) -> MUSEN interaction property id -> value, as read
    interactions: dict[tuple[int, int], dict[int, float]] = field(default_factory=dict)
    anisotropy: bool | int = False               # scene flag 29 / ANISOTROPY
    contact_radius_flag: bool | int = False      # scene flag 30 / CONTACT_RADIUS
    pbc: tuple[list[bool], list[float]] = field(default_factory=lambda: NO_PBC)   # line 28: flags, box
    mdem_source: Path | None = None              # the .mdem read (its scene message is copied)
    gravity_set: bool = False                    # the file or job set gravity (no default note)
    file_models: list[MusenModelSpec] = field(default_factory=list)   # a .mdem's stored models
    # a .mdem's simulator settings fibrelmp cannot simulate: field name -> why (a job script
    # may switch them off; a SIMULATOR job refuses what remains)
    refused: dict[str, str] = field(default_factory=dict)


def scene_record(model: GranularModel, keep: bool = False) -> MusenSceneRecord:
    """The model's MUSEN record; a model without one (a scene from another format written
    as MUSEN) gets MUSEN's defaults, kept on the model when ``keep`` (settings that set it)."""
    if isinstance(model.origin, MusenSceneRecord):
        return model.origin
    record = MusenSceneRecord()
    if keep:
        model.origin = record
    return record
