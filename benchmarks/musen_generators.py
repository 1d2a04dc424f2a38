"""cmusen's generators and MUSEN's Example 6, fibrelmp against the real cmusen, in one run.

Times (wall clock, each in its own process, on MUSEN's example scene PackingGeneration.mdem):

* package: PACKAGE_GENERATOR of MUSEN's Example 4 (5,371 spheres);
* bonds: BONDS_GENERATOR (distance 0..1e-4 m, diameter 1e-3 m) on one packing (cmusen's, so
  both codes bond the same spheres);
* example6: MUSEN's Example 6 script unchanged (packing, then 1e-4 s of simulation).

cmusen runs with ``-t=2``; without FIBRELMP_CMUSEN (or /work/shared/oracles/CMUSEN) it is
skipped with a message and only fibrelmp's times are printed.

    python benchmarks/musen_generators.py           # ~2 min with cmusen
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SCENE = REPO / "tests" / "data" / "real-inputs" / "musen" / "PackingGeneration.mdem"
ORACLE_DEFAULT = Path("/work/shared/oracles/CMUSEN")

PACKAGE = """JOB
SOURCE_FILE          ../InitScenes/PackingGeneration.mdem
RESULT_FILE          ./Result_PackingGeneration.mdem
COMPONENT            PACKAGE_GENERATOR
"""
BONDS = """JOB
SOURCE_FILE          ./packing.mdem
RESULT_FILE          ./Result_Bonds.mdem
COMPONENT            BONDS_GENERATOR
BOND_GEN_MATERIAL    1 Clay
BOND_GEN_MINDIST     1 0
BOND_GEN_MAXDIST     1 1e-4
BOND_GEN_DIAMETER    1 1e-3
"""


def _example6() -> str:
    """MUSEN's Example 6 as shipped (from the MUSEN mirror, else a copy of its lines)."""
    mirror = Path("/work/.mirror/msolids+musen/repo")
    if mirror.exists():
        done = subprocess.run(["git", "-C", str(mirror), "show",
                               "HEAD:Installers/Data/Examples/Scripts/Example 6 - Multiple jobs.txt"],
                              capture_output=True, text=True)
        if done.returncode == 0:
            return done.stdout
    return (PACKAGE + "\u00b4\nJOB\nSOURCE_FILE ./Result_PackingGeneration.mdem\nRESULT_FILE "
            "./Result_Simulation.mdem\nCOMPONENT SIMULATOR\nSIMULATOR_TYPE CPU\nMODEL_PP "
            "ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\nSIMULATION_STEP 2e-7\n"
            "SAVING_STEP 1e-5\nEND_TIME 1e-4\nEXT_ACCEL 0 0 -9.81\n"
            "SIMULATION_DOMAIN -0.03 -0.03 -0.04 0.03 0.03 0.04\n")


def _folder(root: Path, name: str, script: str, packing: Path | None) -> Path:
    case = root / name
    (case / "InitScenes").mkdir(parents=True)
    (case / "Scripts").mkdir()
    shutil.copy(SCENE, case / "InitScenes" / "PackingGeneration.mdem")
    if packing is not None:
        shutil.copy(packing, case / "Scripts" / "packing.mdem")
    (case / "Scripts" / "job.txt").write_text(script, encoding="utf-8")
    return case / "Scripts"


def _time(cmd: list[str], cwd: Path) -> float:
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    took = time.perf_counter() - start
    errors = [line for line in done.stdout.splitlines() if line.startswith("Error")]
    if done.returncode != 0 or errors:
        sys.exit(f"{' '.join(cmd)} failed in {cwd}:\n{done.stderr[-2000:]}{' '.join(errors)}")
    return took


def main() -> None:
    oracle = Path(os.environ.get("FIBRELMP_CMUSEN", ORACLE_DEFAULT))
    have_cmusen = oracle.exists()
    if not have_cmusen:
        print(f"cmusen not found ({oracle}; set FIBRELMP_CMUSEN): fibrelmp's times only")
    fibrelmp = [sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", "job.txt"]
    cases = [("package", PACKAGE), ("bonds", BONDS), ("example6", _example6())]
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-generators.") as tmp:
        root = Path(tmp)
        packing = None
        for name, script in cases:
            if name == "bonds":
                packing = root / ("cmusen-package" if have_cmusen else "fibrelmp-package") / \
                    "Scripts" / "Result_PackingGeneration.mdem"
            mine = _time(fibrelmp, _folder(root, f"fibrelmp-{name}", script, packing))
            theirs = (_time([str(oracle), "-t=2", "-s=job.txt"], _folder(root, f"cmusen-{name}", script, packing))
                      if have_cmusen else float("nan"))
            rows.append((name, mine, theirs))
    print(f"{'case':10s} {'fibrelmp [s]':>13s} {'cmusen -t=2 [s]':>16s} {'ratio':>7s}")
    for name, mine, theirs in rows:
        print(f"{name:10s} {mine:13.2f} {theirs:16.2f} {mine / theirs:7.2f}")


if __name__ == "__main__":
    main()
