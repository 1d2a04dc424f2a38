"""A disk-backed list of GranularFrames: one ``.npz`` per saved time point.

A cmusen script may simulate once and export the same result several times (different
precision or time interval).  fibrelmp keeps the simulated frames here instead of in RAM,
so memory stays bounded by one frame whatever the number of saves.
"""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path
from typing import Iterator

import numpy as np

from fibrelmp.granmodel import GranularFrame

_FIELDS = [f.name for f in dataclasses.fields(GranularFrame)]


class FrameSpool:
    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        if self.folder.exists():
            shutil.rmtree(self.folder)
        self.folder.mkdir(parents=True)
        self.count = 0

    def add(self, frame: GranularFrame) -> None:
        arrays = {name: np.asarray(getattr(frame, name)) for name in _FIELDS
                  if getattr(frame, name) is not None}
        tmp = self.folder / f"frame_{self.count:06d}.tmp.npz"
        np.savez(tmp, **arrays)
        tmp.rename(self.folder / f"frame_{self.count:06d}.npz")
        self.count += 1

    def close(self) -> None:
        """Nothing to finish: every frame is on disk once added (a writer of the pipeline)."""

    def abort(self) -> None:
        """Kept until ``remove`` (the run plan's clean-up)."""

    def __len__(self) -> int:
        return self.count

    def __iter__(self) -> Iterator[GranularFrame]:
        for i in range(self.count):
            with np.load(self.folder / f"frame_{i:06d}.npz") as data:
                values = {name: data[name] for name in data.files}
            values["time"] = float(values["time"])
            values["step"] = int(values["step"])
            yield GranularFrame(**values)

    def times(self) -> np.ndarray:
        return np.array([float(np.load(self.folder / f"frame_{i:06d}.npz")["time"])
                         for i in range(self.count)])

    def remove(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)
