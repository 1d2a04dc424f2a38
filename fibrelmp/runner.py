"""Run a rendered LAMMPS script in-process, line by line, with progress and MPI safety.

The same file replays with ``lmp -in in.lammps``: the runner adds nothing but progress.
MPI rule: LAMMPS runs on every rank; only rank 0 writes files and progress; any error
aborts all ranks.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Callable

from ._lammps import new_lammps
from .errors import RunError
from .lammps_text import input_lines, read_script

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .checkpoint import Checkpointing  # noqa: F401


def mpi_rank_size() -> tuple[int, int]:
    for rank_var, size_var in (("PMI_RANK", "PMI_SIZE"), ("OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE")):
        if rank_var in os.environ:
            return int(os.environ[rank_var]), int(os.environ.get(size_var, "1"))
    return 0, 1


class Progress:
    """A one-line progress bar with ETA on a TTY (rank 0 only); silent otherwise."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done = max(total, 1), 0
        self.enabled = enabled and sys.stderr.isatty()
        self.start = time.monotonic()

    def advance(self, steps: int) -> None:
        self.done += steps
        if not self.enabled:
            return
        frac = min(self.done / self.total, 1.0)
        elapsed = time.monotonic() - self.start
        eta = elapsed * (1 - frac) / frac if frac > 0 else 0.0
        bar = "#" * int(30 * frac)
        sys.stderr.write(f"\r[{bar:<30}] {100 * frac:5.1f}%  step {self.done}/{self.total}  ETA {eta:6.1f}s")
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


def run_script(script: Path, total_steps: int, progress: bool = True, log: bool = False,
               on_command: Callable[[list[str]], None] | None = None, text: str | None = None,
               checkpoints: "Checkpointing | None" = None) -> None:
    """Execute ``script`` inside its folder with the lammps module.

    ``text`` is the script's content when this rank did not write the file (MPI ranks > 0:
    LAMMPS opens data files and writes dumps on rank 0 only).  ``on_command`` is called with
    the words of every command after LAMMPS finished it (also for the ``write_dump`` lines a
    resumed run skips: their frames are in the dump already).  ``checkpoints`` enables
    checkpoints and resuming (see fibrelmp.checkpoint).
    """
    from .checkpoint import ACTIONS, CheckpointStop

    script = Path(script)
    rank, size = mpi_rank_size()
    args = ["-nocite", "-log", "log.lammps" if log and rank == 0 else "none", "-screen", "none"]
    script_text = text if text is not None else read_script(script)
    lines = input_lines(script_text, script)      # exactly the lines `lmp -in` executes
    cwd = os.getcwd()
    bar = Progress(total_steps, progress and rank == 0)
    resume = checkpoints.resume if checkpoints is not None else None
    skip_to = resume["line"] if resume else 0
    steps = resume["steps"] if resume else 0
    frames = 0
    since = 0
    deferred: list[str] = []         # per-atom fixes: defined after read_restart to get their data
    lmp = None
    if resume:
        bar.advance(steps)
    try:
        lmp = new_lammps(args)
        if size > 1:
            # rank 0 wrote the job files before it got here; LAMMPS's read_data checks the
            # data file on every rank, so no rank may decide where to run before that
            from ._lammps import mpi_barrier
            mpi_barrier()
        try:
            os.chdir(script.parent)
        except OSError as exc:
            raise RunError(f"{script.parent}: job folder not visible on MPI rank {rank} ({exc.strerror}): "
                           "the work folder must be on a file system shared by all ranks") from None
        if checkpoints is not None:
            checkpoints.install()
        for number, line in enumerate(lines, 1):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            words = text.split()
            if number <= skip_to:
                if words[0] in ACTIONS:
                    if words[0] == "write_dump":
                        frames += 1
                        if on_command is not None:
                            on_command(words)
                    continue
                if words[0] == "fix" and len(words) > 3 and words[3] == "property/atom":
                    deferred.append(text)
                    continue
                if words[0] == "read_data":
                    text = "read_restart checkpoint.restart"
            try:
                lmp.command(text)
                if number <= skip_to and words[0] == "read_data":
                    for fix in deferred:
                        lmp.command(fix)
                if number <= skip_to and words[0] == "dump":     # keep what it wrote before
                    lmp.command(f"dump_modify {words[1]} append yes")
            except Exception as exc:       # LAMMPS raises plain Exception subclasses
                raise RunError(f"{script}:{number}: LAMMPS error: {str(exc).strip()}") from None
            if words[0] == "write_dump":
                frames += 1
            if words[0] == "run" and len(words) > 1:
                n = int(words[1])
                bar.advance(n)
                steps += n
                since += n
            if on_command is not None:
                on_command(words)
            if checkpoints is not None and words[0] == "run":
                signum = checkpoints.stop_requested(size)
                if signum or (checkpoints.every and since >= checkpoints.every):
                    checkpoints.write(lmp, rank, number, steps, frames, script_text)
                    since = 0
                    if signum:
                        raise CheckpointStop(script.parent, signum)
        if checkpoints is not None:
            checkpoints.clear(rank)
    finally:
        bar.close()
        os.chdir(cwd)
        if lmp is not None:
            lmp.close()


class RunAborted(Exception):
    """Raised inside the consumer when LAMMPS failed: writers discard partial outputs."""


def run_overlapped(script: Path, total_steps: int, frame_token: Callable[[list[str]], object],
                   consume: Callable, progress: bool = True, checkpoints=None):
    """Run ``script`` while ``consume(tokens)`` converts frames on a second thread (the lammps
    module releases the GIL inside the library, so conversion overlaps the next steps).

    ``frame_token(words)`` is called after every command and returns a token (not None) when
    that command wrote a frame; ``consume`` receives an iterator over those tokens, which ends
    when the run is done and raises RunAborted when it failed.  Returns what ``consume``
    returns.  LAMMPS never waits for the consumer (the queue is unbounded); a consumer error
    stops the run at the next frame.
    """
    import queue
    import threading

    ready: queue.Queue = queue.Queue()
    done, abort = object(), object()
    result: dict = {}

    def tokens():
        while True:
            token = ready.get()
            if token is done:
                return
            if token is abort:
                raise RunAborted()
            yield token

    def work() -> None:
        try:
            result["value"] = consume(tokens())
        except BaseException as exc:       # writers already removed their temp files
            result["error"] = exc

    def hook(words: list[str]) -> None:
        token = frame_token(words)
        if token is not None:
            if "error" in result:
                raise result["error"]
            ready.put(token)

    worker = threading.Thread(target=work, daemon=True)
    worker.start()
    try:
        run_script(script, total_steps, progress=progress, on_command=hook, checkpoints=checkpoints)
    except BaseException:
        ready.put(abort)
        worker.join()
        raise
    ready.put(done)
    worker.join()
    if "error" in result:
        raise result["error"]
    return result.get("value")
