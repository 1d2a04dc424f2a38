"""MUSEN's contact and bond laws, as translated to LAMMPS, against independent formulas.

Every model is built directly in Python (tests/granular_models.py) and run through
``fibrelmp.pipeline.run_model.run_granular``; the forces, velocities and break times LAMMPS
reports in the frames are compared with closed-form expressions written from
shared/research/musen.md section 2 (not from the translator).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.granmodel import ContactLaw, hertz_effective
from fibrelmp.translate.granular_job import law_args, write_granular_job

from . import granular_models as gm
from .granular_models import run




def hertz(e_star, r_star, delta):
    return 4.0 / 3.0 * e_star * math.sqrt(r_star) * delta ** 1.5


# ---------------------------------------------------------------------------------------
def test_mixing_back_solve_reproduces_effective_moduli():
    """LAMMPS's own mixing of the written (E, nu) gives back MUSEN's E* and G*."""
    mats, _ = gm.two_materials()
    for a, b in [(0, 0), (0, 1), (1, 1)]:
        es, gs = hertz_effective(mats[a], mats[b])
        args = law_args(ContactLaw(es, gs, 0.5, 0.3), 0.0, 1.0, 1.0).split()
        E, nu = float(args[1]), float(args[3])
        assert args[6] == "NULL"
        # LAMMPS: E_eff = 1/(2 (1-nu^2)/E) ; G_eff = 1/(2*2(2-nu)(1+nu)/E)
        assert E / (2 * (1 - nu * nu)) == pytest.approx(es, rel=1e-14)
        assert E / (4 * (2 - nu) * (1 + nu)) == pytest.approx(gs, rel=1e-13)
        assert float(args[7]) == pytest.approx(2 * math.sqrt(gs / es), rel=1e-14)


def test_hertz_normal_force_static_overlap(tmp_path):
    """Two spheres of different materials and radii: F = 4/3 E* sqrt(R*) delta^1.5."""
    mats, contacts = gm.two_materials()
    r1, r2, delta = 0.0005, 0.0008, 2e-6
    sph = gm.spheres([[0, 0, 0], [r1 + r2 - delta, 0, 0]], [r1, r2], [0, 1], mats)
    job, frames = run(gm.model(sph, mats, contacts, dt=1e-8, t_end=0.0), tmp_path)
    assert len(frames) == 1 and frames[0].time == 0.0
    f = frames[0].force
    es, _ = hertz_effective(mats[0], mats[1])
    expect = hertz(es, r1 * r2 / (r1 + r2), delta)
    print(f"\nHertz: LAMMPS {-f[0, 0]!r} N, formula {expect!r} N")
    assert -f[0, 0] == pytest.approx(expect, rel=1e-9)
    assert f[1, 0] == pytest.approx(expect, rel=1e-9)
    assert np.abs(f[:, 1:]).max() == 0.0


def _tangential_case(tmp_path, shift_velocity, steps, mu=0.45, name="t"):
    """Spheres far too heavy to move (m = 1e13 kg): sphere 2 slides tangentially at a
    prescribed speed; e = 1 so no damping acts.  Returns frames and geometry."""
    glass = gm.material("Glass", **{**gm.GLASS, "density": 1e20})
    es, gs = hertz_effective(glass, glass)
    contacts = {(0, 0): ContactLaw(es, gs, 1.0, mu, 0.0)}
    r, delta, dt = 0.0005, 2e-6, 1e-8
    sph = gm.spheres([[0, 0, 0], [2 * r - delta, 0, 0]], r, [0, 0], [glass],
                     v=[[0, 0, 0], [0, shift_velocity, 0]])
    model = gm.model(sph, [glass], contacts, dt=dt, t_end=steps * dt, save_every_steps=steps)
    _, frames = run(model, tmp_path, name)
    return frames, es, gs, r, dt


def test_tangential_stiffness_8_G_a(tmp_path):
    """Small tangential displacement xi: F_t = 8 G* a xi with a = sqrt(R* delta) (MUSEN's
    tangential spring, with MUSEN's integrator)."""
    v, n = 1e-4, 20
    frames, es, gs, r, dt = _tangential_case(tmp_path, v, n, mu=10.0)
    f0, f1 = frames[0], frames[-1]
    dx = f1.position[1] - f1.position[0]
    dist = np.linalg.norm(dx)
    nrm = dx / dist
    delta = 2 * r - dist
    a = math.sqrt(r / 2 * delta)
    # MUSEN's spring grows by v dt at every force evaluation: the two at t = 0 (its prediction,
    # then the real one: both advance contact states) and one per step, so n + 2 by step n,
    # while sphere 2 moved by v n dt
    xi = v * (n + 2) * dt
    assert f1.position[1][1] - f0.position[1][1] == pytest.approx(v * n * dt, rel=1e-9)
    ft = f1.force[1] - (f1.force[1] @ nrm) * nrm      # tangential part on sphere 2
    expect = 8 * gs * a * xi
    print(f"\ntangential: |F_t| {np.linalg.norm(ft)!r} N, 8 G* a xi = {expect!r} N "
          f"(increment from {np.linalg.norm(f0.force[1] - (f0.force[1] @ nrm) * nrm)!r})")
    assert np.linalg.norm(ft) == pytest.approx(expect, rel=1e-6)
    assert ft[1] < 0          # opposes the sliding direction
    assert f1.force[1] @ nrm == pytest.approx(hertz(es, r / 2, delta), rel=1e-9)   # repulsive


def test_sliding_limit_mu_fn(tmp_path):
    """Beyond the Coulomb limit the tangential force stays at mu |F_n|."""
    mu = 0.3
    frames, es, gs, r, dt = _tangential_case(tmp_path, 1.0, 500, mu=mu, name="slide")
    f1 = frames[-1]
    dx = f1.position[1] - f1.position[0]
    dist = np.linalg.norm(dx)
    nrm = dx / dist
    fn = abs(f1.force[1] @ nrm)
    ft = np.linalg.norm(f1.force[1] - (f1.force[1] @ nrm) * nrm)
    a = math.sqrt(r / 2 * (2 * r - dist))
    assert 8 * gs * a * 1.0 * 500 * dt > 2 * mu * fn        # well beyond the elastic limit
    print(f"\nsliding: |F_t| {ft!r}  mu|F_n| {mu * fn!r}")
    assert fn == pytest.approx(hertz(es, r / 2, 2 * r - dist), rel=1e-9)
    assert ft == pytest.approx(mu * fn, rel=1e-9)


@pytest.mark.parametrize("e", [0.9, 0.5, 0.2])
def test_restitution_head_on_hertz(tmp_path, e):
    """Head-on collision of two glass spheres: relative rebound speed / approach speed = e."""
    glass = gm.material("Glass", **gm.GLASS)
    contacts = {(0, 0): gm.law_for(glass, glass, e, 0.45, 0.0)}
    r, v = 0.0005, 1.0
    sph = gm.spheres([[-1.01 * r, 0, 0], [1.01 * r, 0, 0]], r, [0, 0], [glass],
                     v=[[v, 0, 0], [-v, 0, 0]])
    _, frames = run(gm.model(sph, [glass], contacts, dt=2e-9, t_end=2e-5, save_every_steps=2500), tmp_path)
    f = frames[-1]
    assert f.position[1, 0] - f.position[0, 0] > 2 * r              # separated again
    measured = (f.velocity[1, 0] - f.velocity[0, 0]) / (2 * v)
    print(f"\nrestitution e={e}: measured {measured!r}")
    assert measured == pytest.approx(e, rel=0.01)
    # momentum is conserved exactly by the pair forces
    assert abs(f.velocity[0, 0] + f.velocity[1, 0]) < 1e-12


def test_restitution_sphere_wall(tmp_path):
    """Sphere hitting a flat region wall: rebound speed = e_pw * impact speed (R* = R, m* = m)."""
    mats, contacts = gm.two_materials()
    r, v = 0.0005, 0.5
    sph = gm.spheres([[0, 0, 1.02 * r]], r, [0], mats, v=[[0, 0, -v]])
    m = gm.model(sph, mats, contacts, dt=2e-9, t_end=6e-5, save_every_steps=10000)
    gm.add_geometry(m, "floor", gm.rect_triangles([[-0.01, -0.01, 0], [0.01, -0.01, 0],
                                                   [0.01, 0.01, 0], [-0.01, 0.01, 0]]), 1)
    _, frames = run(m, tmp_path)
    vz = frames[-1].velocity[0, 2]
    print(f"\nsphere-wall restitution: {vz / v!r} (e = 0.8)")
    assert vz / v == pytest.approx(0.8, rel=0.01)


def test_wall_hertz_force_uses_particle_radius(tmp_path):
    """Static overlap with a wall: F = 4/3 E*(glass, steel) sqrt(R_p) delta^1.5."""
    mats, contacts = gm.two_materials()
    r, delta = 0.0005, 1e-6
    sph = gm.spheres([[0, 0, r - delta]], r, [0], mats)
    m = gm.model(sph, mats, contacts, dt=1e-8, t_end=0.0)
    gm.add_geometry(m, "floor", gm.rect_triangles([[-0.01, -0.01, 0], [0.01, -0.01, 0],
                                                   [0.01, 0.01, 0], [-0.01, 0.01, 0]]), 1)
    _, frames = run(m, tmp_path)
    es, _ = hertz_effective(mats[0], mats[1])
    assert frames[0].force[0, 2] == pytest.approx(hertz(es, r, delta), rel=1e-9)
    # the triangles carry the opposite force
    assert frames[0].triangle_force.sum(0)[2] == pytest.approx(-hertz(es, r, delta), rel=1e-9)


def test_rolling_friction_torque_plateau(tmp_path):
    """A sphere spinning on a wall (no sliding): rolling torque magnitude mu_r |F_n| R."""
    mats, contacts = gm.two_materials()
    contacts[(0, 1)] = gm.law_for(mats[0], mats[1], 0.8, 0.0, 0.05)     # frictionless: pure rolling resistance
    r, delta = 0.0005, 1e-6
    sph = gm.spheres([[0, 0, r - delta]], r, [0], mats, w=[[0, 200.0, 0]])
    m = gm.model(sph, mats, contacts, dt=1e-8, t_end=2e-6, save_every_steps=100)
    gm.add_geometry(m, "floor", gm.rect_triangles([[-0.01, -0.01, 0], [0.01, -0.01, 0],
                                                   [0.01, 0.01, 0], [-0.01, 0.01, 0]]), 1)
    m.spheres.mass[:] *= 1e6      # heavy: keeps the overlap; inertia scales with it
    _, frames = run(m, tmp_path)
    I = 0.4 * m.spheres.mass[0] * r * r
    es, _ = hertz_effective(mats[0], mats[1])
    # angular deceleration over the last interval = torque / I
    f1, f2 = frames[-2], frames[-1]
    torque = -(f2.omega[0, 1] - f1.omega[0, 1]) / (f2.time - f1.time) * I
    dz = r - f2.position[0, 2]
    expect = 0.05 * hertz(es, r, dz) * r
    print(f"\nrolling torque {torque!r} vs mu_r F_n R = {expect!r}")
    assert torque == pytest.approx(expect, rel=1e-3)


# ---------------------------------------------------------------------------------------
def _bonded_pair(tmp_path, v_rel, steps, dt=1e-8, name="bond", breakage=1, gap=1.0001, flip=False):
    glass = gm.material("Glass", **{**gm.GLASS, "density": 1e20})
    es, gs = hertz_effective(glass, glass)
    contacts = {(0, 0): ContactLaw(es, gs, 0.9, 0.45, 0.0)}
    r, d = 0.0004, 0.0006
    L0 = 2 * r * gap
    sph = gm.spheres([[0, 0, 0], [L0, 0, 0]], r, [0, 0], [glass],
                     v=[[-v_rel / 2, 0, 0], [v_rel / 2, 0, 0]])
    model = gm.model(sph, [glass], contacts, dt=dt, t_end=steps * dt, save_every_steps=max(1, steps // 10),
                     bond_breakage=breakage)
    model.bonds = gm.bonds([[1, 0]] if flip else [[0, 1]], d, L0)
    job, frames = run(model, tmp_path, name)
    return job, frames, glass, d, L0


@pytest.mark.parametrize("flip", [False, True])
def test_bond_axial_stiffness(tmp_path, flip):
    """F_n = E A / L0 (L - L0) for a solid bond stretched along its axis."""
    job, frames, glass, d, L0 = _bonded_pair(tmp_path, 1e-3, 100, flip=flip)
    A = math.pi * d * d / 4
    f = frames[-1]
    stretch = (f.position[1, 0] - f.position[0, 0]) - L0
    expect = glass.youngs * A / L0 * stretch
    print(f"\nbond: stretch {stretch!r} m, force on sphere 2 {f.force[1, 0]!r} N, EA/L0 dL {expect!r} N")
    assert stretch > 0
    assert -f.force[1, 0] == pytest.approx(expect, rel=1e-6)
    assert f.bond_alive.tolist() == [True]
    # bond force reported on the bond's first sphere (sphere 0 is pulled towards +x); a MUSEN
    # result saves the previous evaluation's, as cmusen does (docs/musen.md, "Saved bonds are
    # cmusen's too"): the stretch one step before (heavy spheres: constant velocities)
    first_sign = -1.0 if flip else 1.0
    before = stretch - (f.velocity[1, 0] - f.velocity[0, 0]) * job.dt
    assert 0 < before < stretch
    saved = glass.youngs * A / L0 * before
    assert f.bond_force[0, 0] == pytest.approx(first_sign * saved, rel=1e-6)
    assert np.abs(f.bond_force[0, 1:]).max() < 1e-12 * saved


def test_bond_breaks_at_normal_strength(tmp_path):
    """Pure tension: the bond breaks in the first step where E A / L0 (L - L0) >= sigma_n A."""
    v, dt = 0.05, 1e-8
    glass = gm.GLASS
    crit = glass["normal_strength"] * 0.0008 * 1.0001 / glass["youngs"]      # sigma_n L0 / E
    steps = int(crit / (v * dt) * 1.5)
    job, frames, mat, d, L0 = _bonded_pair(tmp_path, v, steps, dt=dt)
    assert job.breaks is not None
    last = frames[-1]
    assert last.bond_alive.tolist() == [False]
    t_break = last.bond_end_time[0]
    # stretch at step k (velocity Verlet, constant velocity: heavy spheres) = v k dt
    k_expected = math.ceil(crit / (v * dt) - 1e-9)
    print(f"\nbreak at t = {t_break!r}  expected step {k_expected} (t = {k_expected * dt!r})")
    assert abs(t_break / dt - k_expected) <= 1
    before = [f for f in frames if f.time < t_break]
    after = [f for f in frames if f.time >= t_break]
    assert all(f.bond_alive[0] for f in before) and not any(f.bond_alive[0] for f in after)
    assert np.abs(after[-1].force).max() == 0.0            # nothing holds the spheres together


def test_bond_no_breakage(tmp_path):
    v, dt = 0.05, 1e-8
    crit = gm.GLASS["normal_strength"] * 0.0008 / gm.GLASS["youngs"]
    steps = int(crit / (v * dt) * 1.5)
    job, frames, mat, d, L0 = _bonded_pair(tmp_path, v, steps, dt=dt, breakage=0, name="nobreak")
    assert job.breaks is None
    assert frames[-1].bond_alive.tolist() == [True]


@pytest.mark.parametrize("bonded_contacts", [True, False])
def test_contacts_between_bonded_spheres(tmp_path, bonded_contacts):
    """MUSEN computes Hertz contacts between bonded spheres by default (overlay/pair yes);
    with the flag off only the bond acts (here unstretched: no force at all)."""
    glass = gm.material("Glass", **gm.GLASS)
    es, gs = hertz_effective(glass, glass)
    r, delta = 0.0004, 1e-6
    sph = gm.spheres([[0, 0, 0], [2 * r - delta, 0, 0]], r, [0, 0], [glass])
    model = gm.model(sph, [glass], {(0, 0): ContactLaw(es, gs, 0.9, 0.45, 0.0)}, dt=1e-8, t_end=0.0,
                     contacts_between_bonded=bonded_contacts)
    model.bonds = gm.bonds([[0, 1]], 0.0006, 2 * r - delta)
    _, frames = run(model, tmp_path)
    expect = hertz(es, r / 2, delta) if bonded_contacts else 0.0
    assert frames[0].force[1, 0] == pytest.approx(expect, rel=1e-9, abs=1e-12)


def test_bond_coefficients_and_binning(tmp_path):
    """Stock styles (bpm/rotational): bond_coeff values and the (material, d, L0) binning to
    0.1 %.  (fibrelmp's musen/elastic keeps every bond's own d and L0:
    tests/test_style_musen_bond.py.)"""
    from fibrelmp import lammps_styles

    glass = gm.material("Glass", **gm.GLASS)
    es, gs = hertz_effective(glass, glass)
    contacts = {(0, 0): ContactLaw(es, gs, 0.9, 0.45, 0.0)}
    x = np.array([[0, 0, 0], [0.0008, 0, 0], [0.0016, 0, 0], [0.0024, 0, 0]])
    sph = gm.spheres(x, 0.0004, [0] * 4, [glass])
    model = gm.model(sph, [glass], contacts, dt=1e-8, t_end=0.0)
    model.bonds = gm.bonds([[0, 1], [1, 2], [2, 3]], 0.0006, [0.0008, 0.00080001, 0.0009])
    with lammps_styles.stock(True):
        job = write_granular_job(model, tmp_path / "coeffs")
    assert any(k == "approximate MUSEN physics" and "sum of four load ratios" in w for k, w in model.warnings)
    lines = [ln.split() for ln in job.script.read_text().splitlines() if ln.startswith("bond_coeff")]
    assert len(lines) == 2                          # 0.0008 and 0.00080001 share a type
    d, L0 = 0.0006, 0.0009
    A, I = math.pi * d * d / 4, math.pi * d ** 4 / 64
    G = glass.shear_modulus
    got = [float(v) for v in lines[1][2:]]
    expect = [glass.youngs * A / L0, G * A / L0, 2 * G * I / L0, glass.youngs * I / L0,
              5e7 * A, 5e7 * A, 5e7 * math.pi * d ** 3 / 32, 5e7 * math.pi * d ** 3 / 16, 0, 0, 0, 0]
    assert got == pytest.approx(expect, rel=1e-12)
    data = job.data.read_text()
    assert "\nBonds\n\n1 1 1 2\n2 1 2 3\n3 2 3 4\n" in data


# ---------------------------------------------------------------------------------------
def _cmusen_loop(dt: float, t_end: float, saving: float) -> tuple[list[int], list[float]]:
    """cmusen's clock written out step by step (BaseSimulator::StartSimulation /
    PreCalculationStep): t += dt, save when |t - t_last| + 0.1 dt > saving step, stop after
    the step reaching END_TIME and save there too."""
    t, last, n, steps, times = 0.0, 0.0, 0, [0], [0.0]
    while True:
        if n > 0 and abs(t - last) + 0.1 * dt > saving:
            steps.append(n)
            times.append(t)
            last = t
        t += dt
        n += 1
        if t >= t_end:
            steps.append(n)
            times.append(t)
            return steps, times


def test_free_flight_gravity_is_musens_leapfrog(tmp_path):
    """MUSEN's integrator under a constant force, in closed form: the prediction step gives
    v = v0 + g dt/2, each step v += g dt then x += v dt, so at step n the saved velocity is
    v0 + g dt (n + 1/2) and x = x0 + v0 t + g dt^2 (n^2/2 + n); saved at cmusen's steps and
    summed times."""
    glass = gm.material("Glass", **gm.GLASS)
    es, gs = hertz_effective(glass, glass)
    contacts = {(0, 0): ContactLaw(es, gs, 0.9, 0.45, 0.0)}
    x0, v0, g = np.array([0.001, 0.002, 0.003]), np.array([0.3, -0.2, 1.0]), np.array([0.5, 0.0, -9.81])
    sph = gm.spheres([x0], 0.0005, [0], [glass], v=[v0])
    dt = 1e-5
    model = gm.model(sph, [glass], contacts, dt=dt, t_end=0.1, save_every_time=0.0123, gravity=g)
    job, frames = run(model, tmp_path)
    steps, times = _cmusen_loop(dt, 0.1, 0.0123)
    assert [f.step for f in frames] == list(job.save_steps) == steps
    assert steps[:4] == [0, 1230, 2460, 3690]
    assert [f.time for f in frames] == times
    for f in frames[1:]:
        n, t = f.step, f.time
        assert f.position[0] == pytest.approx(x0 + v0 * t + g * dt * dt * (n * n / 2 + n), abs=1e-12)
        assert f.velocity[0] == pytest.approx(v0 + g * dt * (n + 0.5), abs=1e-12)
        assert f.force[0] == pytest.approx(model.spheres.mass[0] * g, rel=1e-12)
    assert frames[0].velocity[0] == pytest.approx(v0, abs=0)      # saved before the prediction


def test_quaternion_stays_as_musen_keeps_it(tmp_path):
    """MUSEN turns orientations only with anisotropy (CCPUSimulator::MoveParticles), which is
    not simulated: a spinning free sphere keeps its quaternion and its spin."""
    glass = gm.material("Glass", **gm.GLASS)
    es, gs = hertz_effective(glass, glass)
    contacts = {(0, 0): ContactLaw(es, gs, 0.9, 0.45, 0.0)}
    q0 = np.array([[math.cos(0.3), math.sin(0.3), 0.0, 0.0]])
    w = 50.0
    sph = gm.spheres([[0, 0, 0]], 0.0005, [0], [glass], w=[[0, 0, w]], q=q0)
    model = gm.model(sph, [glass], contacts, dt=1e-5, t_end=0.01, save_every_steps=250)
    _, frames = run(model, tmp_path)
    assert len(frames) > 2
    for f in frames:
        assert f.quaternion[0] == pytest.approx(q0[0], abs=1e-15)
        assert f.omega[0] == pytest.approx([0, 0, w], abs=0)


def test_bad_contact_parameters_raise(tmp_path):
    glass = gm.material("Glass", **gm.GLASS)
    sph = gm.spheres([[0, 0, 0]], 0.0005, [0], [glass])
    model = gm.model(sph, [glass], {(0, 0): ContactLaw(1e10, 4e9, 0.0, 0.3)}, dt=1e-8, t_end=0.0)
    with pytest.raises(InputError, match="restitution"):
        write_granular_job(model, tmp_path / "bad")
    model.contacts = {}
    with pytest.raises(InputError, match="no contact parameters"):
        write_granular_job(model, tmp_path / "bad2")


def test_frictionless_and_explicit_kt_paths():
    """G* = 0 -> no tangential force; G*/E* outside (0, 1/3) -> k_t = 8 G* given explicitly."""
    assert "linear_nohistory 0.0 0.0" in law_args(ContactLaw(1e9, 0.0, 0.5, 0.3), 0, 1, 1)
    args = law_args(ContactLaw(1e9, 5e8, 0.5, 0.3), 0, 1, 1).split()
    assert float(args[1]) == 2e9 and float(args[3]) == 0.0 and float(args[6]) == 4e9


def test_large_agglomerate_translation_is_fast(tmp_path):
    """5,696 spheres + 18,802 bonds (the size of MUSEN's SphericalAgglomerate) translate fast."""
    rng = np.random.default_rng(1)
    n, m = 5696, 18802
    glass = gm.material("Glass", **gm.GLASS)
    es, gs = hertz_effective(glass, glass)
    x = rng.uniform(-0.01, 0.01, (n, 3))
    sph = gm.spheres(x, 0.0004, np.zeros(n, np.int64), [glass])
    model = gm.model(sph, [glass], {(0, 0): ContactLaw(es, gs, 0.9, 0.45, 0.05)}, dt=1e-8,
                     t_end=1e-6, domain=(np.full(3, -0.011), np.full(3, 0.011)))
    pairs = np.stack([rng.integers(0, n, m), rng.integers(0, n, m)], 1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    model.bonds = gm.bonds(pairs, 0.0006, rng.uniform(0.0008, 0.0013, len(pairs)))
    t0 = time.perf_counter()
    job = write_granular_job(model, tmp_path / "big")
    elapsed = time.perf_counter() - t0
    print(f"\ntranslate {n} spheres + {len(pairs)} bonds: {elapsed:.3f} s")
    assert elapsed < 2.0
    text = job.data.read_text()
    assert f"{n} atoms" in text and f"{len(pairs)} bonds" in text
