"""FibreNet's reference samples for the conformance tests (tests/conformance/test_fibrenet.py,
test_xyz.py, test_res.py): the sample input under the repository and the builders of small
xyz and restart files (docs/architecture.md, "Conformance tests")."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

INPUT = "examples/fibre_network/input.txt"          # the fibre-network example (input)


def xyz_result(folder: Path) -> tuple[Callable, list]:
    """(a factory of an ``XyzWriter`` of positions into ``folder/run``, three frames of two
    beads)."""
    from fibrelmp.translate.fibrenet.writer import XyzFrame, XyzWriter

    frames = [XyzFrame(10 * k, 0.1, np.ones(3) * 5, ["a", "b"], np.full((2, 3), 0.5 + k))
              for k in range(3)]
    return (lambda: XyzWriter(folder / "run", fields=("position",))), frames


def restart_result(folder: Path) -> tuple[Callable, list]:
    """(a factory of a ``RestartWriter`` into ``folder/run_restart.res``, three states of two
    beads)."""
    from fibrelmp.translate.fibrenet.writer import RestartState, RestartWriter

    z = np.zeros((2, 3))
    frames = [RestartState(10 * k, 0.1, np.ones(3) * 5, np.array([0, 1]), ["a", "b"], z + k, z + k, z, z)
              for k in range(3)]
    return (lambda: RestartWriter(folder / "run_restart.res")), frames
