"""Regenerate each physics model's page docs/models/<module>.md from its model module.

    python tools/model_pages.py

The generated part of a page (MUSEN's name, kind, parameters and defaults, the LAMMPS style it
needs, its .mdem key, its module's docstring) is rewritten; text after its end marker is kept
(a model's longer documentation).  One page per model module, so adding a model adds its own
page and edits no shared document; ``tests/test_physics_models.py`` fails while a registered
model has no page, a page is stale, or a page has no model.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fibrelmp.translate.granular import models as physics  # noqa: E402


def updated(model: type, old: str | None) -> str:
    """The page of ``model``: its generated part, then what followed the marker in ``old``."""
    kept = old.split(physics.PAGE_END, 1)[1] if old and physics.PAGE_END in old else ""
    return physics.model_page(model) + kept.removeprefix("\n")


def main() -> None:
    folder = ROOT / physics.MODEL_PAGES
    folder.mkdir(exist_ok=True)
    for model in physics.registered_models():
        page = folder / f"{physics.module_name(model)}.md"
        old = page.read_text() if page.exists() else None
        new = updated(model, old)
        if new != old:
            page.write_text(new)
            print(f"wrote {page.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
