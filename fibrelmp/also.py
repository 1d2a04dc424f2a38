"""``fibrelmp run --also NAME``: formats written from a run's own frames beside its results.

The registry's ALSO role names one ``RunOutput`` per such format (today ``vtk``,
``post.vtk.run_output``).  An input hook does not pick these writers: it hands the names the user
chose (``RunSettings.also``) and the base name of its result to ``granular_writers`` or
``fibrenet_writers``, which ask the registry.  The files are declared among the run's outputs
at plan time (checked and locked before LAMMPS starts, replaced only with ``--force``), and
the writers are made on rank 0 once the outputs are locked.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Iterator

from fibrelmp import registry
from fibrelmp.registry import ALSO

if TYPE_CHECKING:
    from fibrelmp.formatbase import Writer
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.model import Model
    from fibrelmp.outputs import Outputs
    from fibrelmp.runplan import Consumer

OPTION = "--also"


class RunOutput(ABC):
    """The ALSO hook of a format: its files beside a run's results, made from the run's frames.
    ``base`` is the result's path without its suffix (the format adds its own names)."""

    @abstractmethod
    def declare(self, outputs: "Outputs", base: Path) -> None:
        """Add the files of ``base`` to ``outputs``; a name the format cannot hold is an
        ``InputError`` here, before anything is written."""

    @abstractmethod
    def granular_writer(self, model: "GranularModel", base: Path) -> "Writer":
        """A writer of a granular run's frames (``GranularFrame``)."""

    @abstractmethod
    def fibrenet_writer(self, model: "Model", base: Path) -> "Writer":
        """A writer of a FibreNet job's dump frames (``post.lammps_dump`` ``Frame``)."""


def chosen(names: Iterable[str]) -> tuple[str, ...]:
    """The formats of ``--also`` (repeated or comma-separated), each once, in the given order;
    an unknown name is an ``InputError`` listing the choices."""
    picked: dict[str, None] = {}
    for item in names:
        for name in str(item).split(","):
            if name.strip():
                picked[registry.choose(ALSO, name.strip(), OPTION).name] = None
    return tuple(picked)


def hooks(names: Iterable[str]) -> list[RunOutput]:
    return [registry.choose(ALSO, name, OPTION).load(ALSO)() for name in names]


def granular_writers(names: Iterable[str], model: "GranularModel", outputs: "Outputs",
                     base: Path) -> Callable[[], list["Writer"]]:
    """For a granular run's writer list: declares the files of every chosen format in
    ``outputs`` now; the returned function makes their writers (rank 0, once the outputs are
    locked)."""
    outs = hooks(names)
    for out in outs:
        out.declare(outputs, base)
    return lambda: [out.granular_writer(model, base) for out in outs]


def fibrenet_writers(names: Iterable[str], model: "Model", outputs: "Outputs",
                     base: Path) -> Callable[[], list["Writer"]]:
    """As ``granular_writers``, for a FibreNet job's dump frames."""
    outs = hooks(names)
    for out in outs:
        out.declare(outputs, base)
    return lambda: [out.fibrenet_writer(model, base) for out in outs]


def also_to(consume: "Consumer", writers: list["Writer"]) -> "Consumer":
    """A consumer that hands every frame to ``writers`` too, before ``consume`` sees it;
    the writers are closed after ``consume`` succeeded, aborted if anything fails."""
    if not writers:
        return consume

    def run(frames: Iterator[Any]) -> list[Path]:
        def each() -> Iterator[Any]:
            for frame in frames:
                for writer in writers:
                    writer.add(frame)
                yield frame
        try:
            written = list(consume(each()))
            for writer in writers:
                written += writer.close()
        except BaseException:
            for writer in writers:
                writer.abort()
            raise
        return written
    return run
