"""DEMDF's reference samples for the conformance tests (tests/conformance/test_demdf.py): the
sample document under the repository and the builder of a small snapshot series
(docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

DOCUMENT = "examples/demdf/head_on.json"            # two spheres meeting head on (input)


def sample_model(repo: Path) -> "GranularModel":
    """The model of ``DOCUMENT`` (``repo``: the repository's root)."""
    from fibrelmp.translate.demdf import reader

    return reader.read(repo / DOCUMENT)


def result_writer(model: "GranularModel", folder: Path) -> "DemdfSnapshotWriter":
    """The snapshot writer of ``model`` into ``folder``."""
    from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

    return DemdfSnapshotWriter(model, folder)
