"""ModelPPHertz and ModelPPSimpleViscoElastic (translate/granular/models/pp_hertz.py,
pp_simple_viscoelastic.py; pair_style musen/pp, musen_pp_hertz.cpp,
musen_pp_simple_viscoelastic.cpp):

* against the real cmusen: an oblique, spinning impact of two glass spheres each
  (tests/data/real-outputs/musen/models/pp_hertz/, pp_simple_viscoelastic/ README.md);
* single contacts against MUSEN's CalculatePP re-written here with numpy (Hertz: undamped
  -2/3 Kn overlap, tangential force Kt vt dt capped at mu |Fn|; simple viscoelastic:
  -Kn overlap + mu vn, nothing tangential);
* restart files keep musen/pp's first law; hertz cannot share the style with another law.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp._lammps import new_lammps
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_reference_is_cmusens_output,
                                 check_refused_without_styles, check_result_is_cmusens, model_job,
                                 needs_cmusen, styles_or_skip)

from .test_style_musen_pair import check_restart_round_trip, persistent_lammps

HERTZ = data_path("real-outputs/musen/models/pp_hertz")
SVE = data_path("real-outputs/musen/models/pp_simple_viscoelastic")
SVE_PARAMS = "NORMAL_FORCE_COEFF 2000 NORMAL_DAMPING_PARAMETER 0.02"


def _compare(tmp_path: Path, data: Path, prefix: str, params: str) -> None:
    job = model_job(tmp_path, data, prefix, params)
    python_api.run(job, work=tmp_path / "work")
    # 1e-6 of each quantity's scale is the project's bar; measured: 0 (hertz), <= 3e-16 (sve)
    _, theirs = check_result_is_cmusens(tmp_path / f"{prefix}_result_prec17.txt",
                                        data / f"cmusen_{prefix}_result_prec17.txt",
                                        dict.fromkeys((COORD, VEL, ANGVEL)), rel=1e-12)
    # the impact happened: the spheres' velocities changed clearly
    v0, v1 = theirs.fields[VEL][0], theirs.fields[VEL][-1]
    assert np.linalg.norm(v1 - v0, axis=1).min() > 0.05


def test_hertz_impact_is_cmusens(tmp_path):
    styles_or_skip()
    _compare(tmp_path, HERTZ, "hertz", "MODEL_PP             ModelPPHertz")
    assert "pair_style      musen/pp hertz" in (tmp_path / "work/job2/in.lammps").read_text()


def test_hertz_differs_from_hertz_mindlin_in_cmusens_output():
    """What the case shows: Hertz-Mindlin's (damped, e = 0.7) rebound would be slower; cmusen's
    Hertz keeps the normal relative speed (no normal damping)."""
    theirs = read_time_points(HERTZ / "cmusen_hertz_result_prec17.txt")
    x, v = theirs.fields[COORD], theirs.fields[VEL]
    n0 = (x[0, 1] - x[0, 0]) / np.linalg.norm(x[0, 1] - x[0, 0])
    n1 = (x[-1, 1] - x[-1, 0]) / np.linalg.norm(x[-1, 1] - x[-1, 0])
    before = np.dot(v[0, 1] - v[0, 0], n0)
    after = np.dot(v[-1, 1] - v[-1, 0], n1)
    assert before < 0 < after
    assert after / -before > 0.9        # e = 0.7 with damping; friction takes only a little


def test_simple_viscoelastic_impact_is_cmusens(tmp_path):
    styles_or_skip()
    _compare(tmp_path, SVE, "sve", SVE_PARAMS)
    text = (tmp_path / "work/job2/in.lammps").read_text()
    assert "pair_style      musen/pp simple/viscoelastic 2000.0 0.02" in text
    # nothing tangential: the spins are untouched (cmusen's too)
    theirs = read_time_points(SVE / "cmusen_sve_result_prec17.txt")
    assert np.array_equal(theirs.fields[ANGVEL][-1], theirs.fields[ANGVEL][0])


def test_simple_viscoelastic_contact_time(tmp_path):
    m_eff = 2500.0 * 4.0 / 3.0 * np.pi * 1e-3 ** 3 / 2
    lines = python_api.check(model_job(tmp_path, SVE, "sve", SVE_PARAMS)).lines
    line = next(t for t in lines if t.startswith("contact time"))
    assert line.startswith(f"contact time {np.pi * np.sqrt(m_eff / 2000.0):.3g} (simple "
                           "viscoelastic, Glass-Glass"), line


@pytest.mark.parametrize("params", ["NORMAL_FORCE_COEFF 0 NORMAL_DAMPING_PARAMETER 0.02",
                                    "NORMAL_FORCE_COEFF 2000 NORMAL_DAMPING_PARAMETER -1"])
def test_simple_viscoelastic_bad_parameters(tmp_path, params):
    styles_or_skip()
    job = model_job(tmp_path, SVE, "sve", SVE_PARAMS, params)
    with pytest.raises(InputError, match="ModelPPSimpleViscoElastic parameter") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:11: ")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(model_job(tmp_path, SVE, "sve", SVE_PARAMS),
                                 "ModelPPSimpleViscoElastic", 10, tmp_path / "sve_init.mdem")
    job = model_job(tmp_path / "h", HERTZ, "hertz", "") if (tmp_path / "h").mkdir() is None else None
    check_refused_without_styles(job, "ModelPPHertz", 10, tmp_path / "h/hertz_init.mdem")


@needs_cmusen
@pytest.mark.parametrize("data,prefix", [(HERTZ, "hertz"), (SVE, "sve")])
def test_reference_is_cmusens_output(tmp_path, data, prefix):
    check_reference_is_cmusens_output(tmp_path, data, prefix)


# ---------------------------------------------------------------- single contacts, numpy

E_STAR, G_STAR, REST, MU, MU_R = 2.6e10, 5.7e9, 0.7, 0.3, 0.05
R, RHO, DT = 1e-3, 2500.0, 1e-8


def _single_contact(style: str, overlap: float, v2: tuple, w1=(0.0, 0.0, 0.0)):
    """Force on sphere 1 (at 0) and torque on it from LAMMPS's first force evaluation (run 0:
    a new contact, stored tangential state zero, one step's vt dt), sphere 2 at +x."""
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {styles_or_skip()}", "units si", "atom_style sphere",
                  "boundary f f f", "comm_modify vel yes", "atom_modify map array",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  "create_atoms 1 single 0 0 0", f"create_atoms 1 single {2 * R - overlap!r} 0 0",
                  f"set type 1 diameter {2 * R!r} density {RHO!r}",
                  f"set atom 2 vx {v2[0]!r} vy {v2[1]!r} vz {v2[2]!r}",
                  f"set atom 1 omega {w1[0]!r} {w1[1]!r} {w1[2]!r}",
                  style, f"pair_coeff 1 1 {E_STAR!r} {G_STAR!r} {REST!r} {MU!r} {MU_R!r}",
                  f"timestep {DT!r}", "fix 1 all nve/sphere", "run 0 post no"]:
            lmp.command(c)
        f = np.array(lmp.gather_atoms("f", 1, 3)).reshape(-1, 3)
        t = np.array(lmp.gather_atoms("torque", 1, 3)).reshape(-1, 3)
        return f[0], t[0], f[1]
    finally:
        lmp.close()


def _hertz_numpy(overlap, v2, w1):
    """ModelPPHertz.cpp for a new contact, n = +x, src sphere 1 at rest (angular w1)."""
    n = np.array([1.0, 0.0, 0.0])
    d = 2 * R - overlap
    overlap = 2 * R - d        # the overlap the positions hold (rounded)
    rc1 = n * d * 0.5
    rel = np.array(v2) + np.cross(np.zeros(3), -rc1) - np.cross(w1, rc1)
    vt = rel - np.dot(rel, n) * n
    a = math.sqrt(R / 2 * overlap)
    fn = -2.0 / 3.0 * overlap * 2 * E_STAR * a
    ft = vt * DT * 8 * G_STAR * a
    if np.linalg.norm(ft) > MU * abs(fn):
        ft *= MU * abs(fn) / np.linalg.norm(ft)
    w1 = np.array(w1)
    roll = w1 * (-MU_R * abs(fn) * R / np.linalg.norm(w1)) if np.any(w1) else np.zeros(3)
    return n * fn + ft, np.cross(n, ft) * R + roll


@pytest.mark.parametrize("overlap,v2,w1", [(1e-6, (-0.1, 0.2, 0.0), (0.0, 0.0, 0.0)),
                                           (3e-6, (-0.1, 1e-4, 0.0), (0.0, 0.0, 50.0)),
                                           (1e-12, (0.1, 0.0, 0.3), (10.0, 0.0, 0.0))])
def test_hertz_single_contact_is_musens_law(overlap, v2, w1):
    f1, t1, f2 = _single_contact("pair_style musen/pp hertz", overlap, v2, w1)
    f_ref, t_ref = _hertz_numpy(overlap, v2, w1)
    scale = np.abs(f_ref).max()
    np.testing.assert_allclose(f1, f_ref, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f2, -f_ref, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(t1, t_ref, rtol=0, atol=1e-12 * max(np.abs(t_ref).max(), 1e-30))
    # repulsive, and no damping: the same force approaching or separating
    assert f1[0] < 0
    f_sep, _, _ = _single_contact("pair_style musen/pp hertz", overlap, (-v2[0], v2[1], v2[2]), w1)
    assert f_sep[0] == f1[0]


def test_hertz_force_vanishes_at_the_contact_edge():
    forces = [_single_contact("pair_style musen/pp hertz", d, (0.0, 0.0, 0.0))[0][0]
              for d in (1e-9, 1e-12, 1e-15)]
    # |Fn| ~ overlap^1.5: a thousandth of the overlap, 3.16e-5 of the force
    assert forces[0] < forces[1] < forces[2] < 0
    assert forces[1] / forces[0] == pytest.approx(1e-3 ** 1.5, rel=1e-6)


@pytest.mark.parametrize("overlap,vx", [(1e-6, -0.1), (1e-6, 0.1), (1e-12, 0.3)])
def test_simple_viscoelastic_single_contact_is_musens_law(overlap, vx):
    kn, mu = 2000.0, 0.02
    f1, t1, _ = _single_contact(f"pair_style musen/pp simple/viscoelastic {kn!r} {mu!r}",
                                overlap, (vx, 0.2, 0.1), (0.0, 30.0, 0.0))
    overlap = 2 * R - (2 * R - overlap)        # the overlap the positions hold (rounded)
    f_ref = np.array([-kn * overlap + mu * vx, 0.0, 0.0])
    np.testing.assert_allclose(f1, f_ref, rtol=1e-14, atol=1e-16)
    assert np.all(t1 == 0.0)


def test_hertz_only_as_the_only_law():
    with pytest.raises(Exception, match="law hertz .* must be the only law"):
        _single_contact("pair_style musen/pp simple/viscoelastic 1 0 then hertz", 1e-6, (0, 0, 0))


@pytest.mark.parametrize("style", ["pair_style musen/pp hertz",
                                   "pair_style musen/pp simple/viscoelastic 3e4 0.01 then "
                                   "hertz/mindlin"])
def test_restart_keeps_the_first_law(tmp_path, style):
    """write_restart mid-contact; a new LAMMPS reading it continues bit for bit."""
    check_restart_round_trip(tmp_path, style)


def test_cost_per_contact_vs_hertz_mindlin(tmp_path):
    """Rough cost of the persistent contacts per law (printed, not asserted)."""
    plugin = styles_or_skip()
    for style in ("pair_style musen/hm", "pair_style musen/pp hertz",
                  "pair_style musen/pp simple/viscoelastic 3e4 0.01", "pair_style musen/pp jkr 1.0",
                  "pair_style musen/pp popov/jkr 0.7"):
        lmp = persistent_lammps(plugin, style=style)
        try:
            start = time.perf_counter()
            lmp.command("run 2000 post no")
            print(f"{style}: {(time.perf_counter() - start) / 2000 * 1e6:.2f} us/step")
        finally:
            lmp.close()


@pytest.mark.parametrize("models", ["MODEL_PP             ModelPPHertz\nMODEL_PP             ModelPPHertzMindlin",
                                    "MODEL_PP             ModelPPHertzMindlin\nMODEL_PP             ModelPPHertz"])
def test_hertz_with_another_pp_model_is_an_input_error(tmp_path, models):
    styles_or_skip()
    job = model_job(tmp_path, HERTZ, "hertz", "MODEL_PP             ModelPPHertz", models)
    with pytest.raises(InputError, match="runs ModelPPHertz only as the only PP model") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:11: ")
