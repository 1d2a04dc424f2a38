"""Input-format registry: detection by content ("magic") first, then by extension."""

from __future__ import annotations

import re
from pathlib import Path
from types import ModuleType

from .errors import InputError

# name -> (module path, content test)
_READERS: dict[str, tuple[str, re.Pattern]] = {
    "fibrenet": ("fibrelmp.translate.fibrenet", re.compile(rb"^\s*model_file\s", re.M)),
}


def detect(path: str | Path) -> str:
    path = Path(path)
    if not path.exists():
        raise InputError(path, None, "input file not found")
    if path.is_dir():
        raise InputError(path, None, "input is a directory, expected a file")
    try:
        head = path.read_bytes()[:1 << 20]
    except OSError as exc:
        raise InputError(path, None, f"cannot read input: {exc.strerror or exc}") from None
    for name, (_, magic) in _READERS.items():
        if magic.search(head):
            return name
    raise InputError(path, None, "cannot tell the input format: expected a FibreNet input "
                     "(with a 'model_file' line)")


def reader(name: str) -> ModuleType:
    import importlib

    return importlib.import_module(_READERS[name][0])
