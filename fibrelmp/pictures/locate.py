"""What a RESULT given to ``plot``/``snapshot`` is, and the run (work) folder it came from.

A RESULT is a run's work folder, a LAMMPS log, a LAMMPS dump or a result file of one of the
registered formats.  A result's work folder is found the way ``fibrelmp run`` names it
(``<name>_work`` beside the results, a cmusen script's ``<script>_work/jobN``): the
candidates beside the result that hold a LAMMPS log are taken in this order: the one
named after the result, else the only one there is.  Anything else is ambiguous and
no folder is used (the caller says so).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from fibrelmp.errors import InputError

LOG = "log"                   # a LAMMPS log (thermo)
WORK = "work"                 # a run's work folder
LOG_NAME = "log.lammps"
DUMP_NAME = "frames.dump"
DATA_NAME = "data.lammps"
# the suffixes fibrelmp gives a FibreNet result family (<prefix>_coord.xyz ...)
_FAMILY = re.compile(r"_(coord|vel|force|restart)$")


@dataclass(frozen=True)
class Located:
    kind: str          # LOG, WORK, or a registry format name
    path: Path


def locate(path: str | Path) -> Located:
    """The kind of ``path`` (by content where the registry can tell, else by name)."""
    from fibrelmp.registry import FRAMES, RESULT, check_regular_file, detect, formats

    path = Path(path)
    if path.is_dir():
        if not any((path / name).is_file() for name in (LOG_NAME, DUMP_NAME)):
            raise InputError(path, None, f"not a run's work folder (it has neither {LOG_NAME} "
                             f"nor {DUMP_NAME})")
        return Located(WORK, path)
    check_regular_file(path, "result")
    with open(path, "rb") as fh:
        head = fh.read(4096)
    if path.name == LOG_NAME or path.suffix == ".log" or head.startswith(b"LAMMPS ("):
        return Located(LOG, path)
    for fmt in formats(FRAMES):           # a LAMMPS dump (its reader claims it by content)
        if fmt.magic is not None and fmt.load(FRAMES).claims(path, None):
            return Located(fmt.name, path)
    suffix = path.suffix.lower()
    for fmt in formats(RESULT):           # result formats without content magic: by name
        if fmt.magic is None and suffix in fmt.extensions:
            return Located(fmt.name, path)
    fmt = detect(path)                    # inputs and results of the input formats
    if RESULT not in fmt.roles:
        raise InputError(path, None, f"{fmt.title} is a simulation input, not a result: give "
                         "a result file, the run's work folder or its log.lammps")
    return Located(fmt.name, path)


def family_prefix(result: Path) -> str:
    """The name a result shares with its run: ``x`` of ``x_coord.xyz``, ``x_12.json`` or
    ``x.mdem``."""
    stem = _FAMILY.sub("", result.stem)
    return re.sub(r"_\d+$", "", stem) if result.suffix.lower() == ".json" else stem


def work_folders(result: Path) -> list[Path]:
    """Work folders beside ``result`` that hold a LAMMPS run (``*_work`` and their ``job*``)."""
    found = []
    for folder in sorted(result.parent.glob("*_work")):
        if not folder.is_dir():
            continue
        for candidate in (folder, *sorted(folder.glob("job*"))):
            if (candidate / "in.lammps").is_file():
                found.append(candidate)
    return found


def run_folder(result: Path) -> tuple[Path | None, str]:
    """The work folder ``result`` came from, and how it was chosen (or why none was)."""
    prefix = family_prefix(result)
    candidates = work_folders(result)
    with_log = [c for c in candidates if (c / LOG_NAME).is_file()]
    named = [c for c in candidates if c.name == f"{prefix}_work"]
    if named:
        return named[0], f"the run folder {named[0].name}"
    if len(with_log) == 1:
        return with_log[0], f"the only run folder beside it, {with_log[0].relative_to(result.parent)}"
    if len(candidates) == 1:
        return candidates[0], f"the only run folder beside it, {candidates[0].relative_to(result.parent)}"
    if not candidates:
        return None, "no run folder (*_work) beside it"
    names = ", ".join(str(c.relative_to(result.parent)) for c in candidates)
    return None, f"several run folders beside it ({names}): give the one you mean"
