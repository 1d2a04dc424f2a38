#!/usr/bin/env python3
"""MPI speed-up: ``mpiexec -n 2 fibrelmp run`` versus serial ``fibrelmp run``.

Generates a random ~260,000-bead FibreNet network (examples/generate_network.py; --steps
production steps, frames only at the start and the end, positions only) in a temporary
folder, then times the whole command as a user runs it, in a subprocess each:

  (a) serial = ``fibrelmp -q run input.txt --out serial/``
  (b) MPI    = ``mpiexec -n RANKS fibrelmp -q run input.txt --out mpi/``

Both include start-up, parsing (every rank parses), translation, LAMMPS and the output
files, so parsing and writing (not parallel) bound the speed-up from above.  The MPI result
counts only if its output files are complete and equal to the serial ones within one unit of
the last written digit (a rank leaving early can make mpiexec kill rank 0 while it writes).

Goal: serial / MPI >= 1.7 for 2 ranks.  The machine must have RANKS free cores: on a shared
machine the ratio mostly measures the other load.

    python benchmarks/mpi_speedup.py [--beads 260000] [--steps 1000] [--ranks 2] [--repeat 1]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import load_generator  # noqa: E402

BIN = Path(sys.executable).parent


def mpiexec() -> str | None:
    local = BIN / "mpiexec"
    return str(local) if local.exists() else shutil.which("mpiexec")


def children_cpu() -> float:
    """CPU seconds (user + system) of every finished child process and their children."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed_run(cmd: list[str], cwd: Path, timeout: float) -> tuple[float, subprocess.CompletedProcess | None]:
    """Wall time of ``cmd``; on timeout the whole process group is killed (SIGKILL)."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return time.perf_counter() - t0, None
    return time.perf_counter() - t0, subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def same_outputs(a: Path, b: Path) -> str | None:
    """None when b holds a's FibreNet outputs (within one unit of the last digit), else why not."""
    import numpy as np

    from fibrelmp.translate.fibrenet.writer import read_restart, read_xyz

    names_a = sorted(p.name for p in a.iterdir() if p.is_file())
    names_b = sorted(p.name for p in b.iterdir() if p.is_file())
    if names_a != names_b:
        return f"files differ: {names_b} vs serial {names_a}"
    for name in names_a:
        if name.endswith(".xyz"):
            fa, fb = read_xyz(a / name), read_xyz(b / name)
            if [f.step for f in fa] != [f.step for f in fb]:
                return f"{name}: frames differ"
            for x, y in zip(fa, fb):
                if x.names != y.names or not np.allclose(x.values, y.values, rtol=0, atol=1.0001e-5):
                    return f"{name}: values differ beyond the last digit"
        elif name.endswith(".res"):
            (na, ra), (nb, rb) = read_restart(a / name), read_restart(b / name)
            if na != nb or not np.allclose(ra, rb, rtol=1.0001e-5, atol=1e-12):
                return f"{name}: values differ beyond the last digit"
    return None


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--beads", type=int, default=260000)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=1, help="interleaved (serial, MPI) pairs; best of each")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds before a run counts as hung")
    args = ap.parse_args()

    launcher = mpiexec()
    if launcher is None:
        print("mpiexec not found (pip install mpich)")
        return 1
    cli = [sys.executable, "-m", "fibrelmp.cli", "-q", "run", "input.txt"]
    gen = load_generator()
    with tempfile.TemporaryDirectory(prefix="fibrelmp-bench-mpi-") as tmp:
        tmp = Path(tmp)
        net = gen.generate(gen.parse_args([
            "--beads", str(args.beads), "--seed", str(args.seed), "--out", str(tmp),
            "--run", str(args.steps), "--output-freq", str(args.steps), "--output-data", "position"]))
        print(f"network: {net['n']} beads, {len(net['springs'])} springs, {len(net['angles'])} angles, "
              f"box {net['L']:.4g}; {args.steps} steps, 2 frames (positions); {args.ranks} ranks; "
              f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
        serial, parallel, cpu = [], [], {"serial": [], "mpi": []}
        for r in range(args.repeat):
            for label, prefix, times in (("serial", [], serial),
                                         (f"{args.ranks} ranks", [launcher, "-n", str(args.ranks)], parallel)):
                out = tmp / f"out_{'mpi' if prefix else 'serial'}{r}"
                c0 = children_cpu()
                t, proc = timed_run(prefix + cli + ["--out", str(out)], tmp, args.timeout)
                cpu["mpi" if prefix else "serial"].append(children_cpu() - c0)
                if proc is None:
                    print(f"  pass {r + 1}: {label} HUNG (killed after {t:.0f} s)")
                    print("speed-up: n/a (a run hung)")
                    return 1
                if proc.returncode != 0:
                    print(f"  pass {r + 1}: {label} failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
                    print("speed-up: n/a (a run failed)")
                    return 1
                times.append(t)
                print(f"  pass {r + 1}: {label} {t:.2f} s wall, {cpu['mpi' if prefix else 'serial'][-1]:.2f} s CPU")
            why = same_outputs(tmp / f"out_serial{r}", tmp / f"out_mpi{r}")
            if why is not None:
                print(f"  pass {r + 1}: MPI outputs are not the serial ones: {why}")
                print("speed-up: n/a (MPI outputs incomplete or different)")
                return 1
        t_ser, t_par = min(serial), min(parallel)
        ratio = t_ser / t_par
        # what free cores would give if the ranks were balanced: serial CPU / CPU per rank
        # (MPI wait loops spin and count as CPU, so this underestimates a little)
        cpu_estimate = min(cpu["serial"]) / (min(cpu["mpi"]) / args.ranks)
        print(f"CPU time: serial {min(cpu['serial']):.2f} s, {args.ranks} ranks {min(cpu['mpi']):.2f} s in all; "
              f"speed-up on {args.ranks} free cores estimated from CPU time: {cpu_estimate:.2f}")
        print(f"serial fibrelmp run: {t_ser:.2f} s; mpiexec -n {args.ranks}: {t_par:.2f} s "
              f"(outputs equal to the serial ones); load average now {os.getloadavg()[0]:.2f}")
        goal = 1.7 if args.ranks == 2 else 0.85 * args.ranks
        verdict = "OK" if ratio >= goal else f"BELOW GOAL {goal:g}"
        print(f"{args.ranks}-rank speed-up: {ratio:.2f} ({verdict})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
