"""ModelPWHertzMindlinLiquid (translate/granular/models/pw_hertz_mindlin_liquid.py, fix
musen/wall/mesh ... law hertz/mindlin/liquid, src/musen_pw_hertz_mindlin_liquid.cpp) against the
real cmusen: spheres arriving on and leaving a wet plate (tests/data/real-outputs/musen/models/
pw_hertz_mindlin_liquid/README.md), and the law on single contacts against MUSEN's
CalculatePW re-written in numpy.  The opt-in test (FIBRELMP_CMUSEN) reruns cmusen."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp._lammps import new_lammps
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_lmp_replay_is_bitwise,
                                 check_reference_is_cmusens_output, check_refused_without_styles,
                                 check_resume_is_bitwise, check_run_is_cmusens, model_job,
                                 needs_cmusen, styles_or_skip)

DATA = data_path("real-outputs/musen/models/pw_hertz_mindlin_liquid")
PARAMS = "MIN_THICKNESS 1e-5 CONTACT_ANGLE 30 SURFACE_TENSION 0.5 DYNAMIC_VISCOSITY 0.5"
SPHERES = [0, 3]                      # rows 1, 2 are the plate's triangles


def _job(tmp_path: Path, params: str = PARAMS) -> Path:
    return model_job(tmp_path, DATA, "pwl", PARAMS, params)


def test_wet_plate_is_cmusens(tmp_path):
    styles_or_skip()
    # 1e-6 of each quantity's scale (measured: bit-identical)
    check_run_is_cmusens(tmp_path, _job(tmp_path), DATA, "pwl",
                         "law hertz/mindlin/liquid 1e-05 30.0 0.5 0.5",
                         {COORD: 1e-3, VEL: 2e-2, ANGVEL: 30.0}, rows=SPHERES)


def test_the_reference_tells_the_bridge_from_hertz_mindlin():
    liq = read_time_points(DATA / "cmusen_pwl_result_prec17.txt")
    hm = read_time_points(DATA / "cmusen_pwl_as_hertz_mindlin_result_prec17.txt")
    v_liq, v_hm = liq.fields[VEL][-1, SPHERES, 2], hm.fields[VEL][-1, SPHERES, 2]
    assert (v_liq > 0).all() and (v_hm - v_liq > 5e-4).all()     # the drag slows both rebounds


# ---------------------------------------------------------------- the law on single contacts

PI = 3.14159265358979323846
TWO_SQRT_5_6 = 1.825741858350553711523232609336
HMIN, THETA, SIGMA, ETA = 1e-5, 30.0, 0.5, 0.5
E_STAR, G_STAR, REST, MU, MU_R = 5.0e8, 1.0e8, 0.5, 0.3, 0.02
R, RHO, DT = 1e-3, 2500.0, 1e-6


def musen_pw_liquid(z, v, w, m, dt):
    """ModelPWHertzMindlinLiquid::CalculatePW of a sphere at height z above the plane z = 0
    (normal +z, contact point below the centre), a new contact: force and torque."""
    n = np.array([0.0, 0.0, 1.0])
    rc = np.array([0.0, 0.0, z])
    rc_len = np.linalg.norm(rc)
    rc_n = rc / rc_len
    h = max(rc_len, HMIN)
    overlap = R - rc_len
    rel = v + np.cross(rc_n, w) * R
    vn = n @ rel
    vt = rel - vn * n
    theta = THETA * PI / 180
    volume = PI / 3.0 * R ** 3
    a_ = -1.1 * volume ** -0.53
    b_ = (-0.34 * math.log(volume) - 0.96) * theta ** 2 - 0.019 * math.log(volume) + 0.48
    c_ = 0.0042 * math.log(volume) + 0.078
    cap = n * PI * R * SIGMA * (math.exp(a_ * h + b_) + c_)
    visc = vn * n * -1 * (6 * PI * ETA * R * R / h)
    ft_liq = vt * (6 * PI * ETA * R * (8.0 / 15.0 * math.log(R / h) + 0.9588))
    moment_liq = np.cross(rc, ft_liq)
    alpha = math.log(REST) / math.sqrt(PI * PI + math.log(REST) ** 2)
    a = math.sqrt(R * overlap)
    kn = 2 * E_STAR * a
    fel = 2 / 3 * overlap * kn * abs(rc_n @ n)
    fdamp = TWO_SQRT_5_6 * alpha * vn * math.sqrt(kn * m)
    kt = 8 * G_STAR * a
    shear = -kt * (vt * dt)
    limit = MU * abs(fel + fdamp)
    if np.linalg.norm(shear) > limit:
        ft_dry = shear * limit / np.linalg.norm(shear)
    else:
        ft_dry = shear + vt * (TWO_SQRT_5_6 * alpha * math.sqrt(kt * m))
    roll = w * (-MU_R * abs(fel) * R / np.linalg.norm(w)) if np.abs(w).max() > 1e-100 else 0 * w
    ft = ft_dry + ft_liq
    return n * (fel + fdamp) + ft + cap + visc, np.cross(n, ft) * -R + roll - moment_liq


def _lammps_force(tmp_path: Path, law: str, z, v, w):
    mesh = tmp_path / "walls.mesh"
    mesh.write_text("musen/wall/mesh 1\nlaws 1\n"
                    f"1 1 {E_STAR!r} {G_STAR!r} {REST!r} {MU!r} {MU_R!r}\n"
                    "geometries 1\ngeometry Plate 0 0 0\ntriangles 2\n"
                    "0 1 -0.005 -0.005 0.0 0.005 -0.005 0.0 0.005 0.005 0.0\n"
                    "0 1 -0.005 -0.005 0.0 0.005 0.005 0.0 -0.005 0.005 0.0\n")
    v, w = (np.asarray(a, float).tolist() for a in (v, w))
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {lammps_styles.plugin().path}", "units si", "atom_style sphere",
                  "boundary f f f", "atom_modify map array",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  f"create_atoms 1 single 0.0001 0.0002 {z!r}",
                  f"set atom 1 diameter {2 * R!r} density {RHO!r}",
                  f"set atom 1 vx {v[0]!r} vy {v[1]!r} vz {v[2]!r}",
                  f"set atom 1 omega {w[0]!r} {w[1]!r} {w[2]!r}",
                  f"timestep {DT!r}", "fix integrate all nve/sphere",
                  f"fix walls all musen/wall/mesh {mesh} law {law}", "run 0 post no"]:
            lmp.command(c)
        f = lmp.numpy.extract_atom("f")[:1].copy()
        t = lmp.numpy.extract_atom("torque")[:1].copy()
        m = float(lmp.numpy.extract_atom("rmass")[0])
    finally:
        lmp.close()
    return f[0], t[0], m


# overlap, velocity, spin; the 3rd slips
CONTACTS = [(1e-6, (0.0, 0.0, -0.02), (0.0, 0.0, 0.0)),
            (3e-6, (0.01, 0.0, 0.01), (0.0, 30.0, 0.0)),
            (1e-9, (0.5, 0.2, 0.0), (0.0, 0.0, 0.0)),
            (2e-7, (0.0, 0.0, 0.0), (5.0, 0.0, 7.0))]


@pytest.mark.parametrize("overlap,v,w", CONTACTS)
def test_single_contact_is_musens_law(tmp_path, overlap, v, w):
    styles_or_skip()
    z = R - overlap
    f, t, m = _lammps_force(tmp_path, f"hertz/mindlin/liquid {HMIN} {THETA} {SIGMA} {ETA}", z, v, w)
    force, torque = musen_pw_liquid(z, np.array(v), np.array(w), m, DT)
    np.testing.assert_allclose(f, force, rtol=0, atol=1e-12 * np.abs(force).max())
    np.testing.assert_allclose(t, torque, rtol=0, atol=1e-12 * max(np.abs(torque).max(), 1e-30))


@pytest.mark.parametrize("params,word", [("MIN_THICKNESS -1e-5", "MIN_THICKNESS"),
                                         ("DYNAMIC_VISCOSITY -1", "DYNAMIC_VISCOSITY")])
def test_bad_parameters_are_input_errors(tmp_path, params, word):
    styles_or_skip()
    job = _job(tmp_path, params)
    with pytest.raises(InputError, match=rf"ModelPWHertzMindlinLiquid parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:12: ")


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "pwl")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPWHertzMindlinLiquid", 11,
                                 tmp_path / "pwl_init.mdem")


# checkpointed while the spheres touch (sphere 0 and the plate from about step 2490):
# the law and its tangential overlap survive
def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch):
    check_resume_is_bitwise(tmp_path, monkeypatch, _job, "pwl_result_prec17.txt", 2520)


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    check_lmp_replay_is_bitwise(tmp_path, _job)
