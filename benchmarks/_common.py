"""Helpers shared by the benchmark scripts (run them as `python benchmarks/NAME.py`)."""

import importlib.util
import os
import subprocess
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def load_generator():
    """The network generator in examples/ (a script, not a package module)."""
    spec = importlib.util.spec_from_file_location(
        "generate_network", HERE.parent / "examples" / "generate_network.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def timed(cmd: list[str], cwd: Path | None = None, env: dict | None = None) -> tuple[float, float]:
    """(wall seconds, peak resident bytes) of one command, from ``os.wait4``.  A forked
    child's high-water mark starts at its parent's: keep the calling process small."""
    t = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t
    err = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(map(str, cmd[:5]))} failed{f' in {cwd}' if cwd else ''}:\n{err[-3000:]}")
    return seconds, usage.ru_maxrss * 1024.0
