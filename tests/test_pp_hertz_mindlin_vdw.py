"""ModelPPHertzMindlinVdW (translate/granular/models/pp_hertz_mindlin_vdw.py, pair_style
musen/vdw, src/musen_pp_hertz_mindlin_vdw.cpp) against the real cmusen: a slow oblique approach
of two soft spheres that stick (tests/data/real-outputs/musen/models/pp_hertz_mindlin_vdw/
README.md), and the law on single contacts against MUSEN's CalculatePP re-written in numpy.
The opt-in test (FIBRELMP_CMUSEN) reruns cmusen and checks the stored reference is its output."""

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
                                 check_reference_is_cmusens_output, check_refused_without_styles,
                                 check_resume_is_bitwise, check_run_is_cmusens, model_job,
                                 needs_cmusen, pair_contact, print_per_contact_cost, styles_or_skip)

DATA = data_path("real-outputs/musen/models/pp_hertz_mindlin_vdw")
SCENE_MATERIAL = "11 0.5 12"      # the surface energy in the scene's material line


def _job(tmp_path: Path, scene_edit: tuple[str, str] | None = None) -> Path:
    job = model_job(tmp_path, DATA, "vdw", "")
    if scene_edit:
        scene = tmp_path / "vdw_scene.txt"
        text = scene.read_text()
        assert scene_edit[0] in text
        scene.write_text(text.replace(scene_edit[0], scene_edit[1]))
    return job


def test_sticking_approach_is_cmusens(tmp_path):
    styles_or_skip()
    # 1e-6 of each quantity's scale (measured: bit-identical)
    check_run_is_cmusens(tmp_path, _job(tmp_path), DATA, "vdw", "pair_style      musen/vdw 0.5",
                         {COORD: 1e-3, VEL: 1e-2, ANGVEL: 20.0})


def test_the_reference_tells_vdw_from_hertz_mindlin():
    """cmusen's own outputs: with van der Waals the spheres stick, without they bounce apart."""
    vdw = read_time_points(DATA / "cmusen_vdw_result_prec17.txt")
    hm = read_time_points(DATA / "cmusen_vdw_as_hertz_mindlin_result_prec17.txt")
    for tp, stuck in ((vdw, True), (hm, False)):
        x, v = tp.fields[COORD][-1], tp.fields[VEL][-1]
        gap = np.linalg.norm(x[1] - x[0]) - 2e-3
        speed = np.linalg.norm(v[1] - v[0])
        assert (gap < 0 and speed < 1e-4) if stuck else (gap > 1e-5 and speed > 5e-3), (gap, speed)


# ---------------------------------------------------------------- the law on single contacts

PI = 3.14159265358979323846
TWO_SQRT_5_6 = 1.825741858350553711523232609336
DMIN = 7.5e-10


def musen_vdw(x1, x2, v1, v2, w1, w2, r1, r2, m1, m2, estar, gstar, rest, mu, mu_r, gamma, dt):
    """ModelPPHertzMindlinVdW::CalculatePP for a new contact (zero stored tangential overlap)
    with ConsolidateSrc/Dst: force on 1, torques on 1 and 2; None when cmusen finds no
    collision (CheckPPCollision: (r1 + r2)^2 > |x2 - x1|^2)."""
    cv = x2 - x1
    if not (r1 + r2) ** 2 > cv @ cv:
        return None
    req, meq = r1 * r2 / (r1 + r2), m1 * m2 / (m1 + m2)
    alpha = math.log(rest) / math.sqrt(PI * PI + math.log(rest) ** 2)
    n = cv / np.linalg.norm(cv)
    s = np.linalg.norm(cv) - r1 - r2
    hamaker = 24 * PI * DMIN * DMIN * gamma
    fvdw = hamaker * 2 * req / (12 * DMIN ** 2) if s <= DMIN else hamaker * 2 * req / (12 * (s + DMIN) ** 2)
    if not s < 0:
        return n * fvdw, np.zeros(3), np.zeros(3)
    rc1, rc2 = cv * (r1 / (r1 + r2)), cv * (-r2 / (r1 + r2))
    rel = v2 + np.cross(w2, rc2) - (v1 + np.cross(w1, rc1))
    vn = n @ rel
    vt = rel - vn * n
    a = math.sqrt(req * -s)
    kn = 2 * estar * a
    fel = s * kn * 2 / 3
    fdamp = -TWO_SQRT_5_6 * alpha * vn * math.sqrt(kn * meq)
    kt = 8 * gstar * a
    xi = vt * dt
    fshear = xi * kt
    flimit = mu * abs(fel + fdamp + fvdw)
    if np.linalg.norm(fshear) > flimit:
        ft = fshear * flimit / np.linalg.norm(fshear)
    else:
        ft = fshear + vt * (-TWO_SQRT_5_6 * alpha * math.sqrt(kt * meq))

    def roll(w, r):
        return w * (-mu_r * abs(fel) * r / np.linalg.norm(w)) if np.abs(w).max() > 1e-100 else 0 * w
    force = n * (fel + fdamp + fvdw) + ft
    return force, np.cross(n, ft) * r1 + roll(w1, r1), np.cross(n, ft) * r2 + roll(w2, r2)


E_STAR, G_STAR, REST, MU, MU_R, GAMMA = 2.0e6, 4.0e5, 0.5, 0.3, 0.05, 0.5
R1, R2, RHO, DT = 1e-3, 0.8e-3, 2500.0, 1e-6
COEFF = f"{E_STAR} {G_STAR} {REST} {MU} {MU_R}"      # pair_coeff 1 1's words


# overlap (negative: a gap), approach speed, tangential speed, spins; the last one slips
CONTACTS = [(2e-6, 0.01, 0.0, (0, 0, 0), (0, 0, 0)),
            (1e-5, -0.02, 0.003, (0, 0, 20.0), (5.0, 0, 0)),
            (3e-5, 0.05, 0.0, (0, 3.0, 0), (0, 0, -7.0)),
            (1e-7, 0.0, 0.5, (0, 0, 0), (0, 0, 0)),
            (1e-12, 0.0, 0.0, (0, 0, 0), (0, 0, 0)),
            (-1e-9, 0.1, 0.0, (0, 0, 0), (0, 0, 0))]


@pytest.mark.parametrize("overlap,vn,vt,w1,w2", CONTACTS)
def test_single_contact_is_musens_law(overlap, vn, vt, w1, w2):
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - overlap)
    v1, v2 = direction * vn, np.array([-0.6, 0.8, 0.0]) * vt
    w1, w2 = np.array(w1, float), np.array(w2, float)
    f, t, m = pair_contact(f"musen/vdw {GAMMA}", COEFF, x2, v1, v2, w1, w2,
                              (R1, R2), RHO, DT)
    ref = musen_vdw(np.zeros(3), x2, v1, v2, w1, w2, R1, R2, m[0], m[1], E_STAR, G_STAR, REST, MU,
                    MU_R, GAMMA, DT)
    if ref is None:                  # beyond the contact radii: no collision, no force
        assert overlap < 0 and not f.any() and not t.any()
        return
    force, m1, m2 = ref
    scale = max(np.abs(force).max(), 1e-30)
    np.testing.assert_allclose(f[0], force, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f[1], -force, rtol=0, atol=1e-12 * scale)
    tscale = max(np.abs(np.concatenate([m1, m2])).max(), 1e-30)
    np.testing.assert_allclose(t, [m1, m2], rtol=0, atol=1e-12 * tscale)
    # the attraction pulls sphere 1 towards sphere 2 at the contact's edge, by 4 pi gamma R*
    if overlap <= 1e-12 and vn == 0:
        pull = 4 * math.pi * GAMMA * R1 * R2 / (R1 + R2)
        assert f[0] @ direction == pytest.approx(pull, rel=1e-4)


def test_per_contact_cost_against_hertz_mindlin():
    """A rough figure, printed (pytest -s): the same dense packing with musen/hm and musen/vdw."""
    styles_or_skip()
    print_per_contact_cost(("musen/hm", f"musen/vdw {GAMMA}"), COEFF, RHO, DT,
                           after_atoms=("velocity all create 1e-9 4 loop geom",))


@pytest.mark.parametrize("edit,match", [
    (("5 0.001 0.001 23", "5 0.001 0.0011 23"), "contact radius equals their radius"),
])
def test_refused_where_lammps_cannot_hold_the_range(tmp_path, edit, match):
    styles_or_skip()
    job = _job(tmp_path, edit)
    with pytest.raises(InputError, match=match) as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:10: ")


def test_materials_of_different_surface_energy_are_refused(tmp_path):
    styles_or_skip()
    job = _job(tmp_path)
    scene = tmp_path / "vdw_scene.txt"
    lines = scene.read_text().splitlines()
    mat = next(ln for ln in lines if ln.startswith("32 "))
    other = mat.replace("MSOFT Soft", "MOTHER Other").replace(SCENE_MATERIAL, "11 0.2 12")
    lines.append(other)
    lines.append("33 MOTHER MOTHER 200 0.5 201 0.3 202 0.05")
    lines.append("33 MSOFT MOTHER 200 0.5 201 0.3 202 0.05")
    lines[1] = lines[1].replace("23 MSOFT", "23 MOTHER")
    scene.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="equal surface energy") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:10: ")


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "vdw")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPPHertzMindlinVdW", 10, tmp_path / "vdw_init.mdem")


# checkpointed while the spheres touch (stuck from about step 3000):
# the law and its tangential overlap survive
def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch):
    check_resume_is_bitwise(tmp_path, monkeypatch, _job, "vdw_result_prec17.txt", 5010)


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    check_lmp_replay_is_bitwise(tmp_path, _job)


@pytest.mark.parametrize("pbc, warned", [("1 0 0", True), ("0 0 0", False)])
def test_periodic_box_warns_of_musens_raw_distance(tmp_path, pbc, warned):
    """MUSEN's CalculatePP takes the surface distance from the stored coordinates, so a pair
    touching across a periodic boundary is no contact to cmusen (measured by
    benchmarks/musen_models_cost.py: 1.4 overlaps apart at the end); LAMMPS uses the image."""
    styles_or_skip()
    job = _job(tmp_path)
    text = job.read_text()
    model_line = "MODEL_PP             ModelPPHertzMindlinVdW\n"
    assert model_line in text
    job.write_text(text.replace(model_line, model_line + f"PBC_FLAGS {pbc}\n"
                                "PBC_DOMAIN -0.02 -0.02 -0.02 0.02 0.02 0.02\n"))
    kinds: list[str] = []
    python_api.translate_job(job, tmp_path / "work", lambda items: kinds.extend(k for k, _ in items))
    assert ("musen-periodic-raw-distance" in kinds) == warned
