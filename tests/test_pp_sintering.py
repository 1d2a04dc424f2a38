"""ModelPPSintering (translate/granular/models/pp_sintering.py, pair_style musen/sintering,
src/musen_pp_sintering.cpp) against the real cmusen: two spheres that touch, pulled together by
the sintering force while sliding past each other, spinning (tests/data/real-outputs/musen/models/
pp_sintering/README.md), and the law on single contacts against MUSEN's CalculatePP re-written in
numpy.  The opt-in test (FIBRELMP_CMUSEN) reruns cmusen and checks the stored reference is its
output."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_other_contact_radius_is_refused,
                                 check_reference_is_cmusens_output, check_refused_without_styles,
                                 check_resume_is_bitwise, check_run_is_cmusens, model_job,
                                 needs_cmusen, pair_contact, print_per_contact_cost, styles_or_skip)

DATA = data_path("real-outputs/musen/models/pp_sintering")
PARAMS = "MODEL_PP_PARAMS      DIFFUSION 1e-12 VISCOUS_PARAMETER 0.01"
MODEL_LINE = 10


def _job(tmp_path: Path, new_params: str | None = None) -> Path:
    return model_job(tmp_path, DATA, "sinter", PARAMS, new_params)


def test_sintering_pair_is_cmusens(tmp_path):
    styles_or_skip()
    # 1e-6 of each quantity's scale (measured: 7e-16 of the velocity scale)
    check_run_is_cmusens(tmp_path, _job(tmp_path), DATA, "sinter",
                         "pair_style      musen/sintering 1e-12 0.01 0.5",
                         {COORD: 1e-3, VEL: 1e-2, ANGVEL: 20.0})


def test_the_reference_tells_sintering_from_hertz_mindlin():
    """cmusen's own outputs: sintering pulls the spheres into each other, sliding stops and the
    spins stay (no moments); Hertz-Mindlin pushes them apart and friction changes the spins."""
    sint = read_time_points(DATA / "cmusen_sinter_result_prec17.txt")
    hm = read_time_points(DATA / "cmusen_sinter_as_hertz_mindlin_result_prec17.txt")
    for tp, sintered in ((sint, True), (hm, False)):
        x, w = tp.fields[COORD], tp.fields[ANGVEL]
        overlap = 2e-3 - np.linalg.norm(x[-1, 1] - x[-1, 0])
        spins_kept = np.array_equal(w[-1], w[0])
        if sintered:
            assert overlap > 1e-4 and spins_kept, overlap
        else:
            assert overlap < 0 and not spins_kept, overlap


# ---------------------------------------------------------------- the law on single contacts

PI = 3.14159265358979323846
E_STAR, G_STAR, REST, MU, MU_R = 2.0e6, 4.0e5, 0.5, 0.3, 0.05
R1, R2, RHO, DT = 1e-3, 0.8e-3, 2500.0, 1e-6
COEFF = f"{E_STAR} {G_STAR} {REST} {MU} {MU_R}"      # pair_coeff 1 1's words
DIFFUSION, ETA, GAMMA = 1e-12, 0.01, 0.5
STYLE = f"musen/sintering {DIFFUSION} {ETA} {GAMMA}"


def musen_sintering(x1, x2, v1, v2, r1, r2, diffusion, eta, gamma):
    """ModelPPSintering::CalculatePP with ConsolidateSrc: the force on 1 (the force on 2 is its
    negative, no moments); None when cmusen finds no collision."""
    cv = x2 - x1
    if not (r1 + r2) ** 2 > cv @ cv:
        return None
    req = r1 * r2 / (r1 + r2)
    overlap = r1 + r2 - np.linalg.norm(cv)
    n = cv / np.linalg.norm(cv)
    rel = v1 - v2                                   # centre velocities: no spin term
    rel_n = n * (n @ rel)
    rel_t = rel - rel_n
    a2 = 4 * req * overlap
    return (n * 1.125 * PI * 2 * req * gamma + rel_n * (-PI * a2 ** 2 / 8 / diffusion)
            + rel_t * (-eta * PI * a2 * (2 * req) ** 2 / 8 / diffusion))


# overlap (negative: a gap), approach speed, tangential speed, spins (which must not matter)
CONTACTS = [(2e-6, 0.01, 0.0, (0, 0, 0), (0, 0, 0)),
            (1e-5, -0.02, 0.003, (0, 0, 20.0), (5.0, 0, 0)),
            (3e-5, 0.05, 0.0, (0, 3.0, 0), (0, 0, -7.0)),
            (1e-7, 0.0, 0.5, (0, 0, 300.0), (0, 0, 0)),
            (1e-12, 0.0, 0.0, (0, 0, 0), (0, 0, 0)),
            (-1e-9, 0.1, 0.0, (0, 0, 0), (0, 0, 0))]


@pytest.mark.parametrize("overlap,vn,vt,w1,w2", CONTACTS)
def test_single_contact_is_musens_law(overlap, vn, vt, w1, w2):
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - overlap)
    v1, v2 = direction * vn, np.array([-0.6, 0.8, 0.0]) * vt
    f, t, _ = pair_contact(STYLE, COEFF, x2, v1, v2, w1, w2, (R1, R2), RHO, DT)
    force = musen_sintering(np.zeros(3), x2, v1, v2, R1, R2, DIFFUSION, ETA, GAMMA)
    assert not t.any()                                   # MUSEN's law has no moments
    if force is None:                  # beyond the contact radii: no collision, no force
        assert overlap < 0 and not f.any()
        return
    scale = np.abs(force).max()
    np.testing.assert_allclose(f[0], force, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f[1], -force, rtol=0, atol=1e-12 * scale)
    # at the contact's edge, at rest, only the pull 1.125 pi 2R* gamma remains, towards sphere 2
    if overlap <= 1e-12 and vn == 0 and vt == 0:
        pull = 1.125 * math.pi * 2 * GAMMA * R1 * R2 / (R1 + R2)
        assert f[0] @ direction == pytest.approx(pull, rel=1e-9)


def test_per_contact_cost_against_hertz_mindlin():
    """A rough figure, printed (pytest -s): the same dense packing with musen/hm and musen/sintering
    (sintering collapses it; only the cost per step is of interest)."""
    styles_or_skip()
    print_per_contact_cost(("musen/hm", STYLE), COEFF, RHO, DT,
                           after_atoms=("velocity all create 1e-9 4 loop geom",))


@pytest.mark.parametrize("new_params,match", [
    ("MODEL_PP_PARAMS      DIFFUSION 0 VISCOUS_PARAMETER 0.01", "DIFFUSION must be > 0"),
    ("MODEL_PP_PARAMS      DIFFUSION 1e-12 VISCOUS_PARAMETER inf", "VISCOUS_PARAMETER must be finite"),
])
def test_bad_parameters_are_refused(tmp_path, new_params, match):
    styles_or_skip()
    job = _job(tmp_path, new_params)
    with pytest.raises(InputError, match=match) as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:")


def test_other_contact_radius_is_refused(tmp_path):
    styles_or_skip()
    check_other_contact_radius_is_refused(_job(tmp_path), tmp_path / "sinter_scene.txt", MODEL_LINE, "0.0011")


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "sinter")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPPSintering", MODEL_LINE,
                                 tmp_path / "sinter_init.mdem")


def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch):
    check_resume_is_bitwise(tmp_path, monkeypatch, _job, "sinter_result_prec17.txt", 2010)
