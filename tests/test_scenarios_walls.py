"""The shared real-cmusen scenarios whose metrics depend on MUSEN's particle-wall law, run
through fibrelmp's CLI (long: skipped unless FIBRELMP_SLOW=1).

* rotating_drum: 250 spheres in a 24-facet drum for 0.8 s (~1.5 min serial): the README's four
  metrics (tests/scenarios/drum_metrics.py), in particular spheres reaching the facet corners;
* oblique_two_materials: every metric (tests/scenarios/oblique_metrics.py), the plate impacts
  and slide-to-roll spheres 0-9 among them.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest

from tests.conftest import styles_or_skip

from .conftest import data_path

pytestmark = pytest.mark.skipif(os.environ.get("FIBRELMP_SLOW", "") in ("", "0"),
                                reason="long scenario run: set FIBRELMP_SLOW=1")


def _run(folder, job: str) -> None:
    styles_or_skip()
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "-q", "run", job, "-o", "out",
                           "--work", "work"], cwd=folder, capture_output=True,
                          text=True, timeout=7200, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _copy(name: str, files: list[str], tmp_path):
    src = data_path("real-outputs", "musen", "scenarios", name)
    for f in files:
        shutil.copy(src / f, tmp_path)
    return src


def test_rotating_drum_reaches_the_facet_corners(tmp_path):
    from .scenarios.drum_metrics import compare, drum_metrics

    src = _copy("rotating_drum", ["drum_scene.txt", "job_drum.txt"], tmp_path)
    _run(tmp_path, "job_drum.txt")
    mine = drum_metrics(tmp_path / "out" / "drum_result.txt", src / "drum_scene.txt")
    ref = drum_metrics(src / "cmusen_drum_result.txt.gz", src / "drum_scene.txt")
    rows = compare(mine, ref)
    for key, a, b, ok in rows:
        print(f"{key}: fibrelmp {a:.6g}, cmusen {b:.6g}, {'ok' if ok else 'OUT OF TOLERANCE'}")
    assert all(ok for *_, ok in rows)
    assert mine["max_reach"] >= 14.94e-3         # the inscribed radius is 14.872 mm


def test_oblique_plate_metrics(tmp_path):
    """Every metric of the oblique scenario (tests/scenarios/oblique_metrics.py), the plate
    impacts and slide-to-roll spheres (MUSEN's particle-wall law) among them."""
    from .scenarios.oblique_metrics import compare

    src = _copy("oblique_two_materials", ["oblique_scene.txt", "job_oblique.txt"], tmp_path)
    _run(tmp_path, "job_oblique.txt")
    rows = compare(tmp_path / "out" / "oblique_result_prec17.txt",
                   src / "cmusen_oblique_result_prec17.txt.gz")
    for r in rows:
        print(r.line())
    plate = [r for r in rows if not r.kind.startswith("pair_")]
    assert len(plate) == 30
    assert all(r.ok for r in rows)
