"""The input-format hook: what ``run``/``check``/``translate`` need from each input format.

The registry (``fibrelmp.registry``, role INPUT) names one ``InputFormat`` subclass per
format; ``python_api`` detects the format, loads its hook and calls only the methods below,
so a new input format is one subclass and one ``register_format`` line, and never falls into
another format's code.  This base sits in the core layer so that a format's home (which the
pipeline imports, never the other way) can derive its hook; a hook builds its ``RunPlan``
from the core's plan types (``fibrelmp.runplan``) and the pipeline executes it.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, ClassVar

from fibrelmp.errors import InputError

if TYPE_CHECKING:
    from fibrelmp.runplan import RunOptions, RunPlan
    from fibrelmp.textio import Patch

Say = Callable[[str], None]
Warn = Callable[[list[tuple[str, str]]], None]


@dataclass(frozen=True)
class RunSettings:
    """Where a run writes and what it overrides (``fibrelmp run``'s options)."""
    out: Path | None = None            # results: a folder, or the file of a single result
    work: Path | None = None           # the LAMMPS job folder
    end_time: float | None = None      # --end-time
    step: float | None = None          # --step (the simulation time step)
    save_step: float | None = None     # --save-step
    steps: int | None = None           # --steps
    precision: int = 6                 # significant digits of text results that take it
    also: tuple[str, ...] = ()         # --also: formats also written from the frames (fibrelmp.also)

    def overrides(self) -> tuple:
        return (self.end_time, self.step, self.save_step, self.steps)


class InputFormat(ABC):
    """The hook of one input format."""

    name: ClassVar[str] = ""            # the registry name
    # what ``check`` says about the LAMMPS styles a job uses (None: fibrelmp's plugin or stock)
    styles: ClassVar[str | None] = None

    @abstractmethod
    def read(self, path: Path) -> Any:
        """The neutral model of the input (``fibrelmp.read``)."""

    def model(self, path: Path) -> Any:
        """The model ``check`` and ``translate`` show (a ``Model`` or ``GranularModel``)."""
        return self.read(path)

    def check_patch(self, path: Path) -> "Patch | None":
        """What ``check`` puts in place of a failing line to find the next error
        (``textio.collect_errors``); None: the format reports its first error only."""
        return None

    @abstractmethod
    def check_lines(self, path: Path, model: Any) -> list[str]:
        """``check``'s summary of ``model`` (read from ``path``), ending with where the
        results would go."""

    @abstractmethod
    def write_job(self, model: Any, folder: Path) -> Any:
        """Render ``folder/in.lammps`` and its data file; the job (``.script``, ``.data``)."""

    @abstractmethod
    def plan(self, path: Path, settings: RunSettings, options: "RunOptions", say: Say,
             warn: Warn) -> "RunPlan":
        """The run of the input: read it (its warnings go to ``warn``), apply ``settings``
        and give what ``pipeline.run`` executes."""

    @abstractmethod
    def work_folder(self, path: Path, out: Path | None, work: Path | None) -> Path:
        """The work folder a run with these options uses."""

    def precision_unused(self, path: Path, out: Path | None) -> str | None:
        """Why ``--precision`` has no meaning for this input's results, or None when they
        take it (text results written with that many significant digits)."""
        return "its results are not written with a chosen number of significant digits"

    def has_checkpoint(self, path: Path, out: Path | None = None, work: Path | None = None) -> bool:
        """Is there a checkpoint to ``--resume`` from?"""
        from fibrelmp.checkpoint import has_checkpoint

        return has_checkpoint(self.work_folder(Path(path), out, work))


def no_overrides(path: Path, settings: RunSettings, message: str) -> None:
    """Refuse --end-time/--step/--save-step/--steps for inputs that set their own."""
    if any(v is not None for v in settings.overrides()):
        raise InputError(path, None, message)
