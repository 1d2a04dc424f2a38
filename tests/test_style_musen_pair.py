"""``pair_style musen/hm`` (fibrelmp's plugin) against MUSEN's particle-particle Hertz-Mindlin
law, re-written here from MUSEN's code (commit e0ff360), independently of the C++ style:

* ``Models/ParticleParticle/HertzMindlin/ModelPPHertzMindlin.cpp`` (CalculatePP, Consolidate*)
* ``Modules/SimplifiedScene/SimplifiedScene.cpp`` (CalculateInteractionProperty: E*, G*, dAlpha)
* ``Modules/Simulator/CollisionsCalculator.cpp`` (CheckPPCollision: when a contact exists,
  overlap, contact vector dst - src, R* from the contact radii, m*; a new contact starts with
  zero tangential overlap, a contact that stops overlapping is dropped)
* ``Modules/GeneralSources/Vector3.h`` (vector * vector is the cross product; IsSignificant is
  "some |component| > 1e-100"; Normalized divides by the length)

LAMMPS is driven step by step through ``fix external`` (its callback runs after the pair
forces of a step, with the positions and the half-step velocities the pair saw); the
reference carries its own tangential overlap from step to step, so a wrong history would show
up as wrong forces.  Measured: every force and torque equal to the reference bit for bit
(asserted to 1e-12 of the largest component).
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tests.conftest import styles_or_skip
from tests.test_mpi import MPIEXEC
from fibrelmp._lammps import new_lammps

from .conftest import data_path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent

# ---------------------------------------------------------------- MUSEN, re-written in Python

PI = 3.14159265358979323846          # MUSENDefinitions.h
TWO_SQRT_5_6 = 1.825741858350553711523232609336


class V:
    """MUSEN's CVector3 (Vector3.h): the same operations in the same order."""

    __slots__ = ("x", "y", "z")

    def __init__(self, x, y=None, z=None):
        if y is None:
            x, y, z = (x, x, x) if not hasattr(x, "__len__") else x
        self.x, self.y, self.z = float(x), float(y), float(z)

    def __add__(self, o):
        return V(self.x + o.x, self.y + o.y, self.z + o.z)

    def __sub__(self, o):
        return V(self.x - o.x, self.y - o.y, self.z - o.z)

    def __mul__(self, o):
        if isinstance(o, V):        # cross product
            return V(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
        return V(self.x * o, self.y * o, self.z * o)

    def __rmul__(self, d):          # double * vector
        return V(self.x * d, self.y * d, self.z * d)

    def __truediv__(self, d):
        return V(self.x / d, self.y / d, self.z / d)

    def length(self):
        return math.sqrt(self.x * self.x + self.y * self.y + self.z * self.z)

    def squared_length(self):
        return self.x * self.x + self.y * self.y + self.z * self.z

    def significant(self):
        return abs(self.x) > 1e-100 or abs(self.y) > 1e-100 or abs(self.z) > 1e-100

    def normalized(self):
        n = math.sqrt(self.x * self.x + self.y * self.y + self.z * self.z)
        return self / n if n != 0 else V(0.0)

    def arr(self):
        return np.array([self.x, self.y, self.z])


def dot(a, b):
    return a.x * b.x + a.y * b.y + a.z * b.z


@dataclass
class Material:
    E: float
    nu: float


@dataclass
class Interaction:
    """SInteractProps of one material pair (CalculateInteractionProperty)."""
    e_star: float
    g_star: float
    rest: float
    alpha: float
    mu: float
    mu_r: float


def interaction(m1: Material, m2: Material, rest: float, mu: float, mu_r: float) -> Interaction:
    alpha = math.log(rest) / math.sqrt(PI * PI + math.pow(math.log(rest), 2))
    g1 = m1.E / (2 * (1 + m1.nu))
    g2 = m2.E / (2 * (1 + m2.nu))
    e_star = 1.0 / ((1 - math.pow(m1.nu, 2)) / m1.E + (1 - math.pow(m2.nu, 2)) / m2.E)
    g_star = 1.0 / ((2 - m1.nu) / g1 + (2 - m2.nu) / g2)
    return Interaction(e_star, g_star, rest, alpha, mu, mu_r)


@dataclass
class Sphere:
    x: V
    v: V
    w: V
    r: float
    m: float


@dataclass
class Contact:
    """SCollision (the fields CalculatePP reads and writes)."""
    contact_vector: V
    normal_overlap: float
    equiv_radius: float
    equiv_mass: float
    tang_overlap: V


def check_pp(src: Sphere, dst: Sphere, old: Contact | None) -> Contact | None:
    """CheckPPCollision: the contact of this step (a new one starts with zero tangential
    overlap), or None when the spheres do not overlap (MUSEN drops the contact)."""
    cv = dst.x - src.x
    d2 = cv.squared_length()
    if not ((src.r + dst.r) * (src.r + dst.r) > d2):
        return None
    if old is None:
        old = Contact(V(0.0), 0.0, src.r * dst.r / (src.r + dst.r), src.m * dst.m / (src.m + dst.m), V(0.0))
    old.normal_overlap = src.r + dst.r - math.sqrt(d2)
    old.contact_vector = cv
    return old


def calculate_pp(src: Sphere, dst: Sphere, p: Interaction, c: Contact, dt: float):
    """CalculatePP: (total force on src, moment on src, moment on dst, slipping); updates
    c.tang_overlap."""
    w1, w2 = src.w, dst.w
    r1, r2 = src.r, dst.r
    rc1 = c.contact_vector * (r1 / (r1 + r2))
    rc2 = c.contact_vector * (-r2 / (r1 + r2))
    n = c.contact_vector.normalized()
    rel = (dst.v + w2 * rc2) - (src.v + w1 * rc1)
    vn = dot(n, rel)
    vt = rel - vn * n
    a = math.sqrt(c.equiv_radius * c.normal_overlap)
    kn = 2 * p.e_star * a
    fn_el = -c.normal_overlap * kn * 2. / 3.
    fn_damp = -TWO_SQRT_5_6 * p.alpha * vn * math.sqrt(kn * c.equiv_mass)
    fn = n * (fn_el + fn_damp)
    rot = c.tang_overlap - n * dot(n, c.tang_overlap)
    if rot.significant():
        rot = rot * (c.tang_overlap.length() / rot.length())     # tangOverlapRot *= ...
    xi = rot + vt * dt
    kt = 8 * p.g_star * a
    shear = xi * kt
    damping = vt * (-TWO_SQRT_5_6 * p.alpha * math.sqrt(kt * c.equiv_mass))
    shear_len = shear.length()
    friction = p.mu * abs(fn_el + fn_damp)
    slip = shear_len > friction
    if slip:
        ft = shear * friction / shear_len
        xi = ft / kt
    else:
        ft = shear + damping
    roll1 = w1 * (-p.mu_r * abs(fn_el) * r1 / w1.length()) if w1.significant() else V(0.0)
    roll2 = w2 * (-p.mu_r * abs(fn_el) * r2 / w2.length()) if w2.significant() else V(0.0)
    total = fn + ft
    m1 = n * ft * r1 + roll1
    m2 = n * ft * r2 + roll2
    c.tang_overlap = xi
    return total, m1, m2, slip


# ---------------------------------------------------------------- LAMMPS driver

GLASS = Material(5e10, 0.22)          # the oblique scenario's materials
STEEL = Material(2.1e11, 0.29)
RHO = {"glass": 2500.0, "steel": 7800.0}


def coeff_line(i: int, j: int, p: Interaction) -> str:
    return f"pair_coeff {i} {j} {p.e_star!r} {p.g_star!r} {p.rest!r} {p.mu!r} {p.mu_r!r}"


@dataclass
class Body:
    kind: str           # glass / steel (type 1 / 2)
    r: float
    x: tuple
    v: tuple
    w: tuple = (0.0, 0.0, 0.0)


def body_commands(bodies: list[Body]) -> list[str]:
    """create_atoms / set commands of ``bodies`` (type 1 glass, 2 steel; ids from 1)."""
    cmds = []
    for k, b in enumerate(bodies):
        t = 1 if b.kind == "glass" else 2
        cmds += [f"create_atoms {t} single {b.x[0]!r} {b.x[1]!r} {b.x[2]!r} units box remap yes",
                 f"set atom {k + 1} diameter {2 * b.r!r} density {RHO[b.kind]!r}",
                 f"set atom {k + 1} vx {b.v[0]!r} vy {b.v[1]!r} vz {b.v[2]!r}",
                 f"set atom {k + 1} omega {b.w[0]!r} {b.w[1]!r} {b.w[2]!r}"]
    return cmds


def setup_lammps(plugin: Path, bodies: list[Body], laws: dict, dt: float, *, periodic=False,
                 box=0.02, center=None, newton="off", extra=(), log=None):
    """LAMMPS with the plugin, ``bodies`` (type 1 glass, 2 steel) in a cube of half-side
    ``box`` around ``center`` (default: the first body), and the musen/hm coefficients."""
    lmp = new_lammps(["-log", "none", "-screen", str(log) if log else "none", "-nocite"])
    bnd = "p p p" if periodic else "f f f"
    cmds = [f"plugin load {plugin}", "units si", "atom_style sphere", f"boundary {bnd}",
            f"newton {newton}", "comm_modify vel yes", "atom_modify map array",
            "region box block {} {} {} {} {} {}".format(
                *(c + s * box for c in (bodies[0].x if center is None else center) for s in (-1, 1))),
            "create_box 2 box"]
    cmds += body_commands(bodies)
    cmds += ["pair_style musen/hm"] + [coeff_line(i, j, p) for (i, j), p in laws.items()]
    cmds += ["neighbor 0.0005 bin", "neigh_modify every 1 delay 0 check yes",
             f"timestep {dt!r}", "fix integrate all nve/sphere", *extra]
    for c in cmds:
        lmp.command(c)
    return lmp


def default_laws(mu_gg=0.45, mu_r_gg=0.05):
    return {(1, 1): interaction(GLASS, GLASS, 0.9, mu_gg, mu_r_gg),
            (2, 2): interaction(STEEL, STEEL, 0.9, 0.2, 0.01),
            (1, 2): interaction(GLASS, STEEL, 0.85, 0.15, 0.01)}


class Recorder:
    """fix external callback: the reference forces of every step from the state the pair saw."""

    def __init__(self, lmp, laws, dt, period=None, push=None):
        self.lmp, self.laws, self.dt = lmp, laws, dt
        self.push = push or {}      # sphere index -> constant force added after the pair's
        self.period = None if period is None else np.broadcast_to(np.asarray(period, float), (3,))
        self.contacts: dict[tuple[int, int], Contact] = {}
        self.setup = True
        self.worst = 0.0
        self.steps = self.contact_steps = self.slip_steps = self.stick_steps = 0
        self.ghost_pairs = 0        # pair computations with a periodic image
        self.states = []

    def __call__(self, caller, step, nlocal, tag, x, fext):
        L = self.lmp.numpy
        v, w = L.extract_atom("v")[:nlocal], L.extract_atom("omega")[:nlocal]
        f, t = L.extract_atom("f")[:nlocal], L.extract_atom("torque")[:nlocal]
        r, m = L.extract_atom("radius")[:nlocal], L.extract_atom("rmass")[:nlocal]
        typ = L.extract_atom("type")[:nlocal]
        order = np.argsort(tag)
        sph = [Sphere(V(x[k]), V(v[k]), V(w[k]), float(r[k]), float(m[k])) for k in order]
        kinds = [int(typ[k]) for k in order]
        ref_f = [V(0.0) for _ in sph]
        ref_t = [V(0.0) for _ in sph]
        self.states.append((step, np.array(x)[order].copy(), np.array(v)[order].copy(),
                            np.array(w)[order].copy()))
        for a in range(len(sph)):
            for b in range(len(sph)):
                dst, own = sph[b], False
                if self.period is not None:
                    # a ghost image, as LAMMPS's borders make it (x + xprd): each side
                    # computes the pair for its own sphere only
                    shift = np.round((dst.x - sph[a].x).arr() / self.period)
                    if shift.any():
                        dst = Sphere(V(x[order[b]] - shift * self.period), dst.v, dst.w, dst.r, dst.m)
                        own = True
                if b == a or (b < a and not own):
                    continue
                key = (a, b)
                c = check_pp(sph[a], dst, self.contacts.get(key))
                if c is None:
                    self.contacts.pop(key, None)
                    continue
                self.ghost_pairs += own
                law = self.laws[(min(kinds[a], kinds[b]), max(kinds[a], kinds[b]))]
                saved = c.tang_overlap
                total, m1, m2, slip = calculate_pp(sph[a], dst, law, c, self.dt)
                if self.setup:          # LAMMPS's setup force: the history is not advanced
                    c.tang_overlap = saved
                    if key not in self.contacts:
                        c = None
                else:
                    self.contact_steps += 1
                    self.slip_steps += slip
                    self.stick_steps += not slip
                if c is not None:
                    self.contacts[key] = c
                ref_f[a] += total
                ref_t[a] += m1
                if not own:
                    ref_f[b] -= total
                    ref_t[b] += m2
        for k, force in self.push.items():
            ref_f[k] += V(force)
        for k, idx in enumerate(order):
            for got, want in ((f[idx], ref_f[k].arr()), (t[idx], ref_t[k].arr())):
                scale = max(np.abs(want).max(), 1e-300)
                self.worst = max(self.worst, float(np.abs(got - want).max() / scale))
        self.setup = False
        self.steps += 1


def by_tag(lmp, name):
    n = lmp.extract_global("nlocal")
    order = np.argsort(lmp.numpy.extract_atom("id")[:n])
    return lmp.numpy.extract_atom(name)[:n][order].copy()


def drive(lmp, rec: Recorder, nsteps: int, chunks: int = 1):
    lmp.command("fix ext all external pf/callback 1 1")
    lmp.set_fix_external_callback("ext", rec)
    per = nsteps // chunks
    for _ in range(chunks):
        rec.setup = True
        lmp.command(f"run {per} post no")


def collide(plugin, bodies, laws=None, dt=5e-8, nsteps=400, chunks=1, **kw):
    laws = laws or default_laws()
    lmp = setup_lammps(plugin, bodies, laws, dt, **kw)
    rec = Recorder(lmp, laws, dt, 2 * kw["box"] if kw.get("periodic") else None)
    try:
        drive(lmp, rec, nsteps, chunks)
        final = tuple(by_tag(lmp, name) for name in ("x", "v", "omega"))
    finally:
        lmp.close()
    return rec, final


CASES = {
    # glass hit head-on by a smaller steel sphere
    "normal_glass_steel": [Body("glass", 1e-3, (0, 0, 0), (0, 0, 0)),
                           Body("steel", 0.75e-3, (1.76e-3, 0, 0), (-2.0, 0, 0))],
    # oblique, both spinning, different radii and materials: slip and stick phases
    "oblique_spinning": [Body("glass", 1e-3, (0, 0, 0), (0.1, 0, 0), (0, 0, 300.0)),
                         Body("steel", 0.75e-3, (1.5e-3, 0.9e-3, 0.1e-3), (-1.5, -0.2, 0.3),
                              (200.0, -100.0, 50.0))],
    # the oblique scenario's spinning glass sphere hit by another glass sphere
    "spinning_partner": [Body("glass", 1e-3, (0, 0, 0), (0, 0, 0), (0, 0, 1000.0)),
                         Body("glass", 1e-3, (-1.205e-3, -1.6e-3, 0), (1.5, 0, 0))],
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_forces_and_torques_equal_musen(case):
    plugin = styles_or_skip()
    rec, _ = collide(plugin, CASES[case], nsteps=500)
    assert rec.contact_steps > 100, f"the spheres must collide ({rec.contact_steps} contact steps)"
    assert rec.worst <= 1e-12, f"largest relative difference {rec.worst:.3g}"
    if case == "oblique_spinning":
        assert rec.slip_steps > 5 and rec.stick_steps > 5, (rec.slip_steps, rec.stick_steps)


def test_both_atom_orders_give_the_same_trajectory():
    """MUSEN's law is antisymmetric in IEEE arithmetic: swapping which sphere is atom 1 gives
    the same trajectory bit for bit."""
    plugin = styles_or_skip()
    bodies = CASES["oblique_spinning"]
    _, (x1, v1, w1) = collide(plugin, bodies, nsteps=500)
    rec, (x2, v2, w2) = collide(plugin, bodies[::-1], nsteps=500)
    assert rec.worst <= 1e-12
    np.testing.assert_array_equal(x1, x2[::-1])
    np.testing.assert_array_equal(v1, v2[::-1])
    np.testing.assert_array_equal(w1, w2[::-1])


def test_contact_across_a_periodic_boundary_is_computed_from_both_sides():
    """Across a periodic boundary each sphere meets a ghost image of the other: the pair is
    computed once from each side, each keeping its own history entry; both must agree with
    MUSEN and with the same collision inside the box."""
    plugin = styles_or_skip()
    box = 0.004
    inside = CASES["oblique_spinning"]
    shift = np.array([box - 0.8e-3, 0.0, 0.0])
    across = [Body(b.kind, b.r, tuple(float(c) for c in np.add(b.x, shift)), b.v, b.w) for b in inside]
    rec, (xa, va, wa) = collide(plugin, across, nsteps=500, periodic=True, box=box, center=(0, 0, 0))
    assert rec.contact_steps > 100 and rec.worst <= 1e-12
    assert rec.ghost_pairs > 100
    _, (xi, vi, wi) = collide(plugin, inside, nsteps=500, periodic=True, box=box, center=(0, 0, 0))
    np.testing.assert_allclose(va, vi, rtol=0, atol=1e-12)
    np.testing.assert_allclose(wa, wi, rtol=0, atol=1e-9)


def test_history_survives_many_runs_and_setups():
    """A collision cut into 10 runs: LAMMPS recomputes forces at each run's setup, which must
    not advance the tangential overlap (the reference does not either)."""
    plugin = styles_or_skip()
    laws = default_laws()
    lmp = setup_lammps(plugin, CASES["oblique_spinning"], laws, 5e-8)
    rec = Recorder(lmp, laws, 5e-8)
    try:
        drive(lmp, rec, 500, chunks=10)
    finally:
        lmp.close()
    assert rec.contact_steps > 100 and rec.worst <= 1e-12


# ---------------------------------------------------------------- the oblique scenario's pairs

def cmusen_state(tmp_path, ids, t):
    """Velocities and angular velocities of MUSEN objects ``ids`` at time ``t`` in the real
    cmusen result of the oblique scenario (17 digits)."""
    import gzip

    from fibrelmp.translate.musen.text import read_time_points

    src = data_path("real-outputs", "musen", "scenarios", "oblique_two_materials",
                    "cmusen_oblique_result_prec17.txt.gz")
    plain = tmp_path / "cmusen.txt"
    with gzip.open(src, "rb") as f:
        plain.write_bytes(f.read())
    tp = read_time_points(plain, types=(1,), tags=(15, 16))
    k = int(np.argmin(np.abs(tp.times - t)))
    rows = [list(tp.ids).index(i) for i in ids]
    return tp.fields[15][k, rows], tp.fields[16][k, rows]


# oblique_scene.txt, objects 10/11 and 12/13 (position, velocity, angular velocity)
SCENARIO_PAIRS = {
    "glass_hit_by_steel": ((10, 11), [
        Body("glass", 1e-3, (-0.1, -0.055, 0.015), (0, 0, 0)),
        Body("steel", 0.75e-3, (-0.10161554445662277, -0.055, 0.015875), (2.0, 0, 0))]),
    "spinning_glass_hit_by_glass": ((12, 13), [
        Body("glass", 1e-3, (-0.1, 0.055, 0.015), (0, 0, 0), (0, 0, 1000.0)),
        Body("glass", 1e-3, (-0.10130000000000002, 0.0534, 0.015), (1.5, 0, 0))]),
}


@pytest.mark.parametrize("case", sorted(SCENARIO_PAIRS))
def test_scenario_pairs_as_in_cmusen(tmp_path, case):
    """The free-flight pairs of shared/real-outputs/musen/scenarios/oblique_two_materials, run
    alone for 1 ms (the collision is over) and compared with the real cmusen run.
    12/13: a glass sphere spinning at 1000 rad/s about z hit by a glass sphere at 1.5 m/s
    (impact parameter 0.8 * 2R): MUSEN brakes each sphere's own spin, so the partner leaves
    with 6.77 rad/s (stock `rolling sds`, acting on the relative rolling, gave 126 rad/s).
    Measured: omega within 4e-8 rad/s of cmusen's; velocities within 2.5e-7 m/s, which is
    g dt / 2 (MUSEN saves the half-step velocity of its leapfrog, LAMMPS the full step), the
    other components within 1e-11 m/s."""
    plugin = styles_or_skip()
    ids, bodies = SCENARIO_PAIRS[case]
    # the scene's own coordinates: 10/11 start exactly 1000 steps before touching, so a
    # shifted origin changes by round-off the step the contact starts at (0.003 rad/s after)
    lmp = setup_lammps(plugin, bodies, default_laws(), 5e-8,
                       extra=["fix g all gravity 9.81 vector 0 0 -1"])
    try:
        lmp.command("run 20000 post no")             # t = 1 ms
        v, w = by_tag(lmp, "v"), by_tag(lmp, "omega")
    finally:
        lmp.close()
    v_ref, w_ref = cmusen_state(tmp_path, ids, 1e-3)
    np.testing.assert_allclose(w, w_ref, rtol=0, atol=1e-6)
    g_half_step = 9.81 * 5e-8 / 2
    np.testing.assert_allclose(v[:, :2], v_ref[:, :2], rtol=0, atol=1e-10)
    np.testing.assert_allclose(v[:, 2] - g_half_step, v_ref[:, 2], rtol=0, atol=1e-10)


# ---------------------------------------------------------------- migration, MPI, restart

# Two contacts on a periodic box split between 2 processors along y (processors 1 2 1):
# A) a glass and a steel sphere held together by a spring between their centres (fix spring
#    couple, ~1 N), orbiting each other (5 m/s relative) and spinning against each other
#    (slip, then stick, rolling friction), drifting at 20 m/s along y: the contact crosses the
#    periodic and the processor boundary, and the orbit swaps the spheres' local order when
#    LAMMPS sorts atoms (every 50 steps), so either atom ends up computing the pair;
# B) an oblique glass-glass collision right at the processor boundary.
# Each sphere has one contact, so its force is one pair term (+ the spring): the sums have no
# order to depend on, and the serial and 2-rank runs must agree bit for bit.
_D = 1.7495e-3                                  # centre distance of A (overlap 5e-7 m)
_M1, _M2 = 2500 * 4 / 3 * math.pi * 1e-9, 7800 * 4 / 3 * math.pi * 0.75e-3 ** 3
_U1 = 5.0 * _M2 / (_M1 + _M2)                   # orbit: zero momentum relative to the drift
_U2 = 5.0 - _U1
PERSISTENT = [
    Body("glass", 1e-3, (-2.0e-3 - _D * _M2 / (_M1 + _M2), 7.0e-3, 0.0), (0.0, 20.0 + _U1, 0.0),
         (0.0, 0.0, 300.0)),
    Body("steel", 0.75e-3, (-2.0e-3 + _D * _M1 / (_M1 + _M2), 7.0e-3, 0.0), (0.0, 20.0 - _U2, 0.0),
         (0.0, 0.0, -300.0)),
    Body("glass", 1e-3, (2.0e-3, -1.5e-3, 0.0), (0.0, 1.0, 0.0), (50.0, 0.0, 0.0)),
    Body("glass", 1e-3, (2.3e-3, 0.52e-3, 0.25e-3), (0.0, -1.0, 0.0)),
]
BOX = ((-4e-3, 4e-3), (-8e-3, 8e-3), (-2e-3, 2e-3))
HOLD = ["group a1 id 1", "group a2 id 2", f"fix hold a1 spring couple a2 {1.0 / _D!r} 0.0 0.0 0.0 0.0"]
STEPS = 6000
PERSISTENT_DT = 1e-7

CASE_SCRIPT = r"""
import sys, json
sys.path.insert(0, {root!r})
from tests.test_style_musen_pair import persistent_lammps, gathered
lmp = persistent_lammps({plugin!r}, procs={procs!r}, style={style!r})
lmp.command("run {steps} post no")
state = gathered(lmp)
lmp.close()
if state is not None:
    print("STATE", json.dumps(state))
"""


def persistent_lammps(plugin, procs=None, record=False, log=None, style="pair_style musen/hm"):
    """The two contacts above; ``record``: a fix external (for a Recorder) placed before the
    spring, so that it sees the pair forces alone; ``style``: the pair_style line."""
    laws = default_laws()
    lmp = new_lammps(["-log", "none", "-screen", str(log) if log else "none", "-nocite"])
    (xl, xh), (yl, yh), (zl, zh) = BOX
    cmds = [f"plugin load {plugin}", "units si", "atom_style sphere", "boundary p p p",
            "newton off", "comm_modify vel yes", "atom_modify map array sort 50 0.001"]
    if procs:
        cmds.append(f"processors {procs}")
    cmds += [f"region box block {xl} {xh} {yl} {yh} {zl} {zh}", "create_box 2 box"]
    cmds += body_commands(PERSISTENT)
    cmds += [style] + [coeff_line(i, j, p) for (i, j), p in laws.items()]
    cmds += ["neighbor 0.0005 bin", "neigh_modify every 1 delay 0 check yes",
             f"timestep {PERSISTENT_DT!r}", "fix integrate all nve/sphere"]
    if record:
        cmds.append("fix ext all external pf/callback 1 1")
    cmds += HOLD
    for c in cmds:
        lmp.command(c)
    return lmp


def gathered(lmp):
    """x, v, omega of every atom by id, on rank 0 (None elsewhere)."""
    out = {}
    for name in ("x", "v", "omega"):
        data = lmp.gather_atoms(name, 1, 3)
        out[name] = [float(c) for c in data]
    return out if lmp.extract_setting("world_rank") == 0 else None


def test_history_migrates_with_atoms_serial():
    """Serial run with atom sorting and periodic wrapping: the pair forces of every step equal
    MUSEN's (the reference keeps its own history), while the pressed contact is computed
    from the glass sphere's side, from the steel sphere's side, and across the boundary."""
    plugin = styles_or_skip()
    laws = default_laws()
    lmp = persistent_lammps(plugin, record=True)
    rec = Recorder(lmp, laws, PERSISTENT_DT, [hi - lo for lo, hi in BOX])
    swapped = []

    def record(caller, step, nlocal, tag, x, fext):
        rec(caller, step, nlocal, tag, x, fext)
        order = list(tag)
        swapped.append(order.index(2) < order.index(1))

    lmp.set_fix_external_callback("ext", record)
    try:
        rec.setup = True
        lmp.command(f"run {STEPS} post no")
    finally:
        lmp.close()
    assert rec.worst <= 1e-12, rec.worst
    assert rec.contact_steps >= STEPS                 # A never lets go
    assert rec.ghost_pairs > 100                      # A across the periodic boundary
    assert 100 < sum(swapped) < len(swapped) - 100    # A's atoms in both local orders
    assert rec.slip_steps >= 5 and rec.stick_steps > 1000, (rec.slip_steps, rec.stick_steps)


# several MUSEN laws on each contact (cmusen's several PP models; tests/test_musen_several_models.py)
SEVERAL_LAWS = "pair_style musen/hm then linear/elastic 30000.0 20000.0 then hertz/mindlin"


def _run_case(plugin, ranks, steps, tmp_path, style="pair_style musen/hm"):
    code = CASE_SCRIPT.format(root=str(ROOT), plugin=str(plugin), procs="1 2 1" if ranks else None,
                              steps=steps, style=style)
    cmd = ([MPIEXEC, "-n", str(ranks)] if ranks else []) + [sys.executable, "-c", code]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
    line = [ln for ln in proc.stdout.splitlines() if ln.startswith("STATE ")]
    assert len(line) == 1, proc.stdout
    import json
    return json.loads(line[0][6:])


@pytest.mark.skipif(not MPIEXEC, reason="mpiexec not found (pip install mpich)")
@pytest.mark.parametrize("style", ["pair_style musen/hm", SEVERAL_LAWS])
def test_serial_and_two_ranks_bitwise(tmp_path, style):
    """The contacts above under mpiexec -n 2 (each contact crosses the processor boundary;
    pairs with a ghost are computed on both ranks from each side): bit-identical to serial."""
    plugin = styles_or_skip()
    serial = _run_case(plugin, None, STEPS, tmp_path, style)
    two = _run_case(plugin, 2, STEPS, tmp_path, style)
    for name in ("x", "v", "omega"):
        assert serial[name] == two[name], name


@pytest.mark.parametrize("style", ["pair_style musen/hm", SEVERAL_LAWS])
def test_restart_round_trip(tmp_path, style):
    """write_restart in the middle of the pressed contact; a new LAMMPS reading it (and
    re-defining the fixes, not the pair style: the restart file keeps the laws) continues bit
    for bit as the original."""
    check_restart_round_trip(tmp_path, style)


def check_restart_round_trip(tmp_path: Path, style: str) -> None:
    """The pressed contact of ``persistent_lammps`` with ``style``, written to a restart file
    half-way: a new LAMMPS reading it (the fixes defined again, the pair style and its laws
    from the file) ends with the positions, velocities and spins of the run not stopped, bit
    for bit."""
    plugin = styles_or_skip()
    restart = tmp_path / "mid.restart"
    lmp = persistent_lammps(plugin, style=style)
    try:
        lmp.command(f"run {STEPS // 2} post no")
        lmp.command(f"write_restart {restart}")
        lmp.command(f"run {STEPS // 2} post no")
        straight = gathered(lmp)
    finally:
        lmp.close()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {plugin}", f"read_restart {restart}", "comm_modify vel yes",
                  "neighbor 0.0005 bin", "neigh_modify every 1 delay 0 check yes",
                  "fix integrate all nve/sphere", *HOLD[2:], f"run {STEPS // 2} post no"]:
            lmp.command(c)
        again = gathered(lmp)
    finally:
        lmp.close()
    for name in ("x", "v", "omega"):
        assert straight[name] == again[name], name


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize("change, message", [
    (("pair_coeff 1 2", None), "no pair_coeff for types 1 2"),
    (("pair_coeff 1 1", "pair_coeff 1 1 5e10 2e10 0.0 0.3 0.01"), "restitution coefficient e must be in (0, 1]"),
    (("pair_coeff 1 1", "pair_coeff 1 1 5e10 2e10 1.2 0.3 0.01"), "restitution coefficient e must be in (0, 1]"),
    (("pair_coeff 1 1", "pair_coeff 1 1 -5e10 2e10 0.9 0.3 0.01"), "Estar must be > 0"),
    (("pair_coeff 1 1", "pair_coeff 1 1 5e10 -1 0.9 0.3 0.01"), "Gstar must be >= 0"),
    (("pair_coeff 1 1", "pair_coeff 1 1 5e10 2e10 0.9 -0.3 0.01"), "mu must be >= 0"),
    (("pair_coeff 1 1", "pair_coeff 1 1 5e10 2e10 0.9 0.3 -1e-3"), "mu_r must be >= 0"),
    (("pair_coeff 1 1", "pair_coeff 1 1 5e10 2e10 0.9 0.3"), "pair_coeff I J Estar Gstar e mu mu_r"),
    (("comm_modify", "comm_modify vel no"), "comm_modify vel yes"),
    (("pair_style", "pair_style musen/hm 1.0"), "law hertz/mindlin takes no parameters"),
    (("pair_style", "pair_style musen/hm then"), "'then' needs a law name"),
    (("pair_style", "pair_style musen/hm then linear/elastic 1e3"), "linear/elastic needs Kn > 0 and Kt > 0"),
    (("pair_style", "pair_style musen/hm then nosuch"), "unknown particle-particle law nosuch"),
])
def test_bad_input_is_a_clear_error(change, message):
    plugin = styles_or_skip()
    laws = default_laws()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    cmds = [f"plugin load {plugin}", "units si", "atom_style sphere", "boundary f f f",
            "comm_modify vel yes", "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01",
            "create_box 2 box", "create_atoms 1 single 0 0 0", "create_atoms 2 single 0.0019 0 0",
            "set type 1 density 2500", "set type 2 density 7800", "pair_style musen/hm",
            *[coeff_line(i, j, p) for (i, j), p in laws.items()], "fix 1 all nve/sphere"]
    prefix, replacement = change
    cmds = [replacement if c.startswith(prefix) else c for c in cmds]
    cmds = [c for c in cmds if c is not None] + ["run 0 post no"]
    try:
        with pytest.raises(Exception, match=".*".join(map(re.escape, message.split()))):
            for c in cmds:
                lmp.command(c)
    finally:
        lmp.close()


def test_partial_special_weights_are_refused():
    plugin = styles_or_skip()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    cmds = [f"plugin load {plugin}", "units si", "atom_style bpm/sphere", "boundary f f f",
            "comm_modify vel yes", "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01",
            "create_box 1 box bond/types 1 extra/bond/per/atom 1 extra/special/per/atom 2",
            "create_atoms 1 single 0 0 0", "pair_style musen/hm",
            "pair_coeff * * 5e10 2e10 0.9 0.3 0.01", "special_bonds lj 0.5 1.0 1.0",
            "fix 1 all nve/sphere", "run 0 post no"]
    try:
        with pytest.raises(Exception, match="special_bonds lj weights must be 0"):
            for c in cmds:
                lmp.command(c)
    finally:
        lmp.close()


# ---------------------------------------------------------------- translation

def _translate(source: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fibrelmp.cli", "translate", str(source), "-o", str(out),
                           *extra], capture_output=True, text=True, cwd=ROOT)


def _oblique_job(folder: Path, end_time: float | None = None) -> Path:
    src = data_path("real-outputs", "musen", "scenarios", "oblique_two_materials")
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(src / "oblique_scene.txt", folder)
    job = (src / "job_oblique.txt").read_text()
    if end_time is not None:
        job = re.sub(r"(?m)^END_TIME\s+\S+", f"END_TIME             {end_time!r}", job)
    (folder / "job_oblique.txt").write_text(job)
    return folder / "job_oblique.txt"


def test_musen_job_uses_musen_hm_with_line_33_coefficients(tmp_path):
    """With the plugin: newton off, pair_style musen/hm and, per type pair, the E*/G* MUSEN
    mixes from the materials and e/mu/mu_r of the scene's `33` line."""
    styles_or_skip()
    proc = _translate(_oblique_job(tmp_path / "in"), tmp_path / "job")
    assert proc.returncode == 0, proc.stderr
    script = (tmp_path / "job" / "in.lammps").read_text()
    assert "\nnewton          off\n" in script and "\npair_style      musen/hm\n" in script
    lines = {tuple(ln.split()[1:3]): [float(v) for v in ln.split()[3:]]
             for ln in script.splitlines() if ln.startswith("pair_coeff")}
    expected = {("1", "1"): interaction(GLASS, GLASS, 0.9, 0.45, 0.05),
                ("1", "2"): interaction(GLASS, STEEL, 0.85, 0.15, 0.01),
                ("2", "2"): interaction(STEEL, STEEL, 0.9, 0.2, 0.01)}
    assert set(lines) == set(expected)
    for key, p in expected.items():
        np.testing.assert_allclose(lines[key], [p.e_star, p.g_star, p.rest, p.mu, p.mu_r], rtol=1e-14)
    assert "rolling friction acts on the relative rolling" not in proc.stderr


def test_stock_styles_keep_granular_and_say_how_it_differs(tmp_path):
    proc = _translate(_oblique_job(tmp_path / "in"), tmp_path / "job", "--stock-styles")
    assert proc.returncode == 0, proc.stderr
    script = (tmp_path / "job" / "in.lammps").read_text()
    assert "musen/hm" not in script and "\npair_style      granular\n" in script
    assert "rolling sds" in script and "tangential mindlin" in script
    text = " ".join(proc.stderr.split())
    assert "approximate MUSEN physics" in text
    assert "rolling friction acts on the relative rolling (LAMMPS rolling sds) instead of each sphere's own spin" in text
    assert "tangential damping is inside the Coulomb test" in text


def test_demdf_stays_on_stock_granular(tmp_path):
    """DEMDF's frictionless soft-sphere stand-in for BOS's collisions is not MUSEN's law; the
    stock style is exact for it and it keeps it with the plugin."""
    proc = _translate(ROOT / "examples" / "demdf" / "head_on.json", tmp_path / "job")
    assert proc.returncode == 0, proc.stderr
    script = next((tmp_path / "job").rglob("in.lammps")).read_text()
    assert "\npair_style      granular\n" in script and "musen/hm" not in script


def test_wall_particles_with_musen_hm(tmp_path):
    """The sphere-tile pair_coeff scales E* and G* by sqrt((R_p + r_w)/r_w), so that the
    contact is the flat wall's (R* = R_p); mu_r stays (musen/hm's rolling torque uses the
    sphere's own radius).  (Spheres on moving tiled walls with musen/hm:
    tests/test_granular_walls.py, which runs with the plugin when it is there.)"""
    styles_or_skip()
    from fibrelmp.granmodel import ContactLaw
    from fibrelmp.translate.granular.contacts import pair_coeff_lines

    class Spheres:
        mats = [0]
        m_min = {0: 1e-5}
        r_mean = {0: 1e-3}

    class Model:
        source = "x"
        materials = {0: SimpleNamespace(name="glass"), 1: SimpleNamespace(name="wall")}
        contacts = {(0, 0): ContactLaw(3e10, 1e10, 0.8, 0.4, 0.02),
                    (0, 1): ContactLaw(5e10, 2e10, 0.7, 0.3, 0.03)}

    rw = 0.3e-3
    lines = pair_coeff_lines(Model, Spheres, [1], rw, 1e-7, musen_hm=True)
    scale = math.sqrt((1e-3 + rw) / rw)
    got = {tuple(ln.split()[1:3]): [float(v) for v in ln.split()[3:]] for ln in lines}
    assert got[("1", "1")] == [3e10, 1e10, 0.8, 0.4, 0.02]
    assert got[("1", "2")] == [5e10 * scale, 2e10 * scale, 0.7, 0.3, 0.03]
    assert got[("2", "2")] == got[("1", "1")]         # never in contact (excluded)


def test_oblique_scenario_sphere_sphere_metrics(tmp_path):
    """fibrelmp run of the oblique scenario to 1.2 ms (every impact is over): the free-flight
    sphere pairs (10-13, particle-particle law only) against the real cmusen, with the
    metric script tests/scenarios/oblique_metrics.py.  README tolerances: |v| 0.01 m/s,
    omega 20 rad/s; measured |v| within 1.5e-7 m/s, omega within 1.5e-9 rad/s.  (The plate
    impacts depend on the wall law, not asserted here.)"""
    styles_or_skip()
    from tests.scenarios.oblique_metrics import compare, sphere_sphere

    job = _oblique_job(tmp_path / "run", end_time=0.0012)
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "--quiet", "run", job.name],
                          cwd=job.parent, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    rows = sphere_sphere(compare(job.parent / "oblique_result_prec17.txt"))
    assert len(rows) == 8
    for r in rows:
        assert r.ok, r.line()
        assert r.diff <= (1e-6 if r.kind == "pair_v" else 1e-6), r.line()


def test_newton_on_gives_the_same_trajectory():
    """The style asks for a newton-off list whatever `newton` says: `newton on` (e.g. a
    hand-written script) gives the same collision bit for bit, across a periodic boundary too."""
    plugin = styles_or_skip()
    box = 0.004
    shift = np.array([box - 0.8e-3, 0.0, 0.0])
    across = [Body(b.kind, b.r, tuple(float(c) for c in np.add(b.x, shift)), b.v, b.w)
              for b in CASES["oblique_spinning"]]
    runs = {}
    for newton in ("off", "on"):
        rec, runs[newton] = collide(plugin, across, nsteps=500, periodic=True, box=box,
                                    center=(0, 0, 0), newton=newton)
        assert rec.contact_steps > 100 and rec.worst <= 1e-12
    for a, b in zip(runs["off"], runs["on"]):
        np.testing.assert_array_equal(a, b)
