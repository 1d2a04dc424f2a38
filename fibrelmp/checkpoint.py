"""Checkpoints: stop a run cleanly (every N steps, or on SIGTERM/Ctrl-C) and resume it.

A checkpoint sits in the job folder: ``checkpoint-N.restart`` (LAMMPS ``write_restart``:
atoms, velocities, bonds, contact and bond history, per-atom fix data; N counts the commands
done) and ``checkpoint.json``
(fibrelmp's own state: how many script commands were done, steps done, a hash of the script
and of every file the job reads, and the byte size of every dump the script appends to, so
frames written after the checkpoint are dropped).

``checkpoint-N.forces.npz`` holds the forces and torques the next step starts from (computed
with half-step velocities; ``write_restart`` does not keep them), so a resumed run continues
exactly as an uninterrupted one.  ``checkpoint.json`` is written last, atomically, and names
its two files: a run killed while writing a checkpoint leaves the previous one intact.

Resuming replays the same rendered script: set-up commands run again (styles, fixes,
variables must exist), ``read_data`` becomes ``read_restart``, and commands that change the
state or write output (run, velocity, displace_atoms, write_dump, ...) are skipped up to the
checkpoint's position in the command stream (loops included).  Checkpoints are taken only between ``run`` commands of the script, so every
MPI rank stops at the same command (the stop request is agreed with an MPI all-reduce): one that
is due after a run is written just before the next ``run``, once the step's frame commands
have written what an uninterrupted run writes there (a checkpoint's ``run 0`` recomputes the
wall forces of fix wall/gran/region and fix musen/wall/mesh with full-step velocities).
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import re
import signal
from dataclasses import dataclass, field
from pathlib import Path

from fibrelmp.errors import InputError

STATE = "checkpoint.json"             # written last: names the files below
RESTART = "checkpoint-{n}.restart"     # n: commands done (see runner.run_script)
FORCES = "checkpoint-{n}.forces.npz"   # the step's forces and torques (see runner.step_state)
# commands that change the state or write output: done already when resuming
# (fibrenet/frame: fix fibrenet/output's frame, appended to FibreNet's xyz files; musen/predict:
# MUSEN's prediction kick at t = 0)
ACTIONS = frozenset({"run", "minimize", "velocity", "displace_atoms", "reset_timestep", "write_dump",
                     "write_restart", "write_data", "set", "delete_atoms", "create_atoms",
                     "delete_bonds", "displace_box", "change_box", "fibrenet/frame", "musen/predict"})


class CheckpointStop(Exception):
    """The run stopped after writing a checkpoint (signal received)."""

    def __init__(self, folder: Path, signum: int):
        self.folder, self.signum = folder, signum
        super().__init__(f"stopped by {signal.Signals(signum).name}; checkpoint written in {folder}: "
                         "continue with --resume")


@dataclass
class Checkpointing:
    folder: Path                         # the job folder
    every: int | None = None             # steps between checkpoints (None: only on signals)
    resume: dict | None = None           # state of the checkpoint to continue from
    appended: list[str] = field(default_factory=list)   # dumps the script appends to
    inputs: list[Path] = field(default_factory=list)    # files the job reads (data files)
    _stop: int = 0
    _saved: dict = field(default_factory=dict)           # signal handlers to restore

    # -- signals --------------------------------------------------------------------------
    def install(self) -> None:
        for sig in (signal.SIGTERM, signal.SIGINT):
            try:
                self._saved[sig] = signal.signal(sig, self._request)
            except ValueError:           # not the main thread: no signal handling
                return

    def uninstall(self) -> None:
        """Put back the handlers ``install`` replaced (a notebook keeps its Ctrl-C)."""
        for sig, handler in self._saved.items():
            signal.signal(sig, handler)
        self._saved.clear()

    def _request(self, signum, frame) -> None:
        if self._stop:            # a second signal: stop now, without a checkpoint
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
        self._stop = signum

    def stop_requested(self, size: int) -> int:
        """The signal to stop for, agreed by every MPI rank (0 = go on)."""
        if size == 1:
            return self._stop
        return _allreduce_max(self._stop)

    # -- files -----------------------------------------------------------------------------
    def write(self, lmp, rank: int, commands: int, line: int, steps: int, frames: int,
              script_text: str, step_state: dict | None = None) -> None:
        restart, forces = RESTART.format(n=commands), FORCES.format(n=commands)
        lmp.command(f"write_restart {restart}")
        if rank != 0:
            return
        if step_state is not None:        # forces/torques: write_restart does not keep them
            import numpy as np

            with open(self.folder / forces, "wb") as fh:
                np.savez(fh, **step_state)
        state = {"commands": commands, "line": line, "steps": steps, "frames": frames,
                 "restart": restart, "forces": forces if step_state is not None else None,
                 "script_sha256": _sha(script_text), "inputs_sha256": inputs_digest(self.inputs),
                 "ranks": int(lmp.extract_setting("world_size")),     # a record: any count resumes it
                 "sizes": {name: (self.folder / name).stat().st_size
                           for name in self.appended if (self.folder / name).exists()}}
        part = self.folder / (STATE + ".tmp")
        part.write_text(json.dumps(state, indent=1))
        os.replace(part, self.folder / STATE)      # the new checkpoint is complete from here
        self._remove_files(keep={restart, forces})

    def load_step_state(self) -> dict | None:
        """The forces/torques saved with the checkpoint being resumed (None: not saved)."""
        if self.resume is None or not self.resume.get("forces"):
            return None
        path = self.folder / self.resume["forces"]
        import numpy as np

        with np.load(path) as data:
            return {k: data[k] for k in data.files}

    def clear(self, rank: int) -> None:
        if rank == 0:
            for name in (STATE, STATE + ".tmp"):
                (self.folder / name).unlink(missing_ok=True)
            self._remove_files(keep=set())

    def _remove_files(self, keep: set) -> None:
        """Restart and force files of other (earlier or unfinished) checkpoints."""
        for path in self.folder.glob("checkpoint-*"):
            if path.name not in keep:
                path.unlink(missing_ok=True)


def has_checkpoint(work: Path) -> bool:
    """Is there a checkpoint in the work folder (a cmusen script's: in a job's sub-folder)?"""
    work = Path(work)
    return work.is_dir() and next(work.rglob(STATE), None) is not None


def check_every(every: int | None) -> None:
    """``--checkpoint-every`` must be a positive number of steps (None: only on signals)."""
    if every is not None and every <= 0:
        raise InputError(None, None, f"--checkpoint-every must be a positive number of steps, got {every}")


NO_CHECKPOINT = ("no checkpoint to resume from (run without --resume, or give the same --work "
                 "folder as the interrupted run)")


def load(folder: Path, script_text: str, inputs: list[Path] = ()) -> dict:
    """The checkpoint state in ``folder``; an InputError when there is none or the job
    (script or any file it reads) changed since it was written."""
    path = Path(folder) / STATE
    if not path.exists():
        raise InputError(path, None, NO_CHECKPOINT)
    try:
        state = json.loads(path.read_text())
        commands, line, steps = int(state["commands"]), int(state["line"]), int(state["steps"])
        files = [state["restart"]] + ([state["forces"]] if state.get("forces") else [])
        if not all(isinstance(name, str) and (Path(folder) / name).is_file() for name in files):
            raise ValueError("a checkpoint file is missing")
    except (ValueError, KeyError, TypeError):
        raise InputError(path, None, "the checkpoint state is damaged; run again without --resume") from None
    if state.get("script_sha256") != _sha(script_text) or \
            state.get("inputs_sha256") != inputs_digest(inputs):
        raise InputError(path, None, "the input changed since this checkpoint was written: the "
                         "translated job differs; run again without --resume")
    state["commands"], state["line"], state["steps"] = commands, line, steps
    return state


def truncate_outputs(folder: Path, state: dict) -> None:
    """Drop what the interrupted run appended after its checkpoint."""
    for name, size in state.get("sizes", {}).items():
        path = Path(folder) / name
        if path.exists() and path.stat().st_size > size:
            with open(path, "r+b") as fh:
                fh.truncate(size)


def inputs_digest(paths) -> str:
    """One hash over the files a job reads besides its script (the data file holds the whole
    model: any edit of an input or model file changes it)."""
    h = hashlib.sha256()
    for p in paths:
        p = Path(p)
        h.update(p.name.encode() + b"\0")
        with open(p, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        h.update(b"\0")
    return h.hexdigest()


_PLUGIN_LOAD = re.compile(r'^(plugin\s+load\s+)("[^"]*"|\S+)', re.MULTILINE)


def _sha(text: str) -> str:
    """The script's hash; a ``plugin load`` path counts by its file name only (it names the
    plugin's build, whose id changes with its sources), so the same plugin found elsewhere,
    e.g. installed vs. compiled into the user cache, does not block a resume."""
    text = _PLUGIN_LOAD.sub(lambda m: m.group(1) + os.path.basename(m.group(2).strip('"')), text)
    return hashlib.sha256(text.encode()).hexdigest()


def _allreduce_max(value: int) -> int:
    lib = ctypes.CDLL("libmpi.so.12", mode=os.RTLD_NOLOAD | ctypes.RTLD_GLOBAL)  # ctypes has no RTLD_NOLOAD
    send, recv = ctypes.c_int(value), ctypes.c_int(0)
    # MPICH ABI handles: MPI_INT, MPI_MAX, MPI_COMM_WORLD
    lib.MPI_Allreduce(ctypes.byref(send), ctypes.byref(recv), 1, ctypes.c_int(0x4c000405),
                      ctypes.c_int(0x58000001), ctypes.c_int(0x44000000))
    return recv.value
