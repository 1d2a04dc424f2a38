"""``.mdem``'s reference samples for the conformance tests (tests/conformance/test_mdem.py):
the sample file under the repository and the builder of a small result file
(docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.translate.musen.mdem.result import MdemResultWriter

SCENE = "examples/musen/SingelParticle.mdem"        # a scene with results (input, document)
DOCUMENT_CUT = 3000            # SCENE cut here is no .mdem: a data block beyond the end


def result_writer(model: "GranularModel", folder: Path) -> "MdemResultWriter":
    """The run-result writer of ``model`` into ``folder/result.mdem``."""
    from fibrelmp.translate.musen.mdem.result import MdemResultWriter

    return MdemResultWriter(model, folder / "result.mdem")
