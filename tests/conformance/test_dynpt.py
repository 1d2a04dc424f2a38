"""openCARP ``.dynpt`` node positions over time: the conformance checks of the ``motion``
role, on IGB files built here byte by byte (not by fibrelmp's writer)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .base import MotionConformance

HEADER = 1024          # the IGB header's size (openCARP)


def igb(items: bytes, values: np.ndarray) -> bytes:
    """A header as meshalyzer writes it (items, CR LF, space padding, form feed), then data."""
    head = items + b" \r\n"
    return head + b" " * (HEADER - len(head) - 1) + b"\f" + values.astype("<f4").tobytes()


class TestDynptMotion(MotionConformance):
    format = "dynpt"

    def sample(self, folder: Path):
        values = np.arange(3 * 2 * 3, dtype=np.float64) * 1.5 - 4.0    # 3 frames of 2 nodes, µm
        path = folder / "move.dynpt"
        path.write_bytes(igb(b"x:2 y:1 z:1 t:3 type:vec3f systeme:little_endian org_t:1 inc_t:2.5 "
                             b"unites_t:ms", values))
        return path, [(1.0 + 2.5 * k, values[6 * k:6 * k + 6].reshape(2, 3)) for k in range(3)]

    def bad_samples(self, folder: Path) -> list[Path]:
        good, _ = self.sample(folder)
        data = good.read_bytes()
        edits = {"short.dynpt": data[:HEADER + 10],                          # truncated frames
                 "float.dynpt": data.replace(b"vec3f", b"float"),           # not positions
                 "huge.dynpt": data.replace(b"t:3 ", b"t:" + b"9" * 20 + b" "),  # hostile count
                 "nan.dynpt": data[:HEADER] + np.full(18, np.nan, "<f4").tobytes()}
        for name, content in edits.items():
            (folder / name).write_bytes(content)
        return [folder / name for name in edits]
