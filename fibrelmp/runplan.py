"""What a run is made of: ``RunRequest`` (one LAMMPS simulation) and ``RunPlan`` (the
requests of one input, with the import/export ``Action``\\ s of a cmusen script between them,
and the outputs they lock together); ``feed``, the consumer that hands a request's frames to
its result writers.

The pieces are plain callables, so a request says *what* to run and the pipeline
(``fibrelmp.pipeline.run``) alone decides *how*: rendering, checkpoints, the converter
thread, frame scheduling, locking and finishing outputs.  These types sit in the core layer
so that each format's home builds its own plan (``InputFormat.plan``) without importing the
pipeline, which only executes plans.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Iterator, Protocol, Union

if TYPE_CHECKING:
    from fibrelmp.outputs import Outputs
    from fibrelmp.particles import ParticleModel
    from fibrelmp.runner import LogEvery


# the script commands that write a frame: LAMMPS's write_dump, and fibrenet/frame (fix
# fibrenet/output writes FibreNet's files and the work dump)
FRAME_COMMANDS = frozenset({"write_dump", "fibrenet/frame"})
# the script commands that create the box and the atoms (a resumed run reads its restart there):
# LAMMPS's read_data, and fibrenet/read_data (a FibreNet job's binary topology file)
DATA_COMMANDS = frozenset({"read_data", "fibrenet/read_data"})


@dataclass(frozen=True)
class RunOptions:
    """How to run (the same for every simulation of a plan)."""
    progress: bool = True              # a progress bar on a terminal
    force: bool = False                # replace the results of an earlier run
    checkpoint_every: int | None = None   # steps between checkpoints (None: on signals only)
    resume: bool = False               # continue from the checkpoint in the work folder
    log_every: "LogEvery | None" = None   # progress lines without a terminal (None: the default)
    allow_huge: bool = False           # run --yes-i-mean-it: no disk-space or run-time refusal


@dataclass
class Rendered:
    """A job rendered for LAMMPS: ``job.script`` replays with ``lmp -in in.lammps``."""
    job: Any                           # translate.lammps_job.Job or granular_job.GranularJob
    text: str                          # the script (also on MPI ranks that wrote no file)
    schedule: Iterable[int]            # the steps of the saved frames, in order (lazy)
    dumps: list[Path]                  # files the script appends to (cut back on resume)
    finished: Callable[[Any], None] | None = None   # called with LAMMPS after the last command

    @property
    def folder(self) -> Path:
        return Path(self.job.folder)

    @property
    def script(self) -> Path:
        return Path(self.job.script)

    @property
    def data(self) -> Path:
        return Path(self.job.data)

    @property
    def inputs(self) -> list[Path]:
        """The files the script reads (the data file, a state file): hashed by checkpoints."""
        return [Path(p) for p in getattr(self.job, "inputs", [self.job.data])]

    @property
    def total_steps(self) -> int:
        return int(self.job.total_steps)


class FrameSource(Protocol):
    """Reads the saved frames back from a running job's dumps, one at a time, in order."""

    def is_frame(self, words: list[str]) -> bool:
        """Did this script command (split in words) write a frame?"""

    def read(self, step: int) -> Any:
        """The next frame, which must be the one of ``step`` (else a RunError)."""

    def close(self) -> None:
        """Release open files."""


# the rendered-job builder: (job folder, write the files: rank 0) -> Rendered
JobBuilder = Callable[[Path, bool], Rendered]
# frames in, result files out: the writers are closed when the frames end, aborted on an error
Consumer = Callable[[Iterator[Any]], list[Path]]


@dataclass
class RunRequest:
    """One simulation: a neutral model, how to render and read it, and what its frames feed."""
    model: "ParticleModel"          # any family (Model, GranularModel, SphCase)
    build: JobBuilder                                  # renders the LAMMPS job
    frames: Callable[[Rendered], FrameSource]          # reads the frames the job saves
    results: Callable[[Rendered], Consumer]            # the native writers (rank 0 only)
    work: Path                                         # the job folder
    # what the run summary records (None: fibrelmp.record.Recorder, FibreNet and granular runs)
    recorder: Callable[[Any, Any, str], Any] | None = None


@dataclass
class Action:
    """A step of a multi-job script that runs no simulation (cmusen import, export):
    ``run(rank0)`` returns the result files it wrote."""
    run: Callable[[bool], list[Path]]


Step = Union[RunRequest, Action]


@dataclass
class RunPlan:
    """Everything one input runs: its outputs (checked and locked together, before anything
    runs) and its steps, in order."""
    outputs: "Outputs"
    steps: list[Step]
    options: RunOptions = RunOptions()
    notes: list[str] = field(default_factory=list)        # for the user (renamed results...)
    cleanup: list[Callable[[], None]] = field(default_factory=list)   # run after, always


@dataclass
class Outcome:
    """What a plan wrote, and the jobs it ran (their scripts and dumps stay in the work folder)."""
    outputs: list[Path] = field(default_factory=list)
    jobs: list[Rendered] = field(default_factory=list)
    summaries: list[dict] = field(default_factory=list)   # fibrelmp.record, one per simulation


def feed(writers: list, model: Any = None) -> Consumer:
    """A consumer that adds every frame to each writer (``add``/``close``/``abort``): all are
    closed when the frames end and aborted (their temp files removed) on any failure.  It
    returns the files the writers report (``close()``'s paths, or their ``written`` list).
    A frame holding nan/inf is a RunError (``fibrelmp.finite``; ``model`` names its particles)."""
    from fibrelmp.finite import guarded

    def consume(frames: Iterator[Any]) -> list[Path]:
        try:
            for frame in guarded(frames, model):
                for writer in writers:
                    writer.add(frame)
        except BaseException:
            for writer in writers:
                writer.abort()
            raise
        # every writer writes its last files before any file is renamed into place: a
        # writer failing at the end leaves no output of the others behind
        try:
            for writer in writers:
                prepare = getattr(writer, "prepare", None)
                if prepare is not None:
                    prepare()
        except BaseException:
            for writer in writers:      # abort never raises, and a closed writer ignores it
                writer.abort()
            raise
        written: list[Path] = []
        for k, writer in enumerate(writers):
            try:
                done = writer.close()
            except BaseException:
                for rest in writers[k + 1:]:
                    rest.abort()
                raise
            written += _files(writer, done)
        return written
    return consume


def _files(writer, closed) -> list[Path]:
    if isinstance(closed, (str, os.PathLike)):
        return [Path(closed)]
    if closed:
        return [Path(p) for p in closed]
    return [Path(p) for p in getattr(writer, "written", [])]
