"""Input-format registry: detection by content ("magic") first, then by extension.

Each entry names the reader module; readers are imported lazily so ``fibrelmp check`` on a
FibreNet file never imports the DEM code (and vice versa).
"""

from __future__ import annotations

import re
from pathlib import Path
from types import ModuleType

from .errors import InputError

# name -> (module path, content test, extensions that pick the reader when the content test
# fails, so that reader explains what is wrong; ".txt" is too common to mean MUSEN)
_READERS: dict[str, tuple[str, re.Pattern, tuple[str, ...]]] = {
    "fibrenet": ("fibrelmp.translate.fibrenet", re.compile(rb"^[ \t]*model_file\s", re.M), ()),
    "musen-script": ("fibrelmp.translate.musen_script",
                     re.compile(rb"^[ \t]*(JOB|SOURCE_FILE|COMPONENT)\b", re.M), ()),
    # an object line "0 ID 1 TYPE 5 ...", or a scene line (22 domain / 32 material) of an object-less scene
    "musen": ("fibrelmp.translate.musen",
              re.compile(rb"\A\s*(0\s+\d+\s+1\s+\d+\s+5\b|(22|32)\s+\S)"), ()),
    "demdf": ("fibrelmp.translate.demdf", re.compile(rb"\A\s*\{"), (".json",)),
}

_HINT = ("expected a FibreNet input (with a 'model_file' line), a MUSEN text scene, a cmusen job "
         "script or a DEMDF JSON file")


DETECT_BYTES = 1 << 20          # detection reads at most this much of a file


def check_regular_file(path: Path, what: str = "input") -> None:
    """A readable regular file: not missing, not a folder, not a device or FIFO (reading
    /dev/zero never ends, a FIFO blocks for ever)."""
    from .textio import refuse_special_file

    try:
        refuse_special_file(path, what)
    except FileNotFoundError:
        raise InputError(path, None, f"{what} file not found") from None
    except OSError as exc:
        raise InputError(path, None, f"cannot read {what}: {exc.strerror or exc}") from None
    if path.is_dir():
        raise InputError(path, None, f"{what} is a directory, expected a file")


def detect(path: str | Path) -> str:
    path = Path(path)
    check_regular_file(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(DETECT_BYTES)
    except OSError as exc:
        raise InputError(path, None, f"cannot read input: {exc.strerror or exc}") from None
    if path.suffix.lower() == ".mdem":
        raise InputError(path, None, "binary MUSEN .mdem files cannot be read: export the scene "
                         "as text (MUSEN: File > Export > Text, or a cmusen job with "
                         "'COMPONENT EXPORT_TO_TEXT') and run that file")
    if head.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError(path, None, "the file is UTF-16 encoded; save it as UTF-8 (or ASCII) text")
    if head.startswith(b"\xef\xbb\xbf"):        # UTF-8 byte-order mark: the readers accept it
        head = head[3:]
    for name, (_, magic, _) in _READERS.items():
        if magic.search(head):
            return name
    for name, (_, _, exts) in _READERS.items():
        if path.suffix.lower() in exts:
            return name                 # let the reader explain what is wrong inside
    raise InputError(path, None, f"cannot tell the input format: {_HINT}")


def reader(name: str) -> ModuleType:
    import importlib

    return importlib.import_module(_READERS[name][0])
