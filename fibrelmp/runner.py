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
               on_command: Callable[[list[str]], None] | None = None, text: str | None = None) -> None:
    """Execute ``script`` inside its folder with the lammps module.

    ``text`` is the script's content when this rank did not write the file (MPI ranks > 0:
    LAMMPS opens data files and writes dumps on rank 0 only).  ``on_command`` is called with
    the words of every command after LAMMPS finished it.
    """
    script = Path(script)
    rank, _ = mpi_rank_size()
    args = ["-nocite", "-log", "log.lammps" if log and rank == 0 else "none", "-screen", "none"]
    lines = (text if text is not None else script.read_text()).splitlines()
    cwd = os.getcwd()
    bar = Progress(total_steps, progress and rank == 0)
    lmp = None
    try:
        if rank == 0 or script.parent.is_dir():
            os.chdir(script.parent)
        lmp = new_lammps(args)
        for number, line in enumerate(lines, 1):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            try:
                lmp.command(text)
            except Exception as exc:       # LAMMPS raises plain Exception subclasses
                raise RunError(f"{script}:{number}: LAMMPS error: {str(exc).strip()}") from None
            words = text.split()
            if words[0] == "run" and len(words) > 1:
                bar.advance(int(words[1]))
            if on_command is not None:
                on_command(words)
    finally:
        bar.close()
        os.chdir(cwd)
        if lmp is not None:
            lmp.close()
