"""The two exception types every fibrelmp module raises.

Only the CLI turns them into exit codes: InputError -> 2, RunError -> 1.
"""

from __future__ import annotations

from os import PathLike


class InputError(Exception):
    """Bad user input, reported as ``path:line: message`` (line may be omitted)."""

    def __init__(self, path: str | PathLike | None, line: int | None, message: str):
        self.path = None if path is None else str(path)
        self.line = line
        self.message = message
        super().__init__(str(self))

    def __str__(self) -> str:
        where = self.path or "<input>"
        if self.line is not None:
            where = f"{where}:{self.line}"
        return f"{where}: {self.message}"


class RunError(Exception):
    """LAMMPS (or the machine) failed while running a valid input."""
