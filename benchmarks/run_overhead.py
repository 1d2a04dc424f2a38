#!/usr/bin/env python3
"""Run overhead: ``fibrelmp run`` versus bare LAMMPS running the same rendered in.lammps.

Generates a random ~50,000-bead FibreNet network (examples/generate_network.py; 1000 steps,
a frame every 250 steps) in a temporary folder, then in the same process measures:

  (a) fibrelmp = fibrelmp.translate.fibrenet.reader.read(input.txt) +
      fibrelmp.pipeline.run_model.run_fibrenet(model, out=..., progress=False): translation, LAMMPS run (line by line, as the CLI does) and writing
      FibreNet's output files from the dump;
  (b) bare     = new_lammps([...]); chdir(job folder); lmp.file('in.lammps'); close, on the
      job folder (a) rendered, i.e. the same LAMMPS work (including its write_dump frames)
      with none of fibrelmp's Python around it.

Goal: fibrelmp / bare <= 1.03.  The fibrelmp time is split into read_input, translate,
LAMMPS (runner.run_script) and output conversion (dump -> FibreNet files) by wrapping those
functions with timers, so the overhead sources are visible.

    python benchmarks/run_overhead.py [--beads 50000] [--steps 1000] [--repeat 1]
"""

from __future__ import annotations

import argparse
import functools
import gc
import os
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import load_generator  # noqa: E402




class Timers:
    """Accumulate wall time of selected functions (wrapped in their modules)."""

    def __init__(self):
        self.acc: dict[str, float] = {}
        self.undo: list = []

    def wrap(self, module, name: str, label: str) -> None:
        func = getattr(module, name, None)
        if func is None:         # the code moved: the split is then just less detailed
            return

        @functools.wraps(func)
        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return func(*args, **kwargs)
            finally:
                self.acc[label] = self.acc.get(label, 0.0) + time.perf_counter() - t0

        setattr(module, name, timed)
        self.undo.append((module, name, func))

    def restore(self) -> None:
        for module, name, func in reversed(self.undo):
            setattr(module, name, func)
        self.undo.clear()


def run_fibrelmp(input_path: Path, out: Path) -> tuple[float, dict[str, float], object]:
    import fibrelmp.post.to_fibrenet as to_fibrenet
    import fibrelmp.runner as runner
    import fibrelmp.translate.lammps_job as lammps_job
    from fibrelmp.pipeline.run_model import run_fibrenet
    from fibrelmp.translate.fibrenet.reader import read

    timers = Timers()
    # the pipeline looks up write_job / run_script / write_fibrenet in their modules at call
    # time, so wrapping the module attributes times exactly those parts
    timers.wrap(lammps_job, "write_job", "translate")
    timers.wrap(runner, "run_script", "LAMMPS (run_script)")
    timers.wrap(to_fibrenet, "write_fibrenet", "output conversion (worker thread, overlaps LAMMPS)")
    try:
        gc.collect()
        t0 = time.perf_counter()
        model = read(input_path)
        t1 = time.perf_counter()
        result = run_fibrenet(model, out=out, progress=False)
        t2 = time.perf_counter()
    finally:
        timers.restore()
    split = {"read_input": t1 - t0, **timers.acc}
    # the conversion runs on a second core during LAMMPS; what is left after LAMMPS ends
    # (last frame, restart file, thread join) is the serial tail
    serial = {k: v for k, v in split.items() if not k.startswith("output conversion")}
    split["serial tail after LAMMPS"] = (t2 - t0) - sum(serial.values())
    return t2 - t0, split, result


def run_bare(job_folder: Path) -> float:
    from fibrelmp._lammps import new_lammps

    cwd = os.getcwd()
    gc.collect()
    t0 = time.perf_counter()
    lmp = new_lammps(["-nocite", "-log", "none", "-screen", "none"])
    try:
        os.chdir(job_folder)
        lmp.file("in.lammps")
    finally:
        os.chdir(cwd)
        lmp.close()
    return time.perf_counter() - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--beads", type=int, default=50000)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--output-freq", type=int, default=250)
    ap.add_argument("--repeat", type=int, default=3,
                    help="pairs of (fibrelmp, bare) runs; the best of each is compared")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    gen = load_generator()
    with tempfile.TemporaryDirectory(prefix="fibrelmp-bench-") as tmp:
        tmp = Path(tmp)
        net_dir = tmp / "network"
        net = gen.generate(gen.parse_args([
            "--beads", str(args.beads), "--seed", str(args.seed), "--out", str(net_dir),
            "--run", str(args.steps), "--output-freq", str(args.output_freq)]))
        input_path = net_dir / "input.txt"
        nframes = args.steps // args.output_freq + 1 + (args.steps % args.output_freq > 0)
        print(f"network: {net['n']} beads, {len(net['springs'])} springs, {len(net['angles'])} "
              f"angles, box {net['L']:.4g}; {args.steps} steps, {nframes} frames")
        from fibrelmp._lammps import load_lammps_module

        load_lammps_module()              # library load is not part of either measurement

        fib, bare, splits = [], [], []
        for r in range(args.repeat):
            out = tmp / f"out{r}"
            t, split, result = run_fibrelmp(input_path, out)
            fib.append(t)
            splits.append(split)
            bare.append(run_bare(result.job.folder))
            print(f"  pass {r + 1}: fibrelmp {t:.2f} s, bare LAMMPS {bare[-1]:.2f} s")
        best = min(range(args.repeat), key=lambda i: fib[i])
        t_fib, t_bare = fib[best], min(bare)
        split = splits[best]
        lammps = split.get("LAMMPS (run_script)", 0.0)
        print(f"fibrelmp run (read_input + run): {t_fib:.2f} s")
        for name, value in split.items():
            print(f"  {name:22s} {value:7.3f} s  {100 * value / t_fib:5.1f} %")
        print(f"bare LAMMPS lmp.file('in.lammps'): {t_bare:.2f} s")
        if lammps:
            print(f"fibrelmp overhead outside LAMMPS: {t_fib - lammps:.2f} s "
                  f"({100 * (t_fib - lammps) / t_bare:.1f} % of bare); run_script vs bare: "
                  f"{lammps / t_bare:.3f}")
        ratio = t_fib / t_bare
        verdict = "OK" if ratio <= 1.03 else "ABOVE GOAL 1.03"
        print(f"fibrelmp/bare ratio: {ratio:.3f} ({verdict})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
