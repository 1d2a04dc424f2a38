"""A toy ``post --to csv`` target: one CSV file with every frame's atoms.

The whole of what adding an output format takes (docs/architecture.md): this module and
one ``register_format`` call (tests/conformance/test_registry.py makes it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fibrelmp.post.target import DumpTarget, ReadBack
from fibrelmp.registry import TARGET, Format


class CsvTarget(DumpTarget):
    """``<base>.csv``: a ``time,id,type,x,y,z`` row per atom and frame."""

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        return [base.with_name(base.name + ".csv")]

    def start(self, first: list) -> None:
        self.out = self.open(self.files(self.target)[0], "w")     # staged; renamed by close()
        self.out.write("time,id,type,x,y,z\n")

    def write_frame(self, frame) -> None:
        time = self.time_of(frame)
        for i, t, (x, y, z) in zip(frame.column("id"), frame.column("type"), frame.wrapped()):
            self.out.write(f"{time!r},{i:.0f},{t:.0f},{x:.17g},{y:.17g},{z:.17g}\n")

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        rows = np.loadtxt(files[0], delimiter=",", skiprows=1, ndmin=2)
        return [ReadBack(rows[rows[:, 0] == t, 3:6]) for t in dict.fromkeys(rows[:, 0])]


CSV = Format("csv", "atoms as CSV rows (time,id,type,x,y,z)", "any",
             {TARGET: "tests.csv_target:CsvTarget"}, extensions=(".csv",))
