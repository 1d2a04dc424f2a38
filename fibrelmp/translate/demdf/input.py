"""DEMDF JSON documents (an input, or a snapshot to continue from): the input hook, and where
a run writes.  Its run plan is the shared granular request (``granular_run.request``) fed to
the snapshot writer; the pipeline executes it."""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.errors import InputError
from fibrelmp.inputformat import InputFormat, RunSettings, Say, Warn
from fibrelmp.translate.demdf.record import demdf_record

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.outputs import Outputs
    from fibrelmp.runplan import RunOptions, RunPlan
    from fibrelmp.translate.granular_job import GranularJob


class DemdfInput(InputFormat):
    name = "demdf"

    def read(self, path: Path, settings: RunSettings = RunSettings()) -> "GranularModel":
        """The document; ``settings``' --end-time, --steps and --save-step override its own."""
        from fibrelmp.translate.demdf import reader as demdf

        return demdf.read(path, time_end=settings.end_time, steps=settings.steps,
                          save_every=settings.save_step)

    def precision_unused(self, path: Path, out: Path | None) -> str | None:
        return "DEMDF snapshots keep every number exactly (shortest round-trip digits)"

    def check_lines(self, path: Path, model: "GranularModel") -> list[str]:
        from fibrelmp.granular_check import summary

        folder = demdf_outputs(model)[1]
        return summary(model) + [f"results      {folder / demdf_record(model).filename}"
                                 "_<n>.json (or in -o DIR)"]

    def write_job(self, model: "GranularModel", folder: Path) -> "GranularJob":
        from fibrelmp.translate.granular_job import write_granular_job

        return write_granular_job(model, folder)

    def plan(self, path: Path, settings: RunSettings, options: "RunOptions", say: Say,
             warn: Warn) -> "RunPlan":
        """Snapshots ``<filename>_<saveCount>.json`` next to the input (or in ``out``);
        earlier snapshots of the same name are replaced, all of them, only with ``force``."""
        from fibrelmp.also import granular_writers
        from fibrelmp.granular_run.request import granular_request
        from fibrelmp.runplan import RunPlan
        from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

        model = self.read(path, settings)
        warn(model.warnings)
        outputs, folder = demdf_outputs(model, settings.out, settings.work)
        extra = granular_writers(settings.also, model, outputs,
                                 folder / str(demdf_record(model).filename))
        request = granular_request(model, outputs.work,
                                   lambda: [DemdfSnapshotWriter(model, folder)] + extra())
        return RunPlan(outputs, [request], options)

    def work_folder(self, path: Path, out: Path | None, work: Path | None) -> Path:
        return _folders(path, out, work)[1]


def _folders(source: str | Path, out: str | Path | None, work: str | Path | None) -> tuple[Path, Path]:
    """(the snapshots' folder: the input's or ``out``; the work folder: ``work``, default
    ``<input stem>_work`` in the snapshots' folder)."""
    folder = (Path(out) if out is not None else Path(source).parent).resolve()
    from fibrelmp.outputs import work_folder

    return folder, work_folder(folder, Path(source).stem, work)


def demdf_outputs(model: "GranularModel", out: str | Path | None = None,
                  work: str | Path | None = None) -> tuple["Outputs", Path]:
    """Where a DEMDF run writes: ``<filename>_<n>.json`` in the input's folder (or ``-o``);
    a ``filename`` that leaves that folder is refused."""
    from fibrelmp.outputs import Outputs

    info = demdf_record(model)
    folder, work_folder = _folders(model.source, out, work)
    name = str(info.filename)
    if Path(name).is_absolute() or ".." in Path(name).parts or "/" in name or "\\" in name:
        raise InputError(model.source, None, f"output filename {name!r} must be a plain file name: "
                         f"snapshots are written into {folder}")
    inputs = [Path(model.source)] + ([Path(info.particles_file)] if info.particles_file else [])
    pattern = re.compile(re.escape(name) + r"_\d+\.json")
    return Outputs(Path(model.source), work_folder, patterns=[(folder, pattern)], inputs=inputs), folder
