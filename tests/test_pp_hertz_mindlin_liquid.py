"""ModelPPHertzMindlinLiquid (translate/granular/models/pp_hertz_mindlin_liquid.py, pair_style
musen/liquid, src/musen_pp_hertz_mindlin_liquid.cpp) against the real cmusen: a slow approach
that the bridge holds and a separation it slows (tests/data/real-outputs/musen/models/
pp_hertz_mindlin_liquid/README.md), and the law on single contacts against MUSEN's
CalculatePP re-written in numpy.  The opt-in test (FIBRELMP_CMUSEN) reruns cmusen."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_lmp_replay_is_bitwise,
                                 check_other_contact_radius_is_refused,
                                 check_reference_is_cmusens_output, check_refused_without_styles,
                                 check_resume_is_bitwise, check_run_is_cmusens, model_job,
                                 needs_cmusen, pair_contact, print_per_contact_cost, styles_or_skip)

DATA = data_path("real-outputs/musen/models/pp_hertz_mindlin_liquid")
PARAMS = "MIN_THICKNESS 2e-5 CONTACT_ANGLE 20 SURFACE_TENSION 0.7 DYNAMIC_VISCOSITY 0.001"


def _job(tmp_path: Path, params: str = PARAMS) -> Path:
    return model_job(tmp_path, DATA, "liq", PARAMS, params)


def test_bridge_runs_are_cmusens(tmp_path):
    styles_or_skip()
    # 1e-6 of each quantity's scale (measured: 7.5e-14; the pair style hands the law the
    # contact vector and relative velocity computed in another order than MUSEN's law)
    check_run_is_cmusens(tmp_path, _job(tmp_path), DATA, "liq",
                         "pair_style      musen/liquid 2e-05 20.0 0.7 0.001",
                         {COORD: 1e-3, VEL: 2e-2, ANGVEL: 20.0})


def test_the_reference_tells_the_bridge_from_hertz_mindlin():
    liq = read_time_points(DATA / "cmusen_liq_result_prec17.txt")
    hm = read_time_points(DATA / "cmusen_liq_as_hertz_mindlin_result_prec17.txt")

    def last(tp, a, b):
        x, v = tp.fields[COORD][-1], tp.fields[VEL][-1]
        return np.linalg.norm(x[b] - x[a]) - 2e-3, np.linalg.norm(v[b] - v[a])
    (gap_l, speed_l), (gap_h, speed_h) = last(liq, 0, 1), last(hm, 0, 1)
    assert gap_l < 0 and speed_l < 1e-4 and gap_h > 1e-6 and speed_h > 4e-3
    # the bridge pulls while the separating pair touches: it leaves slower
    assert last(liq, 2, 3)[1] < 0.9 * last(hm, 2, 3)[1]


# ---------------------------------------------------------------- the law on single contacts

PI = 3.14159265358979323846
TWO_SQRT_5_6 = 1.825741858350553711523232609336
HMIN, THETA, SIGMA, ETA = 2e-5, 20.0, 0.7, 0.001
E_STAR, G_STAR, REST, MU, MU_R = 2.0e8, 4.0e7, 0.5, 0.3, 0.05
R1, R2, RHO, DT = 1e-3, 0.8e-3, 2500.0, 1e-6
COEFF = f"{E_STAR} {G_STAR} {REST} {MU} {MU_R}"      # pair_coeff 1 1's words


def musen_liquid(x1, x2, v1, v2, w1, w2, r1, r2, m1, m2, dt):
    """ModelPPHertzMindlinLiquid::CalculatePP for a new contact (zero stored tangential
    overlap), contact radius = radius: force on 1, torques on 1 and 2; None without a
    collision (CheckPPCollision)."""
    cv = x2 - x1
    if not (r1 + r2) ** 2 > cv @ cv:
        return None
    req, meq = r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2)
    alpha = math.log(REST) / math.sqrt(PI * PI + math.log(REST) ** 2)
    theta = THETA * PI / 180
    h = max(np.linalg.norm(cv) - r1 - r2, HMIN)
    overlap = r1 + r2 - np.linalg.norm(cv)
    rc1, rc2 = cv * (r1 / (r1 + r2)), cv * (-r2 / (r1 + r2))
    n = cv / np.linalg.norm(cv)
    rel = v2 - v1 + np.cross(rc1, w1) - np.cross(rc2, w2)
    vn = n @ rel
    vt = rel - vn * n
    volume = PI / 3 * (r1 ** 3 + r2 ** 3)
    a_ = -1.1 * volume ** -0.53
    b_ = (-0.34 * math.log(volume) - 0.96) * theta ** 2 - 0.019 * math.log(volume) + 0.48
    c_ = 0.0042 * math.log(volume) + 0.078
    cap = n * (PI * req * SIGMA * (math.exp(a_ * h + b_) + c_))
    visc_n = vn * n * (6 * PI * ETA * req * req / h)
    ft_liq = vt * (6 * PI * ETA * req * (8 / 15 * math.log(req / h) + 0.9588))
    moment_liq = np.cross(-0.5 * cv, ft_liq)
    a = math.sqrt(req * overlap)
    kn = 2 * E_STAR * a
    fel = -2 / 3 * overlap * kn
    fdamp = -TWO_SQRT_5_6 * alpha * vn * math.sqrt(kn * meq)
    kt = 8 * G_STAR * a
    fshear = vt * dt * kt
    limit = MU * abs(fel + fdamp)
    if np.linalg.norm(fshear) > limit:
        ft_dry = fshear * limit / np.linalg.norm(fshear)
    else:
        ft_dry = fshear + vt * (-TWO_SQRT_5_6 * alpha * math.sqrt(kt * meq))

    def roll(w, r):
        return w * (-MU_R * abs(fel) * r / np.linalg.norm(w)) if np.abs(w).max() > 1e-100 else 0 * w
    ft = ft_dry + ft_liq
    force = n * (fel + fdamp) + ft + cap + visc_n
    return (force, np.cross(n, ft) * r1 + roll(w1, r1) - moment_liq,
            np.cross(n, ft) * r2 + roll(w2, r2) - moment_liq)


STYLE = f"musen/liquid {HMIN} {THETA} {SIGMA} {ETA}"
# overlap (negative: a gap), approach speed, tangential speed, spins; the 4th slips
CONTACTS = [(2e-7, 0.01, 0.0, (0, 0, 0), (0, 0, 0)),
            (1e-6, -0.02, 0.003, (0, 0, 20.0), (5.0, 0, 0)),
            (3e-6, 0.05, 0.0, (0, 3.0, 0), (0, 0, -7.0)),
            (1e-8, 0.0, 0.5, (0, 0, 0), (0, 0, 0)),
            (1e-14, 0.0, 0.0, (0, 0, 0), (0, 0, 0)),
            (-1e-9, 0.1, 0.0, (0, 0, 0), (0, 0, 0))]


@pytest.mark.parametrize("overlap,vn,vt,w1,w2", CONTACTS)
def test_single_contact_is_musens_law(overlap, vn, vt, w1, w2):
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - overlap)
    v1, v2 = direction * vn, np.array([-0.6, 0.8, 0.0]) * vt
    w1, w2 = np.array(w1, float), np.array(w2, float)
    f, t, m = pair_contact(STYLE, COEFF, x2, v1, v2, w1, w2,
                              (R1, R2), RHO, DT)
    ref = musen_liquid(np.zeros(3), x2, v1, v2, w1, w2, R1, R2, m[0], m[1], DT)
    if ref is None:                  # beyond the contact radii: no collision, no bridge
        assert overlap < 0 and not f.any() and not t.any()
        return
    force, m1, m2 = ref
    scale = np.abs(force).max()
    np.testing.assert_allclose(f[0], force, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f[1], -force, rtol=0, atol=1e-12 * scale)
    tscale = max(np.abs(np.concatenate([m1, m2])).max(), 1e-30)
    np.testing.assert_allclose(t, [m1, m2], rtol=0, atol=1e-11 * tscale)
    if overlap <= 1e-14 and vn == 0:     # at the edge: the capillary pull alone, towards 2
        assert f[0] @ direction > 0


def test_per_contact_cost_against_hertz_mindlin():
    """A rough figure, printed (pytest -s): the same dense packing with musen/hm and this law."""
    styles_or_skip()
    print_per_contact_cost(("musen/hm", STYLE), COEFF, RHO, 1e-8)


@pytest.mark.parametrize("params,word", [("MIN_THICKNESS 0", "MIN_THICKNESS"),
                                         ("SURFACE_TENSION -1", "SURFACE_TENSION"),
                                         ("DYNAMIC_VISCOSITY -0.1", "DYNAMIC_VISCOSITY")])
def test_bad_parameters_are_input_errors(tmp_path, params, word):
    styles_or_skip()
    job = _job(tmp_path, params)
    with pytest.raises(InputError, match=rf"ModelPPHertzMindlinLiquid parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:11: ")


def test_contact_radius_other_than_radius_is_refused(tmp_path):
    styles_or_skip()
    check_other_contact_radius_is_refused(_job(tmp_path), tmp_path / "liq_scene.txt", 10, "0.0012")


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "liq")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPPHertzMindlinLiquid", 10,
                                 tmp_path / "liq_init.mdem")


# checkpointed while the spheres touch (spheres 0 and 1 from about step 3650):
# the law and its tangential overlap survive
def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch):
    check_resume_is_bitwise(tmp_path, monkeypatch, _job, "liq_result_prec17.txt", 3760)


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    check_lmp_replay_is_bitwise(tmp_path, _job)
