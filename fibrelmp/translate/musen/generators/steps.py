"""Generator jobs of a cmusen script (PACKAGE_GENERATOR, BONDS_GENERATOR, SNAPSHOT_GENERATOR)
for ``script_input``'s planner.

A generator is pre-processing: it runs while the script is planned (seconds), so that a
later SIMULATOR job is checked and built on the scene it made, as for an imported scene.
The generated ``.mdem`` waits in a temporary folder until the run writes it to its
RESULT_FILE (``write_generated``).
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Callable

from fibrelmp.errors import InputError

Say = Callable[[str], None]
KINDS = {"PACKAGE_GENERATOR": "package", "BONDS_GENERATOR": "bonds",
         "SNAPSHOT_GENERATOR": "snapshot"}


class GeneratedFiles:
    """The ``.mdem`` files generators and imports made during planning, by handle."""

    def __init__(self) -> None:
        self._tmp = tempfile.TemporaryDirectory(prefix="fibrelmp-generated.")
        self.files: dict[Path, Path] = {}
        self.log: dict[Path, list[str]] = {}

    def new(self, handle: Path) -> Path:
        return Path(self._tmp.name) / f"{len(self.files)}-{handle.name}"


def source_mdem(job, source: Path, handles: dict, made: GeneratedFiles) -> Path:
    """The ``.mdem`` a generator job reads: one made earlier in the script (an import is
    converted now), or a file made elsewhere."""
    from fibrelmp.translate.musen.input import is_mdem

    if source in made.files:
        return made.files[source]
    if source in handles:
        kind, _ = handles[source]
        raise InputError(job.path, job.where("SOURCE_FILE"), f"{job.component}: {job.source_file} "
                         f"is the {'simulation result' if kind == 'result' else 'scene'} of an "
                         "earlier job of this script; fibrelmp's generators read a .mdem file "
                         "made before the script runs or by an earlier generator or import")
    if not source.exists():
        raise InputError(job.path, job.where("SOURCE_FILE"), f"SOURCE_FILE {source}: file not found")
    if not is_mdem(source):
        raise InputError(job.path, job.where("SOURCE_FILE"), f"{job.component} reads a .mdem "
                         f"scene (cmusen too); {job.source_file} is not one: import it first "
                         "(COMPONENT IMPORT_FROM_TEXT)")
    return source


def remember_import(handle: Path, text_source: Path, made: GeneratedFiles) -> None:
    """An IMPORT_FROM_TEXT's scene as a .mdem, for a generator job after it."""
    from fibrelmp.translate.musen.mdem.convert import MdemDocumentWriter, MusenTextDocument

    target = made.new(handle)
    with MdemDocumentWriter(target) as out:
        out.add(MusenTextDocument.open(text_source))
    made.files[handle] = target


def run_generator(job, source: Path, handle: Path, made: GeneratedFiles, say: Say):
    """Runs the job's generator now; the scene it made (a ``GranularModel``)."""
    from fibrelmp.translate.musen.generators import jobs, snapshot
    from fibrelmp.translate.musen.mdem.model import read_scene

    kind = KINDS[job.component]
    lines: list[str] = []
    if kind == "package":
        scene = jobs.run_package_generator(source, job, lines.append)
    elif kind == "bonds":
        scene = jobs.run_bonds_generator(source, job, lines.append)
    else:
        scene = snapshot.snapshot(source, job)
    target = made.new(handle)
    with open(target, "w+b") as fh:
        scene.write(fh)
    made.files[handle] = target
    made.log[handle] = lines
    for line in lines:
        say(line)
    return read_scene(target)


def write_generated(handle: Path, written: Path, made: GeneratedFiles) -> Path:
    """Copies a generated file to its RESULT_FILE."""
    written.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(made.files[handle], written)
    return written
