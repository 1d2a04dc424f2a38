"""cmusen's PACKAGE_GENERATOR and BONDS_GENERATOR jobs against the real cmusen's results
(tests/data/real-outputs/musen/generators/README.md), and the re-import of cmusen's text
export of a generated packing.

The packing is random in both codes: its statistics are compared (count per fraction,
porosity, size-distribution moments, largest overlap, spheres inside the volume).  The bond
generator is deterministic: the bond list is compared pair by pair.  Examples 4 and 5
(5,371 and 11,114 spheres, 10-15 s each) and Example 6 run in the normal suite too, next to
a 426-sphere packing of the same scene against cmusen's."""

from __future__ import annotations

import gzip
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import data_path

DATA = data_path("real-outputs/musen/generators")
SCENE = data_path("real-inputs/musen/PackingGeneration.mdem")
STATS = json.loads((DATA / "cmusen_packing_statistics.json").read_text())
R_CYL, HALF_H = 0.02, 0.025           # the scene's generation volume: a cylinder


def _cli(args, cwd):
    return subprocess.run([sys.executable, "-m", "fibrelmp.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600)


def _statistics(path: Path, diameters) -> dict:
    """What cmusen_packing_statistics.json holds, computed the same way (numpy, k-d tree)."""
    from scipy.spatial import cKDTree

    from fibrelmp.translate.musen.mdem.model import read_scene

    s = read_scene(path).spheres
    x, r = s.position, s.radius
    d = 2 * r
    pairs = cKDTree(x).query_pairs(2 * r.max(), output_type="ndarray")
    ov = r[pairs[:, 0]] + r[pairs[:, 1]] - np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    rho = np.hypot(x[:, 0], x[:, 1])
    return {"count": int(s.count),
            "per_diameter": {f"{dd:g}": int(np.isclose(d, dd).sum()) for dd in diameters},
            "porosity": float(1 - (np.pi / 6 * d ** 3).sum() / (np.pi * R_CYL ** 2 * 2 * HALF_H)),
            "psd_moments_number": {"mean_d": d.mean(), "mean_d2": (d ** 2).mean(), "mean_d3": (d ** 3).mean()},
            "max_overlap_pp": float(max(ov.max(), 0.0)),
            "max_overlap_pw_cylinder": float(max((rho + r - R_CYL).max(), (np.abs(x[:, 2]) + r - HALF_H).max())),
            "velocity": s.velocity.mean(axis=0).tolist()}


def _compare(mine: dict, cmusen: dict, target_overlap: float) -> None:
    assert mine["count"] == cmusen["count"]
    assert mine["per_diameter"] == cmusen["per_diameter"]
    assert mine["porosity"] == pytest.approx(cmusen["porosity"], rel=1e-12)
    for k, v in cmusen["psd_moments_number"].items():
        assert mine["psd_moments_number"][k] == pytest.approx(v, rel=1e-12)
    assert mine["max_overlap_pp"] <= target_overlap
    # inside the volume: the facetted cylinder lies inside the ideal one (cmusen's spheres
    # poke out of the caps by its wall-overlap tolerance, ~2e-9 m)
    assert mine["max_overlap_pw_cylinder"] <= max(cmusen["max_overlap_pw_cylinder"], 0.0) + target_overlap
    np.testing.assert_allclose(mine["velocity"], cmusen["velocity"], atol=1e-12)


def _run_script(tmp_path: Path, script: str) -> Path:
    shutil.copy(SCENE, tmp_path / "PackingGeneration.mdem")
    (tmp_path / "job.txt").write_text(script)
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 0, done.stderr
    return tmp_path


SMALL = """JOB
SOURCE_FILE          ./PackingGeneration.mdem
RESULT_FILE          ./small_packing.mdem
COMPONENT            PACKAGE_GENERATOR
PACK_GEN_POROSITY    1 0.96
PACK_GEN_VELOCITY    1 0 0 -0.1
"""


def test_small_packing_has_cmusens_statistics(tmp_path):
    folder = _run_script(tmp_path, SMALL)
    mine = _statistics(folder / "small_packing.mdem", [0.002, 0.0022, 0.0024, 0.0025])
    _compare(mine, STATS["small_packing"], 1e-7)


@pytest.mark.tier2    # long reference comparison: second tier (pytest -m tier2; .ci/run runs it)
@pytest.mark.parametrize("case, script, diameters", [
    ("example4", "job_example4.txt", [0.002, 0.0022, 0.0024, 0.0025]),
    ("example5_corrected", "job_example5_corrected.txt", [0.0015, 0.0018, 0.0019, 0.0021]),
])
def test_examples_4_and_5_have_cmusens_statistics(tmp_path, case, script, diameters):
    text = (DATA / script).read_text().split("JOB\nSOURCE_FILE          ./Result")[0]   # no export
    folder = _run_script(tmp_path, text)
    mine = _statistics(folder / "Result_PackingGeneration.mdem", diameters)
    _compare(mine, STATS[case], 1e-7)


def _cmusen_packing(tmp_path: Path) -> Path:
    """cmusen's exported small packing (17 digits), unpacked."""
    text = tmp_path / "small_packing.txt"
    text.write_bytes(gzip.decompress((DATA / "small_packing.txt.gz").read_bytes()))
    return text


def test_cmusen_export_of_a_packing_converts_back(tmp_path):
    """The analysis-volume line `38` has 20 numbers before its motion (was read as 21)."""
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.text_export import volumes

    text = _cmusen_packing(tmp_path)
    done = _cli(["convert", text.name, "-o", "re.mdem"], tmp_path)
    assert done.returncode == 0, done.stderr
    with MdemFile(tmp_path / "re.mdem") as mdem:
        (vol,) = volumes(mdem.info)
        assert (vol["name"], vol["shape"], len(vol["triangles"])) == ("GenerationDomain", 2, 256)
        assert vol["sizes"] == [0, 0, 0.05, 0.02, 0] and vol["scaling"] == 1
        assert vol["rotation"] == (1, 0, 0, 0, 1, 0, 0, 0, 1) and vol["motion_type"] == 0
    mine = _statistics(tmp_path / "re.mdem", [0.002, 0.0022, 0.0024, 0.0025])
    assert mine["count"] == 426 and mine["max_overlap_pp"] == STATS["small_packing"]["max_overlap_pp"]


BONDS = """JOB
SOURCE_FILE          ./small_packing.txt
RESULT_FILE          ./small_packing.mdem
COMPONENT            IMPORT_FROM_TEXT
JOB
SOURCE_FILE          ./small_packing.mdem
RESULT_FILE          ./small_bonds.mdem
COMPONENT            BONDS_GENERATOR
BOND_GEN_MATERIAL    1 Clay
BOND_GEN_MINDIST     1 0
BOND_GEN_MAXDIST     1 1e-3
BOND_GEN_DIAMETER    1 1.5e-3
"""


def test_bonds_generator_gives_cmusens_bonds(tmp_path):
    from fibrelmp.translate.musen.generators.scene import read_generator_scene
    from fibrelmp.translate.musen.mdem.objects import SOLID_BOND

    _cmusen_packing(tmp_path)
    (tmp_path / "job.txt").write_text(BONDS)
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 0, done.stderr
    objs = read_generator_scene(tmp_path / "small_bonds.mdem").objects()
    b = objs.types == SOLID_BOND
    mine = {(min(i, j), max(i, j)): (d, length, c) for i, j, d, length, c in
            zip(objs.left[b].tolist(), objs.right[b].tolist(), objs.diameter[b].tolist(),
                objs.length0[b].tolist(), np.array(objs.compound, dtype=object)[b])}
    rows = [line.split(",") for line in (DATA / "cmusen_small_bonds.csv").read_text().splitlines()
            if not line.startswith("#")]
    theirs = {(min(int(i), int(j)), max(int(i), int(j))): (float(d), float(length), c)
              for i, j, d, length, c in rows}
    assert len(theirs) == 171 and set(mine) == set(theirs)
    for pair, (d, length, c) in theirs.items():
        assert mine[pair][0] == d and mine[pair][2] == c
        # same operations; a pair cmusen lists the other way round may differ in the last bit
        assert mine[pair][1] == pytest.approx(length, rel=4e-16)


@pytest.mark.parametrize("line, message", [
    ("MIXTURE_PROPERTY 1 1 CG9ZE5YQBM 1.5e-3 0.4", "needs 6 values"),
    ("PACK_GEN_POROSITY x 0.5", "generator's number"),
    ("BOND_GEN_OVERLAY 1 maybe", "expected 1/0"),
])
def test_generator_keys_are_checked(tmp_path, line, message):
    shutil.copy(SCENE, tmp_path / "PackingGeneration.mdem")
    (tmp_path / "job.txt").write_text(SMALL + line + "\n")
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert f"job.txt:7: {line.split()[0]}" in done.stderr and message in done.stderr
    assert not (tmp_path / "small_packing.mdem").exists()


def test_a_mixture_not_adding_up_to_one_is_refused(tmp_path):
    shutil.copy(SCENE, tmp_path / "PackingGeneration.mdem")
    (tmp_path / "job.txt").write_text(SMALL + "MIXTURE_PROPERTY 1 1 CG9ZE5YQBM 2e-3 2e-3 0.5\n")
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 2 and "add up to 1.2" in done.stderr, done.stderr
    assert not (tmp_path / "small_packing.mdem").exists()


def test_results_analyzer_is_refused_by_name(tmp_path):
    (tmp_path / "job.txt").write_text("JOB\nCOMPONENT RESULTS_ANALYZER\n")
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 2 and "job.txt:2: COMPONENT: RESULTS_ANALYZER is not supported" in done.stderr


def test_example6_runs_unchanged_and_falls_as_cmusen(tmp_path):
    """MUSEN's Example 6 as shipped (packing, stray line, simulation; ~30 s).  The packings
    differ (random), so the comparison is the free fall of the whole packing (no walls): the
    mass-weighted mean vz at every cmusen time point: both save MUSEN's leapfrog velocity,
    -g t - g dt/2 (docs/musen.md)."""
    from fibrelmp.translate.musen.mdem import timepoints
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.model import read_scene

    (tmp_path / "InitScenes").mkdir()
    (tmp_path / "Scripts").mkdir()
    shutil.copy(SCENE, tmp_path / "InitScenes" / "PackingGeneration.mdem")
    script = tmp_path / "Scripts" / "Example 6 - Multiple jobs.txt"
    script.write_bytes((DATA / "example6_as_shipped.txt").read_bytes())
    done = _cli(["run", script.name], script.parent)
    assert done.returncode == 0, done.stderr
    assert "skipped (not a keyword" in done.stderr
    mass = read_scene(script.parent / "Result_PackingGeneration.mdem").spheres.mass
    ref = STATS["example6_simulation"]
    with MdemFile(script.parent / "Result_Simulation.mdem") as mdem:
        points = list(mdem.time_points())
    times = np.array([p[0] for p in points])
    np.testing.assert_allclose(times, ref["times"], rtol=1e-12, atol=1e-18)
    mean_vz = np.array([(mass * v[m != 0][:, timepoints.columns("vel")][:, 2]).sum() / mass.sum()
                        for _, v, m in points])
    scale = 9.81 * 1e-4
    np.testing.assert_allclose(mean_vz, ref["mass_mean_vz"], atol=1e-6 * scale, rtol=0)


@pytest.mark.skipif(not os.environ.get("FIBRELMP_CMUSEN"), reason="set FIBRELMP_CMUSEN to the real cmusen")
def test_with_cmusen_a_new_packing_gets_cmusens_bonds(tmp_path):
    """cmusen makes a new random packing and its bonds (job_generators.txt); fibrelmp's bonds
    generator on that packing gives the same bonds, and the packing has the stored statistics."""
    from fibrelmp.translate.musen.generators import bonds
    from fibrelmp.translate.musen.generators.scene import read_generator_scene
    from fibrelmp.translate.musen.mdem.objects import SOLID_BOND

    shutil.copy(SCENE, tmp_path / "PackingGeneration.mdem")
    shutil.copy(DATA / "job_generators.txt", tmp_path / "job.txt")
    done = subprocess.run([os.environ["FIBRELMP_CMUSEN"], "-t=1", "-s=job.txt"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert "Error" not in done.stdout, done.stdout
    cmusen = _statistics(tmp_path / "small_packing.mdem", [0.002, 0.0022, 0.0024, 0.0025])
    _compare(cmusen, STATS["small_packing"], 1e-7)
    scene = read_generator_scene(tmp_path / "small_packing.mdem")
    bonds.generate_bonds(scene, [bonds.BondClass(compound="CG9ZE5YQBM", max_distance=1e-3, diameter=1.5e-3)])

    def listed(objs):
        b = objs.types == SOLID_BOND
        return {(min(i, j), max(i, j)): (d, length) for i, j, d, length in
                zip(objs.left[b].tolist(), objs.right[b].tolist(), objs.diameter[b].tolist(),
                    objs.length0[b].tolist())}
    mine, theirs = listed(scene.objects()), listed(read_generator_scene(tmp_path / "small_bonds.mdem").objects())
    assert set(mine) == set(theirs) and len(theirs) > 50
    for pair, (d, length) in theirs.items():
        assert mine[pair][0] == d and mine[pair][1] == pytest.approx(length, rel=4e-16)


def test_spheres_too_large_for_the_volume_are_refused(tmp_path):
    """cmusen's IsDataCorrect: largest contact diameter above 0.95 of the volume's
    MaxInscribedDiameter (for this cylinder min(r, h) = 0.02 m)."""
    shutil.copy(SCENE, tmp_path / "PackingGeneration.mdem")
    (tmp_path / "job.txt").write_text(SMALL + "MIXTURE_PROPERTY 1 4 BWLPWOW76F 0.0191 0.0191 0.2\n")
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 2 and "job.txt:4: package generator 1 (Generator): particle diameter " \
        "(0.0191 m) is too large" in done.stderr, done.stderr


def test_only_a_lone_stray_mark_is_skipped(tmp_path):
    """Example 6's `´` line is skipped with a warning (cmusen: unknown key); other
    unknown lines stay errors."""
    from fibrelmp.errors import InputError
    from fibrelmp.translate.musen.script_parse import read_script

    job = read_script(DATA / "example6_as_shipped.txt")[0]
    assert job.component == "PACKAGE_GENERATOR" and "'´' skipped" in job.warnings[0][1]
    path = tmp_path / "job.txt"
    path.write_text((DATA / "example6_as_shipped.txt").read_text(encoding="utf-8").replace("´", "´ x"),
                    encoding="utf-8")
    with pytest.raises(InputError, match="unknown cmusen keyword"):
        read_script(path)


BOUNCE = data_path("real-outputs/musen/bounce/bounce_result.mdem")


@pytest.mark.parametrize("time, reference", [(0.0006, "snap_bounce_saved.mdem"),
                                             (0.00111, "snap_bounce_between.mdem")])
def test_snapshot_is_cmusens(tmp_path, time, reference):
    """SNAPSHOT_GENERATOR of cmusen's bounce result at a saved time and between two: the
    objects, every value and every field flag of cmusen's snapshot (job_snapshot.txt)."""
    from fibrelmp.translate.musen.mdem.document import MdemFile

    shutil.copy(BOUNCE, tmp_path / "bounce_result.mdem")
    (tmp_path / "job.txt").write_text("JOB\nSOURCE_FILE ./bounce_result.mdem\nRESULT_FILE ./snap.mdem\n"
                                      f"COMPONENT SNAPSHOT_GENERATOR\nSNAPSHOT_TIME {time!r}\n")
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 0, done.stderr
    with MdemFile(tmp_path / "snap.mdem") as mine, MdemFile(DATA / reference) as theirs:
        assert [p.SerializeToString() for p in mine.info.particles] == \
            [p.SerializeToString() for p in theirs.info.particles]
        (t1, v1, m1), = list(mine.time_points())
        (t2, v2, m2), = list(theirs.time_points())
        assert t1 == t2 == 0.0 and np.array_equal(v1, v2) and np.array_equal(m1, m2)


def test_snapshot_after_the_last_saved_time_is_refused(tmp_path):
    shutil.copy(BOUNCE, tmp_path / "bounce_result.mdem")
    (tmp_path / "job.txt").write_text("JOB\nSOURCE_FILE ./bounce_result.mdem\nRESULT_FILE ./snap.mdem\n"
                                      "COMPONENT SNAPSHOT_GENERATOR\nSNAPSHOT_TIME 1\n")
    done = _cli(["run", "job.txt"], tmp_path)
    assert done.returncode == 2 and "job.txt:5: SNAPSHOT_TIME 1 is outside the saved times" in done.stderr
    assert not (tmp_path / "snap.mdem").exists()


@pytest.mark.skipif(not os.environ.get("FIBRELMP_CMUSEN"), reason="set FIBRELMP_CMUSEN to the real cmusen")
def test_with_cmusen_a_bonded_snapshot_is_cmusens(tmp_path):
    """cmusen: packing + bonds (job_generators.txt), 3e-5 s of simulation and a snapshot
    between saves (job_snapshot.txt); fibrelmp's snapshot of that result equals cmusen's."""
    from types import SimpleNamespace

    from fibrelmp.translate.musen.generators.snapshot import snapshot
    from fibrelmp.translate.musen.mdem.document import MdemFile

    shutil.copy(SCENE, tmp_path / "PackingGeneration.mdem")
    shutil.copy(BOUNCE, tmp_path / "bounce_result.mdem")
    for script in ("job_generators.txt", "job_snapshot.txt"):
        shutil.copy(DATA / script, tmp_path / script)
        done = subprocess.run([os.environ["FIBRELMP_CMUSEN"], "-t=1", f"-s={script}"], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        assert "Error" not in done.stdout, done.stdout
    scene = snapshot(tmp_path / "bonded_result.mdem",
                     SimpleNamespace(path=tmp_path / "job.txt", where=lambda key: 1, snapshot_time=1.3e-5))
    with MdemFile(tmp_path / "snap_bonded_between.mdem") as theirs:
        (_, values, masks), = list(theirs.time_points())
        assert [p.SerializeToString() for p in theirs.info.particles] == \
            [p.SerializeToString() for p in scene.info.particles]
    assert np.array_equal(values, scene.values) and np.array_equal(masks, scene.masks)
