#!/usr/bin/env python3
"""fibrelmp against the codes its users leave: the real FibreNet and the real cmusen.

The same inputs, the same steps, on the same cores, wall time of the whole command including
start-up (a subprocess each, in a fresh folder):

  * FibreNet networks of ~5k / 50k / 260k / 2.6M beads (examples/generate_network.py) for
    30,000 / 3,000 / 600 / 200 steps, a frame every 400 steps (2.6M: at 0 and 200) (the generator's output_freq; both codes write
    their _coord/_vel/_force.xyz and _restart.res at the same steps, checked by counting
    frames): the real FibreNet on PoCL's CPU device with 2 threads (POCL_MAX_PTHREAD_COUNT=2;
    ``kernel.cl`` copied from beside the executable);
  * MUSEN's agglomerate (examples/musen/SphericalAgglomerate_text.txt: 5,696 spheres,
    18,802 bonds), 5,000 steps, a cmusen job script in the style of
    examples/musen/agglomerate_short_job.txt (import, simulate, export to text), and a
    packing: 400 spheres falling into an open steel box of 10 triangles, 100,000 steps, the
    same three jobs: the real ``cmusen -t=2 -s=job.txt``;
  * fibrelmp: ``fibrelmp -q run`` serially and under ``mpiexec -n 2`` (the mpiexec beside
    the Python, i.e. the mpich wheel's, or on PATH).

The real codes run only when their executables are given (``--fibrenet``/``FIBRELMP_FIBRENET``,
``--cmusen``/``FIBRELMP_CMUSEN``); otherwise that column says "not given".  Every side runs
``--repeat`` times, interleaved (the order rotates each round); the table shows medians,
microseconds per particle-step, and the ratio real code / best fibrelmp (issue 28's goals:
>= 3 for FibreNet at every size, >= 2.5 for the agglomerate).  The load average is printed before and after, and the
highest 1-minute load seen at the start of any run.

    python benchmarks/vs_real_codes.py --fibrenet /path/fibrenet --cmusen /path/CMUSEN
    python benchmarks/vs_real_codes.py --quick            # small sizes: checks the script
    python benchmarks/vs_real_codes.py --only fibrenet-5k --only musen-agglomerate --repeat 5
"""

from __future__ import annotations

import argparse
import datetime
import math
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from _common import load_generator  # noqa: E402

AGGLOMERATE = ROOT / "examples" / "musen" / "SphericalAgglomerate_text.txt"
SIDES = ("real", "fibrelmp-1", "fibrelmp-2")
# real code / best of fibrelmp's 1 and 2 ranks (issue 28: >= 3 on FibreNet at every size, >= 2.5
# against cmusen -t=2 on the agglomerate)
GOALS = {"fibrenet-5k": 3.0, "fibrenet-50k": 3.0, "fibrenet-260k": 3.0, "fibrenet-2.6m": 3.0,
         "musen-agglomerate": 2.5}


@dataclass
class Case:
    name: str
    kind: str                      # "fibrenet" or "musen"
    particles: int                 # beads or spheres (set when the input is made)
    steps: int
    make: object                   # make(folder) -> (input file name, particles)
    times: dict = field(default_factory=lambda: {s: [] for s in SIDES})
    frames: dict = field(default_factory=dict)
    note: str = ""


# ---------------------------------------------------------------- inputs

def fibrenet_case(name: str, beads: int, steps: int) -> Case:
    def make(folder: Path) -> tuple[str, int]:
        gen = load_generator()
        net = gen.generate(gen.parse_args(["--beads", str(beads), "--seed", "1", "--out", str(folder),
                                           "--run", str(steps), "--output-freq", str(min(400, steps))]))
        return "input.txt", int(net["n"])
    return Case(name, "fibrenet", beads, steps, make)


MUSEN_JOB = """JOB
SOURCE_FILE          {scene}
RESULT_FILE          init.mdem
COMPONENT            IMPORT_FROM_TEXT
JOB
SOURCE_FILE          init.mdem
RESULT_FILE          result.mdem
COMPONENT            SIMULATOR
SIMULATOR_TYPE       CPU
MODEL_PP             ModelPPHertzMindlin
{models}SIMULATION_STEP      {dt:g}
SAVING_STEP          {save:g}
END_TIME             {end:g}
EXT_ACCEL            0 0 -9.81
SIMULATION_DOMAIN    {domain}
JOB
SOURCE_FILE          result.mdem
RESULT_FILE          ./result.txt
COMPONENT            EXPORT_TO_TEXT
"""


def agglomerate_case(steps: int) -> Case:
    """examples/musen/agglomerate_short_job.txt with ``steps`` steps of 1e-8 s, 10 saves."""
    def make(folder: Path) -> tuple[str, int]:
        shutil.copy(AGGLOMERATE, folder / AGGLOMERATE.name)
        dt = 1e-8
        (folder / "job.txt").write_text(MUSEN_JOB.format(
            scene=AGGLOMERATE.name, dt=dt, save=steps * dt / 10, end=steps * dt,
            models="MODEL_SB             ModelSBElastic\nMODEL_SB_PARAMS      CONSIDER_BREAKAGE 1\n",
            domain="-0.02 -0.02 -0.02 0.02 0.02 0.02"))
        # object lines "0 ID 1 SHAPE ...": shape 1 is a sphere (9 a solid bond, 14 a triangle)
        spheres = sum(1 for line in AGGLOMERATE.read_text().splitlines()
                      if line.split()[:1] == ["0"] and line.split()[3:4] == ["1"])
        return "job.txt", spheres
    return Case("musen-agglomerate", "musen", 5696, steps, make)


def packing_scene(n: int, seed: int = 1) -> str:
    """MUSEN text scene: ``n`` soft glass beads (R 0.9-1.1 mm) on a jittered lattice of up to 7
    layers above the floor of an open steel box (20 x 20 mm for n <= 448, wider for more; 40 mm
    high; 10 triangles, normals inward), in MUSEN 1.74's text format (the layout of
    tests/data/real-outputs/musen/scenarios/rotating_drum/drum_scene.txt)."""
    rng = np.random.default_rng(seed)
    spacing = 0.0024
    side = max(8, math.ceil(math.sqrt(n / 7)))        # beads per lattice row
    w, h = 0.0032 + (side - 1) * spacing, 0.04
    corners = {"a": (0, 0, 0), "b": (w, 0, 0), "c": (w, w, 0), "d": (0, w, 0),
               "A": (0, 0, h), "B": (w, 0, h), "C": (w, w, h), "D": (0, w, h)}
    # each triangle (p, q, r) with (q - p) x (r - p) pointing into the box
    tris = ["abc", "acd", "aBb", "aAB", "bCc", "bBC", "cDd", "cCD", "dAa", "dDA"]
    lines = []
    for k, t in enumerate(tris):
        xyz = " ".join(repr(float(v)) for p in t for v in corners[p])
        lines.append(f"0 {k} 1 14 5  23 MSTEEL 24 0 1e+300 2 0 44 {xyz} 20 0 0 0 18 0 15 0 0 0")
    for i in range(n):
        ix, iy, iz = i % side, (i // side) % side, i // (side * side)
        p = np.array([0.0016 + ix * spacing, 0.0016 + iy * spacing, 0.002 + iz * spacing])
        p = (p + rng.uniform(-1e-4, 1e-4, 3)).tolist()
        r = float(rng.uniform(0.0009, 0.0011))
        v = rng.uniform(-0.05, 0.05, 3).tolist()
        lines.append(f"0 {len(tris) + i} 1 1 5 {r!r} {r!r} 23 MBEAD 24 0 1e+300 2 0 16 0.0 0.0 0.0 "
                     f"12 {p[0]!r} {p[1]!r} {p[2]!r} 20 0 0 0 18 0 31 1 0 0 0 37 0 15 "
                     f"{v[0]!r} {v[1]!r} {v[2]!r}")
    ids = " ".join(str(k) for k in range(len(tris)))
    lines += [
        f"22 -0.005 -0.005 -0.005 {w + 0.005!r} {w + 0.005!r} 0.045",
        "28 0 0 0 0 0 0 0 0 0 0", "29 0", "30 0",
        "25 Box GBOX 0 0 0 0 0", "26 0", f"27 {len(tris)} {ids}",
        "32 MBEAD SoftGlassBead 0 2500.0 1 1000 2 0.1 3 0.5 7 100000000.0 8 10000000.0 9 10000000.0 "
        "10 0.25 11 1 12 2e-05 13 0.7 14 1.7e-05 15 2e+10",
        "32 MSTEEL Steel 0 7800.0 1 1000 2 0.1 3 0.5 7 210000000000.0 8 4000000000.0 9 4000000000.0 "
        "10 0.29 11 1 12 2e-05 13 0.7 14 1.7e-05 15 2e+10",
        "33 MBEAD MBEAD 200 0.6 201 0.5 202 0.05",
        "33 MBEAD MSTEEL 200 0.7 201 0.6 202 0.05",
        "33 MSTEEL MSTEEL 200 0.8 201 0.3 202 0.01"]
    return "\n".join(lines) + "\n"


def packing_domain(n: int) -> str:
    w = 0.0032 + (max(8, math.ceil(math.sqrt(n / 7))) - 1) * 0.0024
    return f"-0.005 -0.005 -0.005 {w + 0.005!r} {w + 0.005!r} 0.045"


def packing_case(spheres: int, steps: int) -> Case:
    def make(folder: Path) -> tuple[str, int]:
        (folder / "packing_scene.txt").write_text(packing_scene(spheres))
        dt = 1e-6
        (folder / "job.txt").write_text(MUSEN_JOB.format(
            scene="packing_scene.txt", dt=dt, save=steps * dt / 10, end=steps * dt,
            models="MODEL_PW             ModelPWHertzMindlin\n",
            domain=packing_domain(spheres)))
        return "job.txt", spheres
    return Case("musen-packing", "musen", spheres, steps, make)


def cases(quick: bool) -> list[Case]:
    if quick:
        return [fibrenet_case("fibrenet-5k", 600, 800), fibrenet_case("fibrenet-50k", 2000, 400),
                fibrenet_case("fibrenet-260k", 4000, 200), fibrenet_case("fibrenet-2.6m", 8000, 100),
                agglomerate_case(40),
                packing_case(40, 1000)]
    return [fibrenet_case("fibrenet-5k", 5000, 30000), fibrenet_case("fibrenet-50k", 50000, 3000),
            fibrenet_case("fibrenet-260k", 260000, 600), fibrenet_case("fibrenet-2.6m", 2600000, 200),
            agglomerate_case(5000), packing_case(400, 100000)]


# ---------------------------------------------------------------- running

def mpiexec() -> str | None:
    local = Path(sys.executable).parent / "mpiexec"
    return str(local) if local.exists() else shutil.which("mpiexec")


def timed(cmd: list[str], cwd: Path, env: dict, stdin: str | None, timeout: float) -> tuple[float, str | None]:
    """Wall seconds of ``cmd`` and None, or the seconds and why it failed."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        out, _ = proc.communicate(stdin.encode() if stdin else None, timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return time.perf_counter() - t0, f"timed out after {timeout:.0f} s"
    wall = time.perf_counter() - t0
    (cwd / "run_output.txt").write_bytes(out)
    if proc.returncode != 0:
        return wall, f"exit {proc.returncode}: {out.decode(errors='replace')[-800:]}"
    return wall, None


def count_frames(path: Path) -> int:
    with open(path, "rb") as fh:
        return sum(1 for line in fh if line.startswith(b"FRAME"))


def run_side(case: Case, side: str, src: Path, input_name: str, work: Path, args) -> float:
    """Run one side in a fresh copy of ``src``; returns the wall time (raises on failure)."""
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(src, work)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    stdin = None
    if side == "real" and case.kind == "fibrenet":
        exe = Path(args.fibrenet).resolve()
        shutil.copy(exe.parent / "kernel.cl", work / "kernel.cl")
        env["POCL_MAX_PTHREAD_COUNT"] = str(args.threads)
        cmd, stdin = [str(exe)], f"1\n1\n{input_name}\n"       # PoCL platform, CPU device, input
    elif side == "real":
        cmd = [str(Path(args.cmusen).resolve()), f"-t={args.threads}", f"-s={input_name}"]
    else:
        cmd = [sys.executable, "-m", "fibrelmp.cli", "-q", "run", input_name]
        if side == "fibrelmp-2":
            cmd = [args.mpiexec, "-n", "2"] + cmd
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    wall, error = timed(cmd, work, env, stdin, args.timeout)
    if error is None:
        error = check_outputs(case, side, work)
    if error is not None:
        raise RuntimeError(f"{case.name} / {side}: {error}")
    return wall


def check_outputs(case: Case, side: str, work: Path) -> str | None:
    """None when the run wrote its results (and, for FibreNet, how many frames)."""
    if case.kind == "fibrenet":
        coord = work / "network_coord.xyz"
        if not coord.is_file() or not (work / "network_restart.res").is_file():
            return "no network_coord.xyz / network_restart.res"
        if side == "real":
            log = b"".join(p.read_bytes() for p in work.glob("log_*.txt"))
            if b"ERROR" in log:
                return "FibreNet's log reports an ERROR"
        case.frames[side] = count_frames(coord)
        return None
    result = work / "result.txt"
    return None if result.is_file() and result.stat().st_size > 0 else "no result.txt"


# ---------------------------------------------------------------- main

def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fibrenet", default=os.environ.get("FIBRELMP_FIBRENET"),
                    help="the real FibreNet executable (kernel.cl beside it); env FIBRELMP_FIBRENET")
    ap.add_argument("--cmusen", default=os.environ.get("FIBRELMP_CMUSEN"),
                    help="the real cmusen executable; env FIBRELMP_CMUSEN")
    ap.add_argument("--threads", type=int, default=2, help="threads of the real codes (PoCL, cmusen -t)")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved rounds; medians are shown")
    ap.add_argument("--quick", action="store_true", help="small sizes: checks that the script works")
    ap.add_argument("--only", action="append", help="a case by name (repeatable): " +
                    ", ".join(c.name for c in cases(False)))
    ap.add_argument("--no-mpi", action="store_true", help="skip the 2-rank fibrelmp runs")
    ap.add_argument("--keep", type=Path, default=None, help="keep the run folders here")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds before a run counts as hung")
    args = ap.parse_args()

    chosen = [c for c in cases(args.quick) if not args.only or c.name in args.only]
    unknown = set(args.only or []) - {c.name for c in cases(args.quick)}
    if unknown:
        ap.error(f"unknown case(s): {', '.join(sorted(unknown))}")
    args.mpiexec = None if args.no_mpi else mpiexec()
    sides = {"fibrenet": [s for s in SIDES if (s != "real" or args.fibrenet) and (s != "fibrelmp-2" or args.mpiexec)],
             "musen": [s for s in SIDES if (s != "real" or args.cmusen) and (s != "fibrelmp-2" or args.mpiexec)]}
    for exe, what in ((args.fibrenet, "FibreNet"), (args.cmusen, "cmusen")):
        if exe and not Path(exe).is_file():
            ap.error(f"{what} executable not found: {exe}")
    if args.fibrenet and not (Path(args.fibrenet).resolve().parent / "kernel.cl").is_file():
        ap.error(f"FibreNet needs kernel.cl beside {args.fibrenet}")

    load0 = os.getloadavg()
    started = datetime.datetime.now().astimezone()
    peak_load = load0[0]
    print(f"vs_real_codes: {started:%Y-%m-%d %H:%M %Z}, {os.cpu_count()} cores, load average "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}; FibreNet: {args.fibrenet or 'not given'}; "
          f"cmusen: {args.cmusen or 'not given'}; mpiexec: {args.mpiexec or 'none'}", flush=True)
    failed = []
    with tempfile.TemporaryDirectory(prefix="fibrelmp-vs-real-") as tmp:
        base = args.keep or Path(tmp)
        for case in chosen:
            src = base / case.name / "input"
            shutil.rmtree(src, ignore_errors=True)
            src.mkdir(parents=True)
            input_name, case.particles = case.make(src)
            here = sides[case.kind]
            print(f"== {case.name}: {case.particles} particles x {case.steps} steps; sides {', '.join(here)}",
                  flush=True)
            for r in range(args.repeat):
                order = here[r % len(here):] + here[:r % len(here)]
                for side in order:
                    load = os.getloadavg()[0]
                    peak_load = max(peak_load, load)
                    try:
                        wall = run_side(case, side, src, input_name, base / case.name / f"{side}-{r}", args)
                    except RuntimeError as exc:
                        print(f"   FAILED {exc}", flush=True)
                        failed.append(f"{case.name}/{side}")
                        continue
                    case.times[side].append(wall)
                    print(f"   round {r + 1} {side:<11} {wall:8.2f} s  (load {load:.2f})", flush=True)
            if len(set(case.frames.values())) > 1:
                case.note = f"frames differ: {case.frames}"
                failed.append(f"{case.name}: frames")
    load1 = os.getloadavg()
    print_table(chosen, args, load0, load1, peak_load)
    if failed:
        print(f"FAILED: {', '.join(failed)}")
    return 1 if failed else 0


def print_table(chosen: list[Case], args, load0, load1, peak_load: float) -> None:
    print()
    print(f"medians of {args.repeat} interleaved rounds, wall time of the whole command incl. start-up; "
          f"real codes with {args.threads} threads; load average {load0[0]:.2f} before / "
          f"{load1[0]:.2f} after, highest at a run's start {peak_load:.2f}"
          f"{' (QUICK sizes: goals not meaningful)' if args.quick else ''}")
    head = (f"| {'case':<18}| {'particles':>9} | {'steps':>7} | {'real s':>7} | {'1 rank s':>8} | {'2 ranks s':>9} "
            f"| {'us/particle-step real / 1 / 2':<30}| {'real / best':>11} | {'goal':<6}| {'verdict':<8}|")
    print(head)
    print("|" + "|".join("-" * len(c) for c in head.split("|")[1:-1]) + "|")
    fibrenet_ratios = []
    for case in chosen:
        med = {s: statistics.median(t) if t else None for s, t in case.times.items()}
        per = [f"{1e6 * med[s] / (case.particles * case.steps):.3f}" if med[s] else "-" for s in SIDES]
        best = min((med[s] for s in ("fibrelmp-1", "fibrelmp-2") if med[s]), default=None)
        ratio = med["real"] / best if med["real"] and best else None
        goal = GOALS.get(case.name)
        verdict = "-" if ratio is None or goal is None else ("OK" if ratio >= goal else "MISSED")

        def cell(s: str) -> str:
            return f"{med[s]:.2f}" if med[s] else ("not given" if s == "real" else "-")
        print(f"| {case.name:<18}| {case.particles:>9} | {case.steps:>7} | {cell('real'):>7} | {cell('fibrelmp-1'):>8} "
              f"| {cell('fibrelmp-2'):>9} | {' / '.join(per):<30}| {(f'{ratio:.2f}' if ratio else '-'):>11} "
              f"| {(f'>={goal:g}' if goal else '-'):<6}| {verdict:<8}|")
        if ratio is not None and case.kind == "fibrenet":
            fibrenet_ratios.append(ratio)
        if case.note:
            print(f"  note: {case.note}")
    if fibrenet_ratios:
        print(f"worst FibreNet ratio, real / best fibrelmp: {min(fibrenet_ratios):.2f}")


if __name__ == "__main__":
    raise SystemExit(main())
