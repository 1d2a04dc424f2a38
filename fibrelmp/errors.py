"""The two exception types every fibrelmp module raises.

Only the CLI turns them into exit codes: InputError -> 2, RunError -> 1.

Their text is printed to a terminal and often quotes user text (paths, tokens, LAMMPS
output): control characters in it (a raw carriage return, ESC of a terminal sequence,
Unicode direction overrides) are shown escaped (``\\r``, ``\\x1b``, ``\\u202e``) so they
cannot garble or disguise the message; all other text is left as it is.
"""

from __future__ import annotations

import re
from os import PathLike

# C0 controls (but tab), DEL, C1 controls, line/paragraph separators and the Unicode
# direction overrides / isolates
_CONTROL = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")
_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def _escape(m: re.Match) -> str:
    c = m.group()
    if c in _NAMED:
        return _NAMED[c]
    code = ord(c)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def visible(text: str, keep_newlines: bool = False) -> str:
    """``text`` with control characters escaped; ``keep_newlines`` leaves ``\\n`` as is
    (multi-line messages)."""
    if not _CONTROL.search(text):
        return text
    if keep_newlines:
        return "\n".join(_CONTROL.sub(_escape, part) for part in text.split("\n"))
    return _CONTROL.sub(_escape, text)


class InputError(Exception):
    """Bad user input, reported as ``path:line: message`` (line may be omitted).

    ``path`` and ``message`` keep the raw text; ``str()`` shows control characters escaped.
    """

    def __init__(self, path: str | PathLike | None, line: int | None, message: str):
        self.path = None if path is None else str(path)
        self.line = line
        self.message = message
        super().__init__(str(self))

    def __str__(self) -> str:
        where = visible(self.path) if self.path else "<input>"
        if self.line is not None:
            where = f"{where}:{self.line}"
        return f"{where}: {visible(self.message)}"


class RunError(Exception):
    """LAMMPS (or the machine) failed while running a valid input.

    ``str()`` shows control characters escaped (line breaks of multi-line messages kept)."""

    def __str__(self) -> str:
        return visible(super().__str__(), keep_newlines=True)


class InputErrors(InputError):
    """Several input errors of one check (``fibrelmp check`` lists them all); the first is
    the one ``path``/``line``/``message`` describe."""

    def __init__(self, errors: list[InputError], at_limit: bool = False):
        self.errors = list(errors)
        self.at_limit = at_limit
        first = self.errors[0]
        super().__init__(first.path, first.line, first.message)

    def __str__(self) -> str:
        more = " (the limit: fix these and check again)" if self.at_limit else ""
        return ("\nerror: ".join(InputError.__str__(e) for e in self.errors)
                + f"\n{len(self.errors)} errors{more}")


def wrong_frame(path: str | PathLike, step: int, found: int | None) -> RunError:
    """The error of a frame source that found another frame (or none) than the scheduled one
    (here, below every frame source: the pipeline's and CardioProof's)."""
    what = "no more frames" if found is None else f"step {found}"
    return RunError(f"{path}: expected the frame of step {step}, found {what}")
