"""MUSEN's reference samples for the conformance tests (tests/conformance/test_musen.py,
test_musen_script.py): the sample files under the repository and the builders of small
result files (docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.translate.musen.writer import MusenResultWriter

SCENE = "examples/musen/SingelParticle_text.txt"     # a text scene with results (input, document)
SCRIPT = "examples/musen/single_particle_job.txt"    # a cmusen job script (musen-script input)
DOCUMENT_CUT = 1500            # SCENE cut here is no MUSEN text: mid-record (tag 15 needs 3 values)


def result_writer(model: "GranularModel", folder: Path) -> "MusenResultWriter":
    """The run-result writer of ``model`` into ``folder/result.txt``."""
    from fibrelmp.translate.musen.writer import MusenResultWriter

    return MusenResultWriter(model, folder / "result.txt")
