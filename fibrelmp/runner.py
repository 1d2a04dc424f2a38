"""Run a rendered LAMMPS script in-process, command by command, with progress and MPI safety.

The same file replays with ``lmp -in in.lammps``: the runner feeds LAMMPS exactly the commands
that ``lmp -in`` reads (lines split on ``\\n`` only, loops through ``label``/``next``/
``jump SELF`` followed as LAMMPS follows them) and adds only progress, frame hooks and
checkpoints.  Schedules with many frames are LAMMPS loops, so neither the script nor the
runner grows with the number of frames.

MPI rule: LAMMPS runs on every rank; only rank 0 writes files and progress; any error
aborts all ranks.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator

from fibrelmp._lammps import new_lammps
from fibrelmp.errors import RunError
from fibrelmp.lammps_text import input_lines, read_script

if TYPE_CHECKING:
    from fibrelmp.checkpoint import Checkpointing  # noqa: F401


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
        self.shown = -1.0

    def advance(self, steps: int) -> None:
        self.done += steps
        if not self.enabled:
            return
        frac = min(self.done / self.total, 1.0)
        now = time.monotonic()
        if now - self.shown < 0.1 and frac < 1.0:      # loops of tiny runs: redraw 10x a second
            return
        self.shown = now
        elapsed = now - self.start
        eta = elapsed * (1 - frac) / frac if frac > 0 else 0.0
        bar = "#" * int(30 * frac)
        sys.stderr.write(f"\r[{bar:<30}] {100 * frac:5.1f}%  step {self.done}/{self.total}  ETA {eta:6.1f}s")
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


@dataclass
class Command:
    number: int          # 1-based line in the script
    text: str
    words: list[str]


def parse_commands(text: str, where: str = "in.lammps") -> tuple[list[Command], dict[str, int]]:
    """Commands of a rendered script and the index of every ``label``: the lines ``lmp -in``
    reads (``lammps_text.input_lines`` refuses lines LAMMPS would join or split otherwise)."""
    commands: list[Command] = []
    labels: dict[str, int] = {}
    for number, line in enumerate(input_lines(text, where), 1):
        body = line.strip()
        if not body or body.startswith("#"):
            continue
        words = body.split()
        if words[0] == "label" and len(words) == 2:
            labels[words[1]] = len(commands)
        commands.append(Command(number, body, words))
    return commands, labels


def execute(commands: list[Command], labels: dict[str, int], where: str = "in.lammps") -> Iterator[Command]:
    """The commands in the order LAMMPS executes them, following loops the way ``lmp -in``
    does: ``variable V loop N`` counts, ``next V`` advances (and past N the next ``jump`` is
    skipped), ``jump SELF L`` continues after ``label L``.  Yields every command (the caller
    sends all but ``label``/``jump`` to LAMMPS, whose ``next`` keeps its own copy in step)."""
    loops: dict[str, list[int]] = {}
    files: set[str] = set()          # atomfile variables: 'next' reads their next block
    skip_jump = False
    pc = 0
    while pc < len(commands):
        cmd = commands[pc]
        pc += 1
        w = cmd.words
        if w[0] == "variable" and len(w) >= 4 and w[2] == "loop":
            lo, hi = (1, int(w[3])) if len(w) == 4 or not w[4].isdigit() else (int(w[3]), int(w[4]))
            loops[w[1]] = [lo, hi]
        elif w[0] == "variable" and len(w) >= 4 and w[2] == "atomfile":
            files.add(w[1])
        elif w[0] == "next" and all(name in files for name in w[1:]):
            pass                     # LAMMPS's own: no loop to follow
        elif w[0] == "next":
            for name in w[1:]:
                state = loops.get(name)
                if state is None:
                    raise RunError(f"{where}:{cmd.number}: 'next {name}' without a loop variable")
                state[0] += 1
                if state[0] > state[1]:
                    del loops[name]
                    skip_jump = True
        elif w[0] == "jump":
            yield cmd
            if skip_jump:
                skip_jump = False
                continue
            if len(w) != 3 or w[1] != "SELF" or w[2] not in labels:
                raise RunError(f"{where}:{cmd.number}: only 'jump SELF label' with a label of "
                               "this script is supported")
            pc = labels[w[2]] + 1
            continue
        yield cmd


def run_script(script: Path, total_steps: int, progress: bool = True, log: bool = False,
               on_command: Callable[[list[str]], None] | None = None, text: str | None = None,
               checkpoints: "Checkpointing | None" = None,
               finished: Callable[[object], None] | None = None) -> None:
    """Execute ``script`` inside its folder with the lammps module.

    ``text`` is the script's content when this rank did not write the file (MPI ranks > 0:
    LAMMPS opens data files and writes dumps on rank 0 only).  ``on_command`` is called with
    the words of every command after LAMMPS finished it (also for the ``write_dump`` commands
    a resumed run skips: their frames are in the dump already).  ``checkpoints`` enables
    checkpoints and resuming (see fibrelmp.checkpoint).  ``finished(lmp)`` is called after
    the last command (before LAMMPS closes), e.g. to read a fix's global values.
    """
    from fibrelmp.checkpoint import ACTIONS, CheckpointStop

    script = Path(script)
    rank, size = mpi_rank_size()
    args = ["-nocite", "-log", "log.lammps" if log and rank == 0 else "none", "-screen", "none"]
    script_text = text if text is not None else read_script(script)
    commands, labels = parse_commands(script_text, str(script))
    cwd = os.getcwd()
    bar = Progress(total_steps, progress and rank == 0)
    resume = checkpoints.resume if checkpoints is not None else None
    skip_to = resume["commands"] if resume else 0     # commands done before the checkpoint
    steps = resume["steps"] if resume else 0
    frames = 0
    since = 0
    done = 0                         # commands executed (the position in the command stream)
    rebuild = False                  # a checkpoint re-exchanged the atoms: rebuild neighbours
    saved_state: dict = {}           # the step state at the last checkpoint
    resumed_state = checkpoints.load_step_state() if resume else None
    deferred: list[str] = []         # per-atom fixes: defined after read_restart to get their data
    lmp = None
    if resume:
        bar.advance(steps)
    try:
        lmp = new_lammps(args)
        if size > 1:
            # rank 0 wrote the job files before it got here; LAMMPS's read_data checks the
            # data file on every rank, so no rank may decide where to run before that
            from fibrelmp._lammps import mpi_barrier
            mpi_barrier()
        try:
            os.chdir(script.parent)
        except OSError as exc:
            raise RunError(f"{script.parent}: job folder not visible on MPI rank {rank} ({exc.strerror}): "
                           "the work folder must be on a file system shared by all ranks") from None
        if checkpoints is not None:
            checkpoints.install()
        for cmd in execute(commands, labels, str(script)):
            done += 1
            words, text = cmd.words, cmd.text
            if words[0] in ("label", "jump"):
                continue                 # followed by execute(); LAMMPS's own jump needs a file
            replaying = done <= skip_to
            if replaying:
                # fix_modify ID write FILE: a frame of fix musen/wall/mesh's triangle forces
                if words[0] in ACTIONS or (words[0] == "fix_modify" and words[2:3] == ["write"]):
                    if words[0] == "write_dump":
                        frames += 1
                        if on_command is not None:
                            on_command(words)
                    continue
                if words[0] == "fix" and len(words) > 3 and words[3] == "property/atom":
                    deferred.append(text)
                    continue
                if words[0] == "read_data":
                    text = f"read_restart {resume['restart']}"
            try:
                if not replaying and resumed_state is not None:
                    # the first command after the checkpoint: computes set up and the step's
                    # forces back (a write_dump or set may come before any run)
                    restore_step_state(lmp, resumed_state)
                    resumed_state = None
                    rebuild = False
                if rebuild and words[0] == "run":
                    # write_restart re-exchanged the atoms and rebuilt the ghosts: a "run …
                    # pre no" would use a stale neighbour list
                    restore_step_state(lmp, saved_state)
                    rebuild = False
                before = _timestep(lmp) if words[0] == "run" else 0
                lmp.command(text)
                if replaying and words[0] == "read_data":
                    for fix in deferred:
                        lmp.command(fix)
                if replaying and words[0] == "dump":     # keep what it wrote before
                    lmp.command(f"dump_modify {words[1]} append yes")
            except RunError:
                raise
            except Exception as exc:       # LAMMPS raises plain Exception subclasses
                raise RunError(f"{script}:{cmd.number}: LAMMPS error: {str(exc).strip()}") from None
            if words[0] == "write_dump":
                frames += 1
            if words[0] == "run":
                n = _timestep(lmp) - before
                bar.advance(n)
                steps += n
                since += n
            if on_command is not None:
                on_command(words)
            if checkpoints is not None and words[0] == "run":
                signum = checkpoints.stop_requested(size)
                if signum or (checkpoints.every and since >= checkpoints.every):
                    saved_state = step_state(lmp)
                    checkpoints.write(lmp, rank, done, cmd.number, steps, frames, script_text,
                                      saved_state)
                    rebuild = True
                    since = 0
                    if signum:
                        raise CheckpointStop(script.parent, signum)
        if finished is not None:
            finished(lmp)
        if checkpoints is not None:
            checkpoints.clear(rank)
    finally:
        bar.close()
        os.chdir(cwd)
        if checkpoints is not None:
            checkpoints.uninstall()
        if lmp is not None:
            lmp.close()


def _timestep(lmp) -> int:
    return int(lmp.extract_global("ntimestep"))


def step_state(lmp) -> dict:
    """What a velocity-Verlet step starts from besides the restart file's contents: the
    forces (and torques) of the last step, computed with half-step velocities in the drag
    and contact damping.  By atom id (ids need not be consecutive after deletions)."""
    import numpy as np

    n = int(lmp.get_natoms())
    state = {"id": np.array(lmp.gather_atoms_concat("id", 0, 1)[:n], dtype=np.int64)}
    for name in ("f", "torque"):
        if lmp.extract_atom(name) is not None:
            state[name] = np.array(lmp.gather_atoms_concat(name, 1, 3)[:3 * n], dtype=np.float64)
    return state


def restore_step_state(lmp, state: dict) -> None:
    """``run 0`` (neighbour lists, computes and fixes set up; forces recomputed), then the
    forces of ``step_state`` put back, so the next step is the one an uninterrupted run takes."""
    import ctypes

    lmp.command("run 0 post no")
    ids = state["id"]
    n = len(ids)
    c_ids = (ctypes.c_int * n)(*ids.tolist()) if n else (ctypes.c_int * 1)()
    for name in ("f", "torque"):
        if name in state:
            values = state[name]
            data = (ctypes.c_double * len(values))(*values.tolist()) if n else (ctypes.c_double * 1)()
            lmp.scatter_atoms_subset(name, 1, 3, n, c_ids, data)



class RunAborted(Exception):
    """Raised inside the consumer when LAMMPS failed: writers discard partial outputs."""


def run_overlapped(script: Path, total_steps: int, frame_token: Callable[[list[str]], object],
                   consume: Callable, progress: bool = True, checkpoints=None, finished=None):
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

    from fibrelmp.numtext.fast import cores_taken

    worker = threading.Thread(target=work, daemon=True)
    # LAMMPS runs without the GIL, but between two commands the main thread needs it back:
    # while the converter holds it, that takes up to the switch interval (5 ms by default)
    switch = sys.getswitchinterval()
    sys.setswitchinterval(min(switch, 2e-4))
    worker.start()
    try:
        with cores_taken(1):        # LAMMPS's core: the converter then uses one thread only
            run_script(script, total_steps, progress=progress, on_command=hook, checkpoints=checkpoints,
                       finished=finished)
    except BaseException:
        ready.put(abort)
        worker.join()
        raise
    finally:
        sys.setswitchinterval(switch)
    ready.put(done)
    worker.join()
    if "error" in result:
        raise result["error"]
    return result.get("value")
