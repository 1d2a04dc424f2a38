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
import threading
import time
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator

from fibrelmp._lammps import new_lammps
from fibrelmp.errors import RunError
from fibrelmp.lammps_flow import condition_holds, execute, jump_target
from fibrelmp.lammps_text import input_lines, read_script
from fibrelmp.runplan import DATA_COMMANDS, FRAME_COMMANDS

if TYPE_CHECKING:
    from fibrelmp.checkpoint import Checkpointing  # noqa: F401
    from fibrelmp.record import Recorder  # noqa: F401

LOG_NAME = "log.lammps"          # LAMMPS's own log with the thermo output (fibrelmp.record)

_CLONE_FS = 0x00000200           # linux/sched.h: the working directory, root and umask
_own_folder = threading.local()  # has this thread a working directory of its own?
_folder_lock = threading.Lock()  # where it cannot have one: one run at a time in the process


def _thread_own_folder() -> bool:
    """Give the calling thread a working directory of its own (Linux ``unshare(CLONE_FS)``:
    a ``chdir`` in it no longer moves the process's other threads; threads it starts later
    share its directory).  False where that is not possible (not Linux)."""
    if getattr(_own_folder, "done", None) is None:
        done = False
        if sys.platform.startswith("linux"):
            import ctypes

            try:
                libc = ctypes.CDLL(None, use_errno=True)
                done = libc.unshare(_CLONE_FS) == 0
            except (OSError, AttributeError):
                done = False
        _own_folder.done = done
    return _own_folder.done


@contextmanager
def in_folder(folder: Path) -> Iterator[None]:
    """Run the block with ``folder`` as the calling thread's working directory (the job's
    relative file names are LAMMPS's own: ``cd WORK && lmp -in in.lammps`` replays it).  The
    caller's other threads keep their directory; where a thread cannot have its own
    directory, runs in this process are serialised instead (docs/python.md)."""
    own = _thread_own_folder()
    if not own:
        _folder_lock.acquire()
    try:
        cwd = os.getcwd()
        os.chdir(folder)
        try:
            yield
        finally:
            os.chdir(cwd)
    finally:
        if not own:
            _folder_lock.release()


def mpi_rank_size() -> tuple[int, int]:
    for rank_var, size_var in (("PMI_RANK", "PMI_SIZE"), ("OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE")):
        if rank_var in os.environ:
            return int(os.environ[rank_var]), int(os.environ.get(size_var, "1"))
    return 0, 1


@dataclass(frozen=True)
class LogEvery:
    """When a run without a terminal writes a progress line (``--log-every``): at every
    ``percent`` of the steps and/or after ``seconds`` since the last line (None: not by that)."""
    percent: float | None = 10.0
    seconds: float | None = 300.0

    def __str__(self) -> str:
        parts = ([f"{self.percent:g}%"] if self.percent else []) + ([f"{self.seconds:g}s"] if self.seconds else [])
        return ",".join(parts)


DEFAULT_LOG_EVERY = LogEvery()
_UNITS = {"s": 1.0, "m": 60.0, "h": 3600.0}


def parse_log_every(text: str) -> LogEvery:
    """``10%`` (every 10 % of the steps), ``60``/``60s``/``5m``/``1h`` (every so long), or
    both, comma-separated (``10%,5m``: whichever comes first)."""
    from fibrelmp.errors import InputError

    percent = seconds = None
    for part in str(text).replace(" ", "").split(","):
        try:
            if part.endswith("%"):
                value = float(part[:-1])
                ok = percent is None and 0 < value <= 100
                percent = value
            else:
                scale = _UNITS.get(part[-1:], None)
                value = float(part[:-1] if scale else part) * (scale or 1.0)
                ok = seconds is None and 0 < value < float("inf")
                seconds = value
        except ValueError:
            ok = False
        if not ok:
            raise InputError(None, None, f"--log-every {text!r}: give a percentage of the steps "
                             "(10%), a time (60, 60s, 5m, 1h) or both (10%,5m)")
    return LogEvery(percent, seconds)


class Progress:
    """The steps done, drawn by tqdm on rank 0: a bar with ETA on a terminal; without one
    (batch jobs), a line on stderr at the start, every ``every`` and at the end.  After a
    resume the count starts at the steps done before and the rate (so the ETA) counts only
    the steps of this session (tqdm's ``initial``)."""

    def __init__(self, total: int, enabled: bool, done: int = 0, every: LogEvery | None = None,
                 label: str = "", stream=None):
        self.total, self.done, self.initial = total, done, done
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled and total > 0          # a job of no steps: nothing to show
        self.every = every or DEFAULT_LOG_EVERY
        self.label = label
        self.bar = None
        self.start = time.monotonic()
        if not self.enabled:
            return
        from tqdm import tqdm

        self.tqdm = tqdm
        if self.stream.isatty():
            try:                    # a terminal without a size (script, some CI): 80 x 24
                size = os.get_terminal_size(self.stream.fileno())
                sized = size.columns > 0 and size.lines > 0
            except (OSError, ValueError, AttributeError):
                sized = False
            fixed = {} if sized else {"ncols": 80, "nrows": 24}
            self.bar = tqdm(total=self.total, initial=done, file=self.stream, unit="step",
                            desc=label or None, dynamic_ncols=sized, mininterval=0.2, leave=True,
                            **fixed)
        else:
            self.line_at, self.line_done = self.start, None
            self._line()

    def advance(self, steps: int) -> None:
        self.done += steps
        if not self.enabled or steps <= 0:
            return
        if self.bar is not None:
            self.bar.update(steps)
            return
        now = time.monotonic()
        every = self.every
        due = every.seconds is not None and now - self.line_at >= every.seconds
        if every.percent is not None:
            size = every.percent / 100 * self.total
            due = due or int((self.done - steps) // size) != int(self.done // size)
        if due:
            self._line(now)

    def _line(self, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        meter = self.tqdm.format_meter(
            min(self.done, self.total), self.total, now - self.start, initial=self.initial,
            unit=" step", bar_format="{percentage:5.1f}% step {n}/{total}, elapsed {elapsed}, "
                                    "ETA {remaining}, {rate_fmt}")
        label = f" {self.label}" if self.label else ""
        stamp = time.strftime("%Y-%m-%d %H:%M:%S")
        self.stream.write(f"[{stamp}] progress{label}: {meter}\n")
        self.stream.flush()
        self.line_at, self.line_done = now, self.done

    def close(self) -> None:
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.close()
        elif self.line_done != self.done:
            self._line()


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


def run_script(script: Path, total_steps: int, progress: bool = True, log: bool = True,
               on_command: Callable[[list[str]], None] | None = None, text: str | None = None,
               checkpoints: "Checkpointing | None" = None,
               finished: Callable[[object], None] | None = None,
               record: "Recorder | None" = None, log_every: LogEvery | None = None,
               label: str = "") -> None:
    """Execute ``script`` inside its folder with the lammps module.

    ``text`` is the script's content when this rank did not write the file (MPI ranks > 0:
    LAMMPS opens data files and writes dumps on rank 0 only).  ``on_command`` is called with
    the words of every command after LAMMPS finished it (also for the ``write_dump`` commands
    a resumed run skips: their frames are in the dump already).  ``checkpoints`` enables
    checkpoints and resuming (see fibrelmp.checkpoint).  ``finished(lmp)`` is called after
    the last command (before LAMMPS closes), e.g. to read a fix's global values.

    ``log``: LAMMPS writes ``log.lammps`` in the job folder (rank 0; a resumed run appends).
    ``record`` (a ``fibrelmp.record.Recorder``) takes the final state, on every rank.  Progress (rank 0): ``Progress`` with ``log_every``.
    """
    script = Path(script)
    rank, size = mpi_rank_size()
    resume = checkpoints.resume if checkpoints is not None else None
    fresh_log = log and rank == 0 and not resume
    args = ["-nocite", "-log", str(script.parent.resolve() / LOG_NAME) if fresh_log else "none",
            "-screen", "none"]
    script_text = text if text is not None else read_script(script)
    commands, labels = parse_commands(script_text, str(script))
    folder = ExitStack()             # the job folder as this thread's working directory
    steps = resume["steps"] if resume else 0
    bar = Progress(total_steps, progress and rank == 0, done=steps, every=log_every, label=label)
    run = _ScriptRun(script, script_text, rank, size, checkpoints, on_command, bar, resume,
                     skip_to=resume["commands"] if resume else 0, steps=steps,
                     resumed_state=checkpoints.load_step_state() if resume else None)
    try:
        run.start(args, folder, log)
        for cmd in execute(commands, labels, str(script), taken=lambda: run.jumped):
            run.command(cmd)
        if record is not None:
            record.end(run.lmp, run.steps, steps)
        if finished is not None:
            finished(run.lmp)
        if checkpoints is not None:
            checkpoints.clear(rank)
    finally:
        bar.close()
        folder.close()
        if checkpoints is not None:
            checkpoints.uninstall()
        if run.lmp is not None:
            run.lmp.close()


@dataclass
class _ScriptRun:
    """Where one run_script is: the command stream, steps, frames and checkpoints."""

    script: Path
    script_text: str
    rank: int
    size: int
    checkpoints: "Checkpointing | None"
    on_command: Callable[[list[str]], None] | None
    bar: Progress
    resume: dict | None
    skip_to: int = 0                 # commands done before the checkpoint (replayed)
    steps: int = 0
    resumed_state: dict | None = None
    frames: int = 0
    since: int = 0                   # steps since the last checkpoint
    done: int = 0                    # commands executed (the position in the command stream)
    # a checkpoint (or a stop) due after a run is taken before the next run command, once the
    # step's frame commands have written what an uninterrupted run writes there
    due: tuple[int, int] | None = None   # (signal or 0, line of the run that made it due)
    deferred: list[str] = field(default_factory=list)   # per-atom fixes: defined after read_restart
    atomfiles: set[str] = field(default_factory=set)    # atomfile variables skipped while replaying
    lmp: object = None
    jumped: bool = False             # the last conditional 'jump SELF' was taken

    def start(self, args: list[str], folder: ExitStack, log: bool) -> None:
        """Start LAMMPS and enter the job folder (every rank must see it)."""
        self.lmp = new_lammps(args)
        if self.size > 1:
            # rank 0 wrote the job files before it got here; LAMMPS's read_data checks the
            # data file on every rank, so no rank may decide where to run before that
            from fibrelmp._lammps import mpi_barrier
            mpi_barrier()
        try:
            folder.enter_context(in_folder(self.script.parent))
        except OSError as exc:
            raise RunError(f"{self.script.parent}: job folder not visible on MPI rank {self.rank} "
                           f"({exc.strerror}): the work folder must be on a file system shared by "
                           "all ranks") from None
        if log and self.resume:
            self.lmp.command(f"log {LOG_NAME} append")      # LAMMPS opens it on rank 0
        if self.checkpoints is not None:
            self.checkpoints.install()

    def command(self, cmd: Command) -> None:
        """Execute (or, up to the checkpoint, replay) one command of the stream."""
        self.done += 1
        words, text = cmd.words, cmd.text
        if words[0] in ("label", "jump"):
            return                       # followed by execute(); LAMMPS's own jump needs a file
        replaying = self.done <= self.skip_to
        if words[0] == "if" and jump_target(text) is not None:
            # taken only to end the run (MUSEN's stop criterion): never before a checkpoint
            self.jumped = not replaying and condition_holds(self.lmp, text, f"{self.script}:{cmd.number}")
            return
        if replaying:
            text = self._replayed(words, text)
            if text is None:
                return
        if self.due is not None and words[0] == "run" and not self.jumped:
            self._checkpoint(cmd)
        counts, before = self._execute(cmd, text, replaying)
        if words[0] in FRAME_COMMANDS:
            self.frames += 1
        if counts:
            n = max(_timestep(self.lmp) - before, 0)
            self.bar.advance(n)
            self.steps += n
            self.since += n
        if self.on_command is not None:
            self.on_command(words)
        if self.checkpoints is not None and words[0] == "run":
            signum = self.checkpoints.stop_requested(self.size)
            if signum or (self.checkpoints.every and self.since >= self.checkpoints.every):
                self.due = (signum, cmd.number)

    def _replayed(self, words: list[str], text: str) -> str | None:
        """What replaying executes for a command done before the checkpoint (None: nothing)."""
        from fibrelmp.checkpoint import ACTIONS

        # fix_modify ID write|contacts FILE: a frame of fix musen/wall/mesh's triangle forces
        # or its contacts (or of fix musen/leapfrog's clock)
        if words[0] in ACTIONS or (words[0] == "fix_modify" and words[2:3] in (["write"], ["contacts"])):
            if words[0] in FRAME_COMMANDS:
                self.frames += 1
                if self.on_command is not None:
                    self.on_command(words)
            return None
        if words[0] == "fix" and len(words) > 3 and words[3] == "property/atom":
            self.deferred.append(text)
            return None
        # per-atom values set from atomfiles (bond geometry, FibreNet's state) come
        # back with read_restart; the files may name atoms lost before the checkpoint
        if words[0] == "variable" and len(words) > 2 and words[2] == "atomfile":
            self.atomfiles.add(words[1])
            return None
        if self.atomfiles and _uses_atomfile(words, self.atomfiles):
            return None
        if words[0] in DATA_COMMANDS:
            return f"read_restart {self.resume['restart']}"
        return text

    def _checkpoint(self, cmd: Command) -> None:
        """Write the checkpoint that came due (and stop, if a signal asked for it)."""
        from fibrelmp.checkpoint import CheckpointStop

        signum, run_line = self.due
        self.due = None
        saved_state = step_state(self.lmp)
        self.checkpoints.write(self.lmp, self.rank, self.done - 1, run_line, self.steps, self.frames,
                               self.script_text, saved_state)
        self.since = 0
        if signum:
            raise CheckpointStop(self.script.parent, signum)
        # write_restart re-exchanged the atoms (on several ranks their forces did not
        # travel) and rebuilt the ghosts: put the step's state back (and the neighbour
        # lists the "run ... pre no" uses)
        try:
            restore_step_state(self.lmp, saved_state)
        except Exception as exc:
            raise RunError(f"{self.script}:{cmd.number}: LAMMPS error after a checkpoint: "
                           f"{str(exc).strip()}") from None

    def _execute(self, cmd: Command, text: str, replaying: bool) -> tuple[bool, int]:
        """Give LAMMPS one command; whether it counts steps, and the step before it."""
        words = cmd.words
        try:
            if not replaying and self.resumed_state is not None:
                # the first command after the checkpoint: computes set up and the step's
                # forces back (a write_dump or set may come before any run)
                restore_step_state(self.lmp, self.resumed_state)
                self.resumed_state = None
            # FibreNet's first step after a (re)start is made by commands: its
            # "reset_timestep $(step+1)" counts it; a reset to 0 (a new stage) none
            counts = words[0] in ("run", "reset_timestep")
            before = _timestep(self.lmp) if counts else 0
            self.lmp.command(text)
            if replaying and words[0] in DATA_COMMANDS:
                for fix in self.deferred:
                    self.lmp.command(fix)
            if replaying and words[0] == "dump":     # keep what it wrote before
                self.lmp.command(f"dump_modify {words[1]} append yes")
        except RunError:
            raise
        except Exception as exc:       # LAMMPS raises plain Exception subclasses
            raise RunError(f"{self.script}:{cmd.number}: LAMMPS error: {str(exc).strip()}") from None
        return counts, before


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


def _uses_atomfile(words: list[str], names: set[str]) -> bool:
    """Does a command only load or apply one of the atomfile variables ``names``
    (``next V``, ``set ... v_V``, ``variable V delete``)?"""
    if words[0] == "next":
        return any(w in names for w in words[1:])
    if words[0] == "set":
        return any(w.startswith("v_") and w[2:] in names for w in words)
    return words[0] == "variable" and len(words) > 2 and words[1] in names and words[2] == "delete"


def restore_step_state(lmp, state: dict) -> None:
    """``run 0`` (neighbour lists, computes and fixes set up; forces recomputed), then the
    forces of ``step_state`` put back, so the next step is the one an uninterrupted run takes."""
    import ctypes

    import numpy as np

    lmp.command("run 0 post no")
    # atoms beyond an 'f' face that LAMMPS had not yet dropped at the checkpoint are dropped
    # by read_restart: scattering to an id LAMMPS no longer has reads past its atom map
    now = int(lmp.get_natoms())
    present = np.array(lmp.gather_atoms_concat("id", 0, 1)[:now], dtype=np.int64)
    keep = np.isin(state["id"], present)
    ids = state["id"][keep]
    n = len(ids)
    c_ids = (ctypes.c_int * n)(*ids.tolist()) if n else (ctypes.c_int * 1)()
    for name in ("f", "torque"):
        if name in state:
            values = state[name].reshape(-1, 3)[keep].reshape(-1)
            data = (ctypes.c_double * len(values))(*values.tolist()) if n else (ctypes.c_double * 1)()
            lmp.scatter_atoms_subset(name, 1, 3, n, c_ids, data)



_switch = {"runs": 0, "saved": 0.0}
_switch_lock = threading.Lock()


def _short_switch(change: int) -> None:
    """A short GIL switch interval while any overlapped run is under way (runs in several
    threads: the interval the first one found comes back when the last one ends)."""
    with _switch_lock:
        if _switch["runs"] == 0 and change > 0:
            _switch["saved"] = sys.getswitchinterval()
            sys.setswitchinterval(min(_switch["saved"], 2e-4))
        _switch["runs"] += change
        if _switch["runs"] == 0:
            sys.setswitchinterval(_switch["saved"])


class RunAborted(Exception):
    """Raised inside the consumer when LAMMPS failed: writers discard partial outputs."""


def run_overlapped(script: Path, total_steps: int, frame_token: Callable[[list[str]], object],
                   consume: Callable, progress: bool = True, checkpoints=None, finished=None,
                   **options):
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
    _short_switch(+1)
    worker.start()
    try:
        with cores_taken(1):        # LAMMPS's core: the converter then uses one thread only
            run_script(script, total_steps, progress=progress, on_command=hook, checkpoints=checkpoints,
                       finished=finished, **options)
    except BaseException:
        ready.put(abort)
        worker.join()
        raise
    finally:
        _short_switch(-1)
    ready.put(done)
    worker.join()
    if "error" in result:
        raise result["error"]
    return result.get("value")
