#!/usr/bin/env python3
"""Translation speed: fibrelmp's read_input + translate versus LAMMPS's own read_data.

Generates a random ~260,000-bead FibreNet network (examples/generate_network.py) in a
temporary folder, then in the same process measures, best of --repeat:

  (a) translate = fibrelmp.translate.fibrenet.reader.read(input.txt) +
      fibrelmp.translate.lammps_job.write_job(model, job)
      (parse the FibreNet input and model, write data.lammps, fibrenet_state.txt and in.lammps);
  (b) read_data = LAMMPS executing the ``read_data`` line of that in.lammps and the commands
      that load the per-bead state after it (the set-up commands before it are issued first,
      untimed, in a fresh instance).

Goal: translate / read_data <= 1.0, i.e. fibrelmp's whole translation costs no more than
LAMMPS reading the file it produces.

    python benchmarks/translate.py [--beads 260000] [--repeat 3] [--profile]
"""

from __future__ import annotations

import argparse
import gc
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import load_generator  # noqa: E402




def setup_and_read_data(script: Path) -> tuple[list[str], list[str], list[str]]:
    """The commands of in.lammps before the job's files are loaded, and the commands that load
    them: LAMMPS's ``read_data data.lammps`` (the baseline), and the script's own line (with
    the plugin, ``fibrenet/read_data topology.bin``), each with the per-bead state (atomfile)
    commands after it."""
    from fibrelmp.lammps_text import input_lines, read_script
    from fibrelmp.runplan import DATA_COMMANDS
    from fibrelmp.translate.lammps_job import DATA_NAME

    lines = [ln.strip() for ln in input_lines(read_script(script), script)]
    lines = [ln for ln in lines if ln and not ln.startswith("#")]
    k = next(i for i, ln in enumerate(lines) if ln.split()[0] in DATA_COMMANDS)
    end = next((i for i, ln in enumerate(lines) if ln.split() == ["variable", "fn_state", "delete"]), k)
    state = lines[k + 1:end + 1]
    return lines[:k], [f"read_data {DATA_NAME}"] + state, lines[k:end + 1]


def time_translate(input_path: Path, job_dir: Path) -> tuple[float, float, object]:
    from fibrelmp.translate.fibrenet.reader import read as read_input
    from fibrelmp.translate.lammps_job import write_job as translate

    shutil.rmtree(job_dir, ignore_errors=True)     # a fresh folder, as in a real first translate
    gc.collect()
    t0 = time.perf_counter()
    model = read_input(input_path)
    t1 = time.perf_counter()
    job = translate(model, job_dir)
    t2 = time.perf_counter()
    return t1 - t0, t2 - t1, job


def time_read_data(job_dir: Path, setup: list[str], read_data: list[str]) -> float:
    from fibrelmp._lammps import new_lammps

    cwd = os.getcwd()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        os.chdir(job_dir)
        for ln in setup:
            lmp.command(ln)
        gc.collect()
        t0 = time.perf_counter()
        for ln in read_data:
            lmp.command(ln)
        return time.perf_counter() - t0
    finally:
        os.chdir(cwd)
        lmp.close()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--beads", type=int, default=260000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--profile", action="store_true",
                    help="also cProfile one read_input + translate and print the top functions")
    args = ap.parse_args()

    gen = load_generator()
    with tempfile.TemporaryDirectory(prefix="fibrelmp-bench-") as tmp:
        tmp = Path(tmp)
        net_dir, job_dir = tmp / "network", tmp / "job"
        t0 = time.perf_counter()
        net = gen.generate(gen.parse_args(["--beads", str(args.beads), "--seed", str(args.seed),
                                           "--out", str(net_dir)]))
        t_gen = time.perf_counter() - t0
        input_path = net_dir / "input.txt"
        print(f"network: {net['n']} beads, {len(net['springs'])} springs, {len(net['angles'])} "
              f"angles, box {net['L']:.4g} (generated in {t_gen:.2f} s)")

        # warm-up (imports, jinja template compilation, LAMMPS library load), untimed
        _, _, job = time_translate(input_path, job_dir)
        setup, read_data, load = setup_and_read_data(job.script)
        print(f"model.txt {(net_dir / 'model.txt').stat().st_size / 1e6:.1f} MB, "
              f"data.lammps {job.data.stat().st_size / 1e6:.1f} MB")

        parse, write, rd, own = [], [], [], []
        for _ in range(args.repeat):       # interleaved, so machine-load drift hits both alike
            a, b, _ = time_translate(input_path, job_dir)
            parse.append(a)
            write.append(b)
            rd.append(time_read_data(job_dir, setup, read_data))
            if load != read_data:
                own.append(time_read_data(job_dir, setup, load))
        total = [a + b for a, b in zip(parse, write)]
        best = min(range(args.repeat), key=lambda i: total[i])
        t_tr, t_rd = total[best], min(rd)
        print(f"translate (read_input + translate), best of {args.repeat}: {t_tr:.3f} s "
              f"(read_input {parse[best]:.3f} s + translate {write[best]:.3f} s); "
              f"all: {', '.join(f'{t:.3f}' for t in total)}")
        print(f"LAMMPS read_data, best of {args.repeat}: {t_rd:.3f} s; "
              f"all: {', '.join(f'{t:.3f}' for t in rd)}")
        if own:
            print(f"the job's own loading ({load[0]}), best of {args.repeat}: {min(own):.3f} s "
                  f"(read_data / it: {t_rd / min(own):.1f}x)")

        if args.profile:
            import cProfile
            import pstats

            from fibrelmp.translate.fibrenet.reader import read as read_input
            from fibrelmp.translate.lammps_job import write_job as translate

            prof = cProfile.Profile()
            prof.enable()
            translate(read_input(input_path), job_dir)
            prof.disable()
            pstats.Stats(prof).sort_stats("tottime").print_stats(25)

        ratio = t_tr / t_rd
        verdict = "OK" if ratio <= 1.0 else "ABOVE GOAL 1.0"
        print(f"translate/read_data ratio: {ratio:.2f} ({verdict})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
