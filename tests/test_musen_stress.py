"""MUSEN's stress tensor (36) and principal stresses (42) in fibrelmp's MUSEN results, against
the real cmusen's 17-digit exports stored in tests/data (each case's README gives how cmusen
1.74.2 made it): every sphere at every saved time.

- models/pp_hertz: two spheres in an oblique Hertz impact (contacts only): within 4 ulp of
  the scale (the sum of two terms per sphere, in MUSEN's order).
- stop_criterion: five spheres joined by four bonds, two of which break; a bond broken since
  the previous save still counts there with the force it broke with (MUSEN marks its object
  inactive only at that save): bit for bit.
- force_walls press, rot and const: three spheres between a plate and a force-driven (in rot
  also rotating; in const constant-force) plate: sphere-wall contacts (fix musen/wall/mesh's
  contact points and forces) and sphere-sphere ones: bit for bit.

- several_bond_models: three spheres, two bonds under ModelSBKelvin then ModelSBElastic (one
  breaks): within 8 ulp of the scale (MUSEN's stress takes the last model's TotalForce, which
  bond_style musen/elastic's compute bond/local reports).

In the bit-for-bit cases every other field of the export equals cmusen's too (the bonds' and
walls' forces are the previous evaluation's, as cmusen saves them).

Independently of cmusen, ``granular_run.stress.stress_tensors`` is checked against the formula
written out per pair (numpy loops) and ``schedule.with_presaves`` against the steps it must
dump at.
"""

from __future__ import annotations

import gzip
import math
import shutil
import subprocess
import sys

import numpy as np
import pytest

from fibrelmp.granular_run.stress import principal_stresses, stress_tensors
from fibrelmp.translate.granular.schedule import with_presaves
from fibrelmp.translate.musen.scene import read_time_points

from .conftest import data_path, styles_or_skip

MUSEN = data_path("real-outputs", "musen")


def _run(case, job: str, tmp_path):
    styles_or_skip()
    for f in case.iterdir():
        if f.suffix == ".txt" and not f.name.startswith("cmusen"):
            shutil.copy(f, tmp_path)
    done = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "-q", "run", job], cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


@pytest.mark.parametrize("case, job, ours, theirs, ulps", [
    (MUSEN / "models" / "pp_hertz", "job_hertz.txt", "hertz_result_prec17.txt",
     "cmusen_hertz_result_prec17.txt", 4),
    (MUSEN / "stop_criterion", "job_stop.txt", "stop_result_prec17.txt",
     "cmusen_stop_result_prec17.txt", 0),
    (MUSEN / "force_walls", "job_press.txt", "press_result_prec17.txt",
     "cmusen_press_result_prec17.txt", 0),
    (MUSEN / "force_walls", "job_rot.txt", "rot_result_prec17.txt",
     "cmusen_rot_result_prec17.txt", 0),
    (MUSEN / "force_walls", "job_const.txt", "const_result_prec17.txt",
     "cmusen_const_result_prec17.txt", 0),
    (MUSEN / "several_bond_models", "job_kelvin_elastic.txt", "ke_result_prec17.txt",
     "cmusen_ke_result_prec17.txt.gz", 8),
])
def test_stress_tensor_is_cmusens(tmp_path, case, job, ours, theirs, ulps):
    done = _run(case, job, tmp_path)
    assert "musen-no-stress" not in done.stderr
    if theirs.endswith(".gz"):
        (tmp_path / "cmusen.txt").write_bytes(gzip.decompress((case / theirs).read_bytes()))
        case, theirs = tmp_path, "cmusen.txt"
    real = read_time_points(case / theirs, tags=(36, 42))
    mine = read_time_points(tmp_path / ours, tags=(36, 42))
    assert mine.times.tolist() == real.times.tolist()
    spheres = real.types == 1
    for tag in (36, 42):
        r, o = real.fields[tag][:, spheres], mine.fields[tag][:, spheres]
        scale = np.abs(r).max()
        assert scale > 1e3                                  # the cases do load their spheres
        assert np.abs(o - r).max() <= ulps * np.spacing(scale), tag
    # the zero tensor of the first save (no evaluation before it) is written too
    assert not np.any(mine.fields[36][0][spheres])
    if ulps == 0:
        # and every other field of every object too: the bonds' force, overlap and torque (a
        # bond broken since the previous save as it broke) and the walls' forces are the
        # previous evaluation's, as cmusen saves them
        real, mine = read_time_points(case / theirs), read_time_points(tmp_path / ours)
        assert set(real.fields) == set(mine.fields)
        for tag in real.fields:
            assert np.array_equal(real.fields[tag], mine.fields[tag], equal_nan=True), tag


def test_stress_formula_per_pair():
    rng = np.random.default_rng(3)
    radius = rng.uniform(0.5, 1.5, 6)
    rows = np.array([0, 2, 3, 4, 5])                    # sphere 1 is not in the frame
    pos = rng.normal(size=(5, 3)) * 3
    r1, r2 = np.array([0, 2, 1, 3]), np.array([2, 3, 4, 5])
    force = rng.normal(size=(4, 3))
    got = stress_tensors(rows, pos, radius, [(r1, r2, force)])
    want = np.zeros((5, 9))
    where = {r: k for k, r in enumerate(rows)}
    for a, b, f in zip(r1, r2, force):
        if a not in where or b not in where:
            continue                                    # a pair with a sphere not in the frame
        xa, xb = pos[where[a]], pos[where[b]]
        for me, other, fm in ((a, xb, f), (b, xa, -f)):
            x = pos[where[me]]
            arm = (other - x) / np.linalg.norm(other - x) * radius[me]
            volume = math.pi * (2 * radius[me]) ** 3 / 6
            want[where[me]] += np.outer(arm, fm).ravel() / volume
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13 * np.abs(want).max())
    # principal stresses of a symmetric tensor are its eigenvalues (MUSEN's closed form)
    sym = got.reshape(-1, 3, 3)
    sym = 0.5 * (sym + sym.transpose(0, 2, 1))
    p = principal_stresses(sym.reshape(-1, 9))
    np.testing.assert_allclose(np.sort(p, axis=1), np.linalg.eigvalsh(sym), rtol=1e-9,
                               atol=1e-9 * np.abs(sym).max())


def test_presave_one_step_before_every_frame():
    acts = [("run0",), ("frame", 0), ("predict",), ("run", 5, False), ("frame", 5),
            ("loop", "fl_loop1", 3), ("run", 2, False), ("run", 3, False), ("frame", None),
            ("end", "fl_loop1"), ("run", 1, True), ("delete", 21, [0]), ("frame", 21)]
    out = with_presaves(acts)
    assert out == [("run0",), ("presave",), ("frame", 0), ("predict",), ("run", 4, False),
                   ("presave",), ("run", 1, False), ("frame", 5), ("loop", "fl_loop1", 3),
                   ("run", 2, False), ("run", 2, False), ("presave",), ("run", 1, False),
                   ("frame", None), ("end", "fl_loop1"), ("presave",), ("run", 1, True),
                   ("delete", 21, [0]), ("frame", 21)]
    # the steps: a presave is always followed by exactly one step before its frame
    for k, act in enumerate(out):
        if act == ("presave",) and k > 1:
            assert out[k + 1][:2] == ("run", 1)
    # a one-step run after a deletion: the presave comes before the deletion (delete_atoms
    # drops the ghost atoms until the run's set-up, and a local dump would miss their pairs)
    acts = [("run0",), ("frame", 0), ("run", 20, False), ("delete", 20, [1]), ("run", 1, True),
            ("frame", 21)]
    assert with_presaves(acts) == [("run0",), ("presave",), ("frame", 0), ("run", 20, False),
                                   ("presave",), ("delete", 20, [1]), ("run", 1, True), ("frame", 21)]


@pytest.mark.parametrize("case, job, why, result", [
    ("variable_time_step", "job_vardt.txt", "variable time step", "vardt_result_prec17.txt"),
    # MUSEN's stress takes the last PP model's force alone, fibrelmp's contacts their sum
    # (measured with them: 1.5 x the scale off cmusen's)
    ("several_models", "job_hm_le.txt", "several particle-particle models", "hm_le_result_prec17.txt"),
])
def test_no_stress_says_why(tmp_path, case, job, why, result):
    """A job fibrelmp does not compute the stress for says so (warning musen-no-stress) and
    leaves 36/42 out, as before."""
    done = _run(MUSEN / case, job, tmp_path)
    assert "musen-no-stress" in done.stderr and why in done.stderr
    fields = read_time_points(tmp_path / result).fields
    assert 12 in fields and 36 not in fields and 42 not in fields


def test_principal_stresses_c_and_python_agree(monkeypatch):
    """The C helper (numtext) and the Python fallback give the same bits (both are MUSEN's
    closed form; cmusen's export of fibrelmp's agglomerate result equals them:
    tests/test_mdem_cmusen.py), zero and degenerate tensors included."""
    from fibrelmp.numtext import fast

    if fast.library() is None:
        pytest.skip("no C helper here")
    rng = np.random.default_rng(5)
    s = rng.normal(size=(5000, 9)) * 10.0 ** rng.uniform(-3, 8, (5000, 1))
    s[::9] = 0.0
    s[1] = [1, 0, 0, 0, 1, 0, 0, 0, 1]                  # three equal principal stresses
    s[2] = [2, 1, 0, 1, 2, 0, 0, 0, 3]
    c = principal_stresses(s)
    monkeypatch.setattr(fast, "principal_stresses", lambda tensors: None)
    p = principal_stresses(s)
    assert c.tobytes() == p.tobytes()
    assert not c[::9].any() and np.isfinite(c).all()


def test_resume_cuts_the_presave_dumps_back(tmp_path, monkeypatch):
    """A run that died after its checkpoint may have appended presave blocks past it: a
    resumed run cuts stress_contacts.dump and stress_walls.dump back to the checkpoint (as
    every dump the script appends to) and writes the uninterrupted run's result."""
    from fibrelmp import python_api

    from .musen_model_checks import run_to_first_checkpoint

    case = MUSEN / "force_walls"
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    _run(case, "job_press.txt", whole)
    for name in ("job_press.txt", "press_scene.txt"):
        shutil.copy(case / name, cut)
    run_to_first_checkpoint(monkeypatch, cut / "job_press.txt", cut / "work", 2290)
    for name in ("stress_contacts.dump", "stress_walls.dump"):    # as a crashed run leaves them:
        path = cut / "work" / "job2" / name                         # one more block, complete
        text = path.read_text()
        path.write_text(text + text[text.rindex("ITEM: TIMESTEP"):])
    python_api.run(cut / "job_press.txt", work=cut / "work", resume=True)
    assert (cut / "press_result_prec17.txt").read_bytes() == (whole / "press_result_prec17.txt").read_bytes()
