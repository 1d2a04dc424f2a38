"""The MDAnalysis reader's reference samples for the conformance tests
(tests/conformance/test_mdanalysis.py; docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path

ATOMS = 2


def trajectories(folder: Path) -> tuple[Path, Path]:
    """(a 3-frame XYZ trajectory of ``ATOMS`` atoms, a file that is no trajectory)."""
    good = folder / "t.xyz"
    good.write_text("".join(f"2\nframe {k}\nC 0 0 {k}\nO 1 0 {k}\n" for k in range(3)))
    bad = folder / "bad.xyz"
    bad.write_text("not a trajectory\n")
    return good, bad
