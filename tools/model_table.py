"""Regenerate the model table of docs/musen.md from the registered physics models.

    python tools/model_table.py

One row per model module of ``fibrelmp/translate/granular/models/`` (its MUSEN name, kind,
parameters, the LAMMPS style it needs, its docstring; a link to ``docs/models/<module>.md`` when
that page exists).  Run it after adding or changing a model; ``tests/test_physics_models.py``
fails while the table and the registry differ.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fibrelmp.translate.granular import models as physics  # noqa: E402

DOC = ROOT / "docs" / "musen.md"
PLACEHOLDER = "MODEL_TABLE_PLACEHOLDER"     # where a table goes the first time


def updated(text: str) -> str:
    """``text`` (docs/musen.md) with its model table replaced by the registry's."""
    table = physics.model_table(ROOT)
    if physics.TABLE_START in text and physics.TABLE_END in text:
        head, rest = text.split(physics.TABLE_START, 1)
        return head + table + rest.split(physics.TABLE_END, 1)[1]
    if PLACEHOLDER in text:
        return text.replace(PLACEHOLDER, table, 1)
    raise SystemExit(f"{DOC}: the markers {physics.TABLE_START!r} and {physics.TABLE_END!r} "
                     "are missing")


def main() -> None:
    DOC.write_text(updated(DOC.read_text()))
    print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
