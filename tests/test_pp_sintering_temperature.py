"""ModelPPSinteringTemperature (translate/granular/models/pp_sintering_temperature.py, pair_style
musen/pp sintering/temperature, src/musen_pp_sintering_temperature.cpp) against the real cmusen:
four pairs of touching or approaching spheres, hot and cold (tests/data/real-outputs/musen/models/
pp_sintering_temperature/README.md), and the law on single contacts against MUSEN's CalculatePP
re-written in numpy.  The opt-in test (FIBRELMP_CMUSEN) reruns cmusen and checks the stored
reference is its output."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp._lammps import new_lammps
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, CMUSEN, COORD, VEL, check_lmp_replay_is_bitwise,
                                 check_reference_is_cmusens_output, check_refused_without_styles,
                                 check_result_is_cmusens, check_resume_is_bitwise,
                                 check_run_is_cmusens, model_job, needs_cmusen,
                                 print_per_contact_cost, styles_or_skip)

DATA = data_path("real-outputs/musen/models/pp_sintering_temperature")
PARAMS = ("MODEL_PP_PARAMS      GRAINBOUND_DIFFUSION 1.3e-8 VISCOUS_PARAMETER 0.01 ATOMIC_VOLUME "
          "5e-21 ACTIVATION_ENERGY 100000 MINIMAL_TEMPERATURE 1000 MAX_OVERLAP_COEFF 0.05")
MODEL_LINE = 10
TEMPERATURE = 37


def _job(tmp_path: Path, new_params: str | None = None) -> Path:
    return model_job(tmp_path, DATA, "sintert", PARAMS, new_params)


def test_sintering_temperature_pair_is_cmusens(tmp_path):
    styles_or_skip()
    # 1e-6 of each quantity's scale (measured: 2e-13 of the velocity scale, 6e-16 of positions)
    ours, theirs = check_run_is_cmusens(
        tmp_path, _job(tmp_path), DATA, "sintert", "pair_style      musen/pp sintering/temperature "
        "1.3e-08 0.01 5e-21 100000.0 1000.0 0.05 0.5", {COORD: 1e-3, VEL: 1e-2, ANGVEL: 20.0})
    # no heat model: the temperatures stay the scene's
    np.testing.assert_array_equal(ours.fields[TEMPERATURE], theirs.fields[TEMPERATURE])


def test_with_heat_conduction_is_cmusens(tmp_path):
    """Together with ModelPPHeatConduction (its default parameters) the law reads the
    temperatures fix musen/heat updates: the mixed pair (1800 K, 400 K) exchanges heat."""
    styles_or_skip()
    for name in ("sintert_scene.txt", "job_sintert_heat.txt"):
        shutil.copy(DATA / name, tmp_path)
    python_api.run(tmp_path / "job_sintert_heat.txt", work=tmp_path / "work")
    _, theirs = check_result_is_cmusens(tmp_path / "sintert_heat_result_prec17.txt",
                                        DATA / "cmusen_sintert_heat_result_prec17.txt",
                                        {COORD: 1e-3, VEL: 1e-2, ANGVEL: 20.0, TEMPERATURE: 1000.0})
    assert theirs.fields[TEMPERATURE][-1, 6, 0] < 1800.0 - 1e-2      # heat went from 6 to 7


def _overlaps(path: Path) -> np.ndarray:
    x = read_time_points(path).fields[COORD]
    return np.stack([2e-3 - np.linalg.norm(x[:, a + 1] - x[:, a], axis=1) for a in range(0, 8, 2)], 1)


def test_the_reference_tells_it_from_plain_sintering():
    """cmusen's own outputs: with temperatures the hot pairs stop at MAX_OVERLAP_COEFF 2R* = 50 um,
    the cold pair touching at time 0 stays near its initial 10 um, the cold pair meeting later
    bounces off; plain ModelPPSintering (D = 1.04e-12, the hot pairs' value) sinters all four."""
    temp = _overlaps(DATA / "cmusen_sintert_result_prec17.txt")
    plain = _overlaps(DATA / "cmusen_sintert_as_sintering_result_prec17.txt")
    assert np.all(temp[-1, [0, 3]] == pytest.approx(5e-5, rel=1e-2))
    assert temp[-1, 1] == pytest.approx(1e-5, rel=1e-2) and np.abs(temp[:, 1] - 1e-5).max() < 3e-6
    assert temp[-1, 2] < -1e-4
    assert np.all(plain[-1] > 2.5e-4)
    # the hot pair follows plain sintering until it nears the maximum overlap
    assert temp[1, 0] == pytest.approx(plain[1, 0], rel=1e-5)


# ---------------------------------------------------------------- the law on single contacts

PI = 3.14159265358979323846
KB, R_GAS, TWO_SQRT_5_6 = 1.38064852e-23, 8.314462618, 1.825741858350553711523232609336
E_STAR, G_STAR, REST, MU, MU_R = 2.0e6, 4.0e5, 0.5, 0.3, 0.05
R1, R2, RHO, DT = 1e-3, 0.8e-3, 2500.0, 1e-6
LAW = dict(db=1.3e-8, eta=0.01, omega=5e-21, q=1e5, tmin=1000.0, cmax=0.05, gamma=0.5)


def musen_sintering_temperature(x2, v1, v2, t1, t2, initial, at_zero, p=LAW):
    """ModelPPSinteringTemperature::CalculatePP for a contact whose stored tangential overlap is
    zero and whose stored initial overlap is ``initial``: the force on sphere 1 at the origin."""
    cv = np.asarray(x2, float)
    if not (R1 + R2) ** 2 > cv @ cv:
        return None
    req, meq = R1 * R2 / (R1 + R2), None
    m1, m2 = (RHO * 4 / 3 * PI * r ** 3 for r in (R1, R2))
    meq = m1 * m2 / (m1 + m2)
    overlap = R1 + R2 - np.linalg.norm(cv)
    n = cv / np.linalg.norm(cv)
    temp = (t1 + t2) / 2
    max_overlap = p["cmax"] * 2 * req
    rel = np.asarray(v1, float) - np.asarray(v2, float)
    vn = n @ rel
    rel_t = rel - vn * n
    alpha = math.log(REST) / math.sqrt(PI ** 2 + math.log(REST) ** 2)
    if at_zero:
        initial = overlap
    if temp >= p["tmin"] and overlap < max_overlap:
        d = p["omega"] / (KB * temp) * p["db"] * math.exp(-p["q"] / (R_GAS * temp))
        a2 = 4 * req * overlap
        return (n * 1.125 * PI * 2 * req * p["gamma"] + vn * n * (-PI * a2 ** 2 / 8 / d)
                + rel_t * (-p["eta"] * PI * a2 * (2 * req) ** 2 / 8 / d))
    a = math.sqrt(req * overlap)
    kn = 2 * E_STAR * a
    damp_n = TWO_SQRT_5_6 * alpha * vn * math.sqrt(kn * meq)
    if temp <= p["tmin"]:
        rest = max_overlap if overlap >= max_overlap else initial
        kt = 8 * G_STAR * a
        tang = -rel_t * DT * kt + rel_t * TWO_SQRT_5_6 * alpha * math.sqrt(kt * meq)
        return n * (-(overlap - rest) * kn * 2 / 3 + damp_n) + tang
    return n * (-(overlap - max_overlap) * kn * 2 / 3 + damp_n)


def _law_words(p=LAW) -> str:
    return "sintering/temperature " + " ".join(
        repr(p[k]) for k in ("db", "eta", "omega", "q", "tmin", "cmax", "gamma"))


def _lammps_forces(x2, v1, v2, t1, t2, time_now, x1=(0.0, 0.0, 0.0), boundary="f f f",
                   laws=None, steps=0, state=None):
    """Forces and torques on both spheres at the given state (``run 0``); with ``steps``, after
    that many steps first (then ``state``, a dict, gets the final positions and velocities)."""
    x1 = np.asarray(x1, float).tolist()
    x2 = (np.asarray(x2, float) + x1).tolist()
    v1, v2 = (np.asarray(a, float).tolist() for a in (v1, v2))
    words = laws or _law_words()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {lammps_styles.plugin().path}", "units si", "atom_style sphere",
                  f"boundary {boundary}", "newton off", "comm_modify vel yes",
                  "atom_modify map array", "fix temps all property/atom d_musen_temperature ghost yes",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  f"create_atoms 1 single {x1[0]!r} {x1[1]!r} {x1[2]!r}",
                  f"create_atoms 1 single {x2[0]!r} {x2[1]!r} {x2[2]!r} remap yes",
                  f"set atom 1 diameter {2 * R1!r} density {RHO!r}",
                  f"set atom 2 diameter {2 * R2!r} density {RHO!r}",
                  f"set atom 1 vx {v1[0]!r} vy {v1[1]!r} vz {v1[2]!r}",
                  f"set atom 2 vx {v2[0]!r} vy {v2[1]!r} vz {v2[2]!r}",
                  "set atom 1 omega 0 0 30.0", "set atom 2 omega 7.0 0 0",
                  f"set atom 1 d_musen_temperature {t1!r}", f"set atom 2 d_musen_temperature {t2!r}",
                  f"pair_style musen/pp {words}",
                  f"pair_coeff 1 1 {E_STAR} {G_STAR} {REST} {MU} {MU_R}",
                  f"reset_timestep 0 time {time_now!r}",
                  "neighbor 0.0005 bin", f"timestep {DT!r}", "fix integrate all nve/sphere",
                  *([f"run {steps} post no"] if steps else []), "run 0 post no"]:
            lmp.command(c)
        order = np.argsort(lmp.numpy.extract_atom("id")[:2])     # by atom id (atoms sort)
        if state is not None:
            state["x"] = lmp.numpy.extract_atom("x")[:2][order].copy()
            state["v"] = lmp.numpy.extract_atom("v")[:2][order].copy()
        f = lmp.numpy.extract_atom("f")[:2][order].copy()
        t = lmp.numpy.extract_atom("torque")[:2][order].copy()
    finally:
        lmp.close()
    return f, t


# overlap (negative: a gap), approach speed, tangential speed, temperatures, MUSEN's time
CONTACTS = [(2e-5, 0.01, 0.003, 1500.0, 1500.0, 0.0),      # hot, below the maximum: sintering
            (2e-5, -0.02, 0.003, 1800.0, 400.0, 1e-3),     # mean 1100 K: sintering
            (1e-5, 0.0, 0.0, 1000.0, 1000.0, 1e-3),        # exactly the minimum: sintering
            (3e-5, 0.02, 0.0, 1500.0, 1500.0, 1e-3),       # hot, past the maximum (5e-5 * 0.8/0.9)
            (1e-5, 0.01, 0.004, 500.0, 500.0, 0.0),        # cold at time 0: spring to this overlap
            (1e-5, 0.01, 0.004, 500.0, 500.0, 1e-3),       # cold, new contact later: to zero
            (5e-5, -0.01, 0.0, 900.0, 300.0, 1e-3),        # cold, past the maximum: to it
            (-1e-9, 0.1, 0.0, 1500.0, 1500.0, 1e-3)]


@pytest.mark.parametrize("overlap,vn,vt,t1,t2,time_now", CONTACTS)
def test_single_contact_is_musens_law(overlap, vn, vt, t1, t2, time_now):
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - overlap)
    v1, v2 = direction * vn, np.array([-0.6, 0.8, 0.0]) * vt
    f, t = _lammps_forces(x2, v1, v2, t1, t2, time_now)
    force = musen_sintering_temperature(x2, v1, v2, t1, t2, 0.0, time_now == 0.0)
    assert not t.any()                                   # MUSEN's law has no moments
    if force is None:
        assert overlap < 0 and not f.any()
        return
    scale = np.abs(force).max()
    assert scale > 0
    np.testing.assert_allclose(f[0], force, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f[1], -force, rtol=0, atol=1e-12 * scale)


def test_two_laws_keep_their_own_initial_overlap():
    """Each law's per-contact values are its own block of the contact's history (pair musen/hm
    sizes the entry as 9 + the laws' blocks): at 1500 K a law with Tmin 1000 sinters and sets
    its initial overlap to the overlap; after it, one with Tmin 2000 is cold and springs towards
    ITS initial overlap, zero for a contact that starts after time 0.  Shared values would give
    the second the first's overlap (no elastic force)."""
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - 1e-5)
    v1, v2 = direction * 0.01, np.array([-0.6, 0.8, 0.0]) * 0.003
    cold = {**LAW, "tmin": 2000.0}
    f, t = _lammps_forces(x2, v1, v2, 1500.0, 1500.0, 1e-3,
                          laws=f"{_law_words()} then {_law_words(cold)}")
    hot_part = musen_sintering_temperature(x2, v1, v2, 1500.0, 1500.0, 0.0, False)
    cold_part = musen_sintering_temperature(x2, v1, v2, 1500.0, 1500.0, 0.0, False, p=cold)
    shared = musen_sintering_temperature(x2, v1, v2, 1500.0, 1500.0, 1e-5, False, p=cold)
    expected = hot_part + cold_part
    scale = np.abs(expected).max()
    assert np.abs(cold_part - shared).max() > 1e-3 * scale      # the test tells them apart
    np.testing.assert_allclose(f[0], expected, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f[1], -expected, rtol=0, atol=1e-12 * scale)


def test_two_laws_keep_their_own_initial_overlap_through_steps():
    """The same two laws after 5 steps (pair musen/hm writes each law's values into its block
    of the contact's stored entry), then evaluated at the final state (``run 0`` reads the
    entry): the cold law's initial overlap is still its own zero, not the hot law's overlap."""
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - 1e-5)
    v1, v2 = direction * 0.01, np.array([-0.6, 0.8, 0.0]) * 0.003
    cold = {**LAW, "tmin": 2000.0}
    state = {}
    f, _ = _lammps_forces(x2, v1, v2, 1500.0, 1500.0, 1e-3,
                          laws=f"{_law_words()} then {_law_words(cold)}", steps=5, state=state)
    rel = state["x"][1] - state["x"][0]
    v1, v2 = state["v"]
    assert not np.allclose(rel, x2, rtol=0, atol=1e-12)           # the spheres moved
    expected = (musen_sintering_temperature(rel, v1, v2, 1500.0, 1500.0, 0.0, False)
                + musen_sintering_temperature(rel, v1, v2, 1500.0, 1500.0, 0.0, False, p=cold))
    overlap = R1 + R2 - np.linalg.norm(rel)
    shared = (musen_sintering_temperature(rel, v1, v2, 1500.0, 1500.0, 0.0, False)
              + musen_sintering_temperature(rel, v1, v2, 1500.0, 1500.0, overlap, False, p=cold))
    scale = np.abs(expected).max()
    assert np.abs(expected - shared).max() > 1e-3 * scale
    np.testing.assert_allclose(f[0], expected, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(f[1], -expected, rtol=0, atol=1e-12 * scale)


def test_across_a_periodic_boundary_the_ghosts_temperature_counts():
    """A hot contact across a periodic boundary (sphere 2 a ghost of sphere 1's processor): the
    same force as in open space; the translation gives the temperature property ``ghost yes``."""
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    x2 = direction * (R1 + R2 - 2e-5)
    v1, v2 = direction * 0.01, np.array([-0.6, 0.8, 0.0]) * 0.003
    open_space, _ = _lammps_forces(x2, v1, v2, 1500.0, 1200.0, 1e-3)
    across, _ = _lammps_forces(x2, v1, v2, 1500.0, 1200.0, 1e-3, x1=(0.0099, 0.0, 0.0),
                               boundary="p f f")
    force = musen_sintering_temperature(x2, v1, v2, 1500.0, 1200.0, 0.0, False)
    scale = np.abs(force).max()
    np.testing.assert_allclose(open_space[0], force, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(across[0], force, rtol=0, atol=1e-9 * scale)


def test_signs_of_the_branches():
    """Hot and below the maximum: pulled together; hot past it, at rest: pushed apart; cold at
    rest at time 0: no normal force (the overlap is the equilibrium), later: pushed apart."""
    styles_or_skip()
    direction = np.array([0.8, 0.6, 0.0])
    max_overlap = LAW["cmax"] * 2 * R1 * R2 / (R1 + R2)

    def normal(overlap, t, time_now):
        x2 = direction * (R1 + R2 - overlap)
        f, _ = _lammps_forces(x2, np.zeros(3), np.zeros(3), t, t, time_now)
        return f[0] @ direction

    assert normal(0.5 * max_overlap, 1500.0, 1e-3) > 0
    assert normal(1.5 * max_overlap, 1500.0, 1e-3) < 0
    later = normal(0.5 * max_overlap, 500.0, 1e-3)
    assert later < 0
    assert abs(normal(0.5 * max_overlap, 500.0, 0.0)) < 1e-12 * abs(later)   # round-off only


def test_per_contact_cost_against_hertz_mindlin():
    """A rough figure, printed (pytest -s): the same dense packing with musen/hm and this law."""
    styles_or_skip()
    words = " ".join(repr(LAW[k]) for k in ("db", "eta", "omega", "q", "tmin", "cmax", "gamma"))
    print_per_contact_cost({"musen/hm": "musen/hm",
                            "musen/pp sintering/temperature": f"musen/pp sintering/temperature {words}"},
                           f"{E_STAR} {G_STAR} {REST} {MU} {MU_R}", RHO, DT,
                           before_box=("fix temps all property/atom d_musen_temperature",),
                           after_atoms=("set group all d_musen_temperature 500.0",
                                        "velocity all create 1e-9 4 loop geom"))


@pytest.mark.parametrize("new_params,match", [
    (PARAMS.replace("ATOMIC_VOLUME 5e-21", "ATOMIC_VOLUME 0"), "ATOMIC_VOLUME must be > 0"),
    (PARAMS.replace("MAX_OVERLAP_COEFF 0.05", "MAX_OVERLAP_COEFF -1"), "MAX_OVERLAP_COEFF must be >= 0"),
    (PARAMS.replace("VISCOUS_PARAMETER 0.01", "VISCOUS_PARAMETER inf"), "VISCOUS_PARAMETER must be finite"),
])
def test_bad_parameters_are_refused(tmp_path, new_params, match):
    styles_or_skip()
    job = _job(tmp_path, new_params)
    with pytest.raises(InputError, match=match) as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:")


@needs_cmusen
def test_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, DATA, "sintert")
    for prefix in ("sintert_as_sintering", "sintert_heat"):
        shutil.copy(DATA / f"job_{prefix}.txt", tmp_path)
        done = subprocess.run([CMUSEN, "-t=1", f"-s=job_{prefix}.txt"], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
        assert (tmp_path / f"{prefix}_result_prec17.txt").read_bytes() == \
            (DATA / f"cmusen_{prefix}_result_prec17.txt").read_bytes()


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(_job(tmp_path), "ModelPPSinteringTemperature", MODEL_LINE,
                                 tmp_path / "sintert_init.mdem")


def test_checkpointed_and_resumed_run_is_bitwise_the_same(tmp_path, monkeypatch):
    """The initial overlap (the law's block of the contact history) goes through the checkpoint."""
    check_resume_is_bitwise(tmp_path, monkeypatch, _job, "sintert_result_prec17.txt", 2010)


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames (the
    time-0 rule and the initial overlaps come from the script alone)."""
    check_lmp_replay_is_bitwise(tmp_path, _job)
