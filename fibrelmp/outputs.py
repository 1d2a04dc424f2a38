"""Where a run writes, checked and locked before LAMMPS starts.

Every run (FibreNet, MUSEN scene, cmusen script, DEMDF) describes its outputs as an
``Outputs``: the exact files it writes, the files of earlier runs it replaces (a family: all
four FibreNet files, every ``<filename>_<n>.json`` snapshot), the files it reads (never
overwritten) and its work folder.  ``prepare`` refuses, as an InputError before anything is
written, an output that is an input, a location under a regular file or not writable, and
existing results unless ``force``; then it creates the folders and takes an exclusive lock on
each (``flock`` on the folder itself: nothing is left behind, and a killed run releases it).
While the run holds the lock, every result renamed into place keeps the file it replaced
aside (``formatbase.replacing``): a run that fails at any point, even after some of its
writers finished, leaves the earlier results as they were and none of its own.  ``finish``
removes what an earlier run wrote that this run did not (``--force`` replaces results
completely).
"""

from __future__ import annotations

import errno
import fcntl
import os
import re
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

from fibrelmp.errors import InputError
from fibrelmp.formatbase import replacing


# what a run writes into its work folder (translate.lammps_job / granular_job, checkpoint)
WORK_FILES = frozenset({"in.lammps", "data.lammps", "frames.dump", "bonds.dump", "walls.dump",
                        "breaks.dump", "stress_contacts.dump", "stress_walls.dump",
                        "checkpoint.json",
                        "log.lammps", "data.fibrelmp.json",
                        "fibrenet_state.txt", "bond_geometry.txt", "summary.json"})


@dataclass
class Outputs:
    source: Path                                    # the input (for messages)
    work: Path                                      # job folder(s) live here
    files: list[Path] = field(default_factory=list)         # written by this run
    family: list[Path] = field(default_factory=list)        # earlier runs' files this run replaces
    patterns: list[tuple[Path, re.Pattern]] = field(default_factory=list)   # families by name
    inputs: list[Path] = field(default_factory=list)        # read by this run: never written

    def folders(self) -> list[Path]:
        found = {f.parent for f in self.files} | {f.parent for f in self.family} | \
            {folder for folder, _ in self.patterns}
        return sorted(found | {self.work})

    def existing(self) -> list[Path]:
        """Results of earlier runs this run would replace."""
        found = [f for f in dict.fromkeys(self.files + self.family) if f.is_file()]
        for folder, pattern in self.patterns:
            if folder.is_dir():
                found += sorted(p for p in folder.iterdir() if pattern.fullmatch(p.name) and p.is_file())
        return list(dict.fromkeys(found))


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and os.path.samefile(a, b))
    except OSError:
        return False


def _check_location(path: Path, what: str) -> None:
    """``path`` can be created: its nearest existing ancestor is a writable folder."""
    if path.is_dir() and what == "output":
        raise InputError(path, None, "is a directory, but fibrelmp writes a result file there")
    probe = path.parent if what == "output" else path
    while not probe.exists():
        if probe.is_symlink():
            raise InputError(probe, None, f"{what} location: a broken symbolic link")
        probe = probe.parent
    if not probe.is_dir():
        raise InputError(probe, None, f"is a file, so the {what} location {path} cannot be created below it")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise InputError(probe, None, f"{what} location {path}: this folder is not writable")


def check(outputs: Outputs, force: bool) -> None:
    """Everything about the locations that can be known before the run (no side effects)."""
    for out in outputs.files + outputs.family:
        for inp in outputs.inputs:
            if _same_file(out, inp):
                raise InputError(out, None, f"is an input of this run ({outputs.source}) and would "
                                 "be overwritten by a result: choose another result name")
        _check_location(out, "output")
    for inp in outputs.inputs:
        # the job files a run writes into its work folder (cmusen scripts: one level down)
        inp = Path(inp).resolve()
        work = Path(outputs.work).resolve()
        if inp.name in WORK_FILES and work in (inp.parent, inp.parent.parent):
            raise InputError(inp, None, f"is an input, and the run writes its own {inp.name} in "
                             f"the work folder {work}: choose another --work")
    _check_location(outputs.work, "work folder")
    if outputs.work.exists() and not outputs.work.is_dir():
        raise InputError(outputs.work, None, "is a file, not a folder (--work)")
    if not force:
        old = outputs.existing()
        if old:
            more = f" and {len(old) - 1} more" if len(old) > 1 else ""
            raise InputError(old[0], None, f"exists already{more} (results of an earlier run): "
                             "give --force to replace them, or choose another output location")


@contextmanager
def locked(outputs: Outputs, force: bool, rank: int = 0) -> Iterator[Outputs]:
    """Check, create the folders, lock them for this run; rank 0 only does the file work
    (other MPI ranks only check)."""
    check(outputs, force)
    if rank != 0:
        yield outputs
        return
    fds: list[int] = []
    created: list[Path] = []          # removed again when a later location fails
    succeeded = False
    try:
        for folder in outputs.folders():
            try:
                missing = [p for p in [folder, *folder.parents] if not p.exists()]
                folder.mkdir(parents=True, exist_ok=True)
                created += missing
                fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
            except OSError as exc:
                raise InputError(folder, None, f"cannot create the folder: {exc.strerror or exc}") from None
            fds.append(fd)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                if exc.errno in (errno.EWOULDBLOCK, errno.EACCES):
                    raise InputError(folder, None, "another fibrelmp run is using this folder; "
                                     "wait for it to finish, or choose another output/work "
                                     "location") from None
                raise
            try:     # writable in fact (read-only mounts, quotas), not just by its mode bits
                fh, name = tempfile.mkstemp(prefix=".fibrelmp-probe-", dir=folder)
                os.close(fh)
                os.unlink(name)
            except OSError as exc:
                raise InputError(folder, None, f"cannot write here: {exc.strerror or exc}") from None
        _remove_stale_temps(outputs)
        # every result this run renames into place replaces its earlier file only for good
        # when the whole run succeeds: a failure puts the earlier set back (formatbase)
        with replacing(outputs.folders()):
            yield outputs
        succeeded = True
    finally:
        for fd in fds:
            os.close(fd)          # closing releases the lock
        # a failure removes the folders this run created while they are still empty (a run
        # refused while translating leaves nothing; one that failed in LAMMPS keeps its log)
        if not succeeded:
            for folder in sorted(set(created), key=lambda p: len(p.parts), reverse=True):
                try:
                    folder.rmdir()
                except OSError:
                    pass


def _remove_stale_temps(outputs: Outputs) -> None:
    """Temp files of a killed earlier run (SIGKILL leaves no chance to clean up)."""
    names = {f.name for f in outputs.files + outputs.family}
    for folder in {f.parent for f in outputs.files + outputs.family} | {p for p, _ in outputs.patterns}:
        if not folder.is_dir():
            continue
        for p in folder.glob(".*.tmp*"):
            base = p.name[1:].split(".tmp", 1)[0]
            if base in names or any(pat.fullmatch(base) for fo, pat in outputs.patterns if fo == folder):
                p.unlink(missing_ok=True)


def finish(outputs: Outputs, written: list[Path]) -> list[Path]:
    """After success: remove the earlier runs' files this run did not write again."""
    keep = {Path(p).resolve() for p in written}
    removed = []
    for old in outputs.existing():
        if old.resolve() not in keep:
            old.unlink(missing_ok=True)
            removed.append(old)
    return removed


def work_folder(results: str | os.PathLike, name: str, work: str | os.PathLike | None) -> Path:
    """The folder of a run's LAMMPS job: ``work`` when given, else ``<name>_work`` beside the
    results (``results`` is their folder); absolute."""
    return (Path(work) if work is not None else Path(results) / f"{name}_work").resolve()
