"""With the real cmusen (opt-in: FIBRELMP_CMUSEN=/path/to/CMUSEN, built as
shared/research/musen_build.md says): MUSEN opens fibrelmp's .mdem files.

* cmusen's EXPORT_TO_TEXT of fibrelmp's agglomerate result equals fibrelmp's own 17-digit
  text result in every field, object line and scene line (cmusen adds its stress fields 36/42
  as zeros), and fibrelmp's exporter gives cmusen's export byte for byte;
* cmusen simulates fibrelmp's import of a text scene to the same result as its own import.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.translate.musen.text import read_time_points

from .conftest import REPO

CMUSEN = os.environ.get("FIBRELMP_CMUSEN")
pytestmark = pytest.mark.skipif(not CMUSEN, reason="set FIBRELMP_CMUSEN to the real cmusen")
EXAMPLES = REPO / "examples" / "musen"


def _cmusen(folder: Path, script: str) -> None:
    (folder / "cm.txt").write_text(script)
    done = subprocess.run([CMUSEN, "-t=2", "-s=cm.txt"], cwd=folder, capture_output=True,
                          text=True, timeout=900)
    assert done.returncode == 0, done.stdout + done.stderr


def test_cmusen_exports_fibrelmps_result_as_fibrelmp_does(tmp_path):
    shutil.copy(EXAMPLES / "SphericalAgglomerate_text.txt", tmp_path)
    job = (EXAMPLES / "agglomerate_short_job.txt").read_text().replace(
        "RESULT_FILE          ./agglomerate_short_result.txt",
        "RESULT_FILE          ./agglomerate_short_result.txt\nTEXT_EXPORT_PRECISION 17")
    (tmp_path / "job.txt").write_text(job)
    python_api.run(tmp_path / "job.txt")
    _cmusen(tmp_path, "JOB\nSOURCE_FILE agglomerate_short_result.mdem\nRESULT_FILE ./cmusen.txt\n"
                      "COMPONENT EXPORT_TO_TEXT\nTEXT_EXPORT_PRECISION 17\n")
    ours = read_time_points(tmp_path / "agglomerate_short_result.txt")
    theirs = read_time_points(tmp_path / "cmusen.txt")
    assert np.array_equal(ours.times, theirs.times) and np.array_equal(ours.ids, theirs.ids)
    # every field, the stress tensor (36) fibrelmp stores and its principal stresses (42) that
    # cmusen's export computes from it included
    assert set(theirs.fields) == set(ours.fields) and {36, 42} <= set(ours.fields)
    for tag in ours.fields:
        assert np.array_equal(ours.fields[tag], theirs.fields[tag], equal_nan=True), tag
    assert np.nanmax(np.abs(ours.fields[36])) > 1e4
    lines = [(tmp_path / n).read_text().splitlines() for n in ("agglomerate_short_result.txt", "cmusen.txt")]
    assert [[ln.split(" 2 ")[0] for ln in f if ln.startswith("0 ")] for f in lines][0] == \
           [[ln.split(" 2 ")[0] for ln in f if ln.startswith("0 ")] for f in lines][1]
    assert [ln for ln in lines[0] if not ln.startswith("0 ")] == [ln for ln in lines[1] if not ln.startswith("0 ")]
    python_api.convert_file(tmp_path / "agglomerate_short_result.mdem", tmp_path / "ours.txt", precision=17)
    assert (tmp_path / "ours.txt").read_bytes() == (tmp_path / "cmusen.txt").read_bytes()


def test_cmusen_simulates_fibrelmps_import_as_its_own(tmp_path):
    simulate = ("JOB\nSOURCE_FILE init.mdem\nRESULT_FILE result.mdem\nCOMPONENT SIMULATOR\n"
                "SIMULATOR_TYPE CPU\nMODEL_PP ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\n"
                "SIMULATION_STEP 1e-7\nSAVING_STEP 2e-4\nEND_TIME 0.012\nEXT_ACCEL 0 0 0\n"
                "JOB\nSOURCE_FILE result.mdem\nRESULT_FILE ./result.txt\nCOMPONENT EXPORT_TO_TEXT\n"
                "TEXT_EXPORT_PRECISION 17\n")
    own, ours = tmp_path / "own", tmp_path / "ours"
    own.mkdir()
    ours.mkdir()
    shutil.copy(EXAMPLES / "SingelParticle_text.txt", own)
    _cmusen(own, "JOB\nSOURCE_FILE SingelParticle_text.txt\nRESULT_FILE init.mdem\n"
                 "COMPONENT IMPORT_FROM_TEXT\n" + simulate)
    python_api.convert_file(EXAMPLES / "SingelParticle_text.txt", ours / "init.mdem")
    _cmusen(ours, simulate)
    assert (ours / "result.txt").read_bytes() == (own / "result.txt").read_bytes()
