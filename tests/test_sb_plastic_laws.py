"""MUSEN's plastic solid-bond laws in ``bond_style musen/elastic`` (``plastic``,
``linear/plastic``, ``creep``) on one bond against an independent numpy statement of each
law's normal part, written from MUSEN's ModelSBElasticPerfectlyPlastic.cpp,
ModelSBLinearPlastic.cpp and ModelSBCreep.cpp (CalculateSB): the left sphere rests at the
origin, the right one is pulled along x past yield, pushed back into compression and
released, positions and velocities prescribed every step (the harness of
test_style_musen_bond.py).  Checked per step: the force's value and sign, that it has no jump
at yield (the change per step stays within the elastic one), the plastic strain left after
unloading, the fracture strain's break step, and a checkpoint round trip of the state."""

from __future__ import annotations


import numpy as np
import pytest

from .test_style_musen_bond import Lmp, breaks_in, write_data

MUSEN_PI = 3.14159265358979323846
D, L0, DT = 6e-4, 1e-3, 1e-7
A = MUSEN_PI * D * D / 4
NEVER = 1e300


def stretch_path(steps: int, peak: float, low: float) -> np.ndarray:
    """Extension u of the bond at steps 0..steps: up to ``peak``, down to ``low``, back to 0."""
    knots_t = np.array([0, 0.3, 0.75, 1.0]) * steps
    return np.interp(np.arange(steps + 1), knots_t, [0.0, peak, low, 0.0])


def strain_of(u: np.ndarray) -> np.ndarray:
    """The bond strain the right sphere at L0 + u gives (the same rounding as the law's)."""
    return ((L0 + u) - L0) / L0


def lammps_forces(tmp_path, style: str, coeff: str, u: np.ndarray) -> tuple[np.ndarray, list]:
    """The x force on the left sphere after each step of the prescribed extension u, and the
    style's break records."""
    x0 = np.array([[0.0, 0.0, 0.0], [L0, 0.0, 0.0]])
    write_data(tmp_path / "data.bonds", x0, [4e-4, 4e-4], [(0, 1)])
    lmp = Lmp(tmp_path, tmp_path / "data.bonds", f"musen/elastic {style} breaks breaks.txt",
              f"1 {coeff}", DT)
    out = []
    try:
        lmp.run(0)
        for s in range(1, len(u)):
            x = x0.copy()
            x[1, 0] += u[s]
            v = np.zeros((2, 3))
            v[1, 0] = (u[s] - u[s - 1]) / DT
            lmp.set("x", x)
            lmp.set("v", v)
            lmp.set("omega", np.zeros((2, 3)))
            lmp.run(1)
            out.append(lmp.get("f")[0].copy())
    finally:
        lmp.close()
    return np.array(out), breaks_in(tmp_path / "breaks.txt")


def perfectly_plastic(strain: np.ndarray, E: float, Y: float, rc: float, creep=(0.0, 0.0)):
    """Normal stress per step and the plastic strain after it: stress (strain - eps_p) E,
    capped at Y in tension and rc Y in compression, eps_p moved so the cap holds; creep
    (a, m): eps_p then moves by dt a |stress|^m towards the stress's sign."""
    a, m = creep
    eps_p, stress, plastic = 0.0, [], []
    for e in strain:
        trial = (e - eps_p) * E
        cap = Y * (rc if trial < 0 else 1.0)
        s = min(max(trial, -cap), cap)
        eps_p = e - s / E if s != trial else eps_p
        stress.append(s)
        if a:
            eps_p += DT * a * abs(s) ** m if s > 0 else -DT * a * abs(s) ** m
        plastic.append(eps_p)
    return np.array(stress), np.array(plastic)


def linear_plastic(strain: np.ndarray, E: float, kl: float, ku: float) -> np.ndarray:
    """Normal force (positive: tension) per step: loading along KL (eps_p = strain (1 -
    KL/KU)), unloading along KU from the plastic strain; E (<= 2) a factor."""
    eps_p, force = 0.0, []
    for e in strain:
        if abs(ku * (e - eps_p)) > abs(kl * e):
            force.append(A * kl * e * E)
            eps_p = e * (1 - kl / ku)
        else:
            force.append(A * ku * (e - eps_p) * E)
    return np.array(force)


def _no_jump(force: np.ndarray, u: np.ndarray, stiffness: float) -> None:
    """Continuity: no step changes the force by more than the elastic response to its
    extension increment."""
    du = np.abs(np.diff(u))[:len(force) - 1]
    assert (np.abs(np.diff(force)) <= stiffness * du * (1 + 1e-9) + 1e-15).all()


E_B, G_B, Y_B = 1e8, 1e8 / 2.44, 1e6        # yield strain 0.01


@pytest.mark.parametrize("rc", [1.0, 0.5])
def test_perfectly_plastic_normal_law(tmp_path, rc):
    u = stretch_path(300, 0.03 * L0, -0.03 * L0)
    f, breaks = lammps_forces(tmp_path, "breakage 0 plastic 0.1 0 1 " + repr(rc),
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}", u)
    strain = strain_of(u[1:])
    stress, plastic = perfectly_plastic(strain, E_B, Y_B, rc)
    # the left sphere is pulled towards the right one (+x) in tension
    np.testing.assert_allclose(f[:, 0], stress * A, rtol=1e-12, atol=1e-12 * Y_B * A)
    assert np.abs(f[:, 1:]).max() < 1e-12 * Y_B * A
    assert f[:, 0].max() == pytest.approx(Y_B * A, rel=1e-12)              # tension cap
    assert f[:, 0].min() == pytest.approx(-rc * Y_B * A, rel=1e-12)        # compression cap
    _no_jump(f[:, 0], u[1:], E_B * A / L0)
    # back at the initial length the bond keeps a plastic strain: a residual force
    assert plastic[-1] != 0 and f[-1, 0] == pytest.approx(-plastic[-1] * E_B * A, rel=1e-9)
    assert not breaks


def test_perfectly_plastic_breaks_at_its_fracture_strain(tmp_path):
    u = stretch_path(300, 0.03 * L0, -0.03 * L0)
    _, breaks = lammps_forces(tmp_path, "breakage 0 plastic 0.02 0 1 1.0",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}", u)
    first = int(np.flatnonzero(strain_of(u) > 0.02)[0])
    assert breaks == [(first, 1, 2)]
    (tmp_path / "compression").mkdir()
    _, breaks = lammps_forces(tmp_path / "compression", "breakage 0 plastic 0.1 0.02 1 1.0",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}", u)
    assert breaks == [(int(np.flatnonzero(strain_of(u) < -0.02)[0]), 1, 2)]      # compression


def test_creep_normal_law(tmp_path):
    a, m = 20.0, 0.3
    u = stretch_path(300, 0.03 * L0, -0.03 * L0)
    f, breaks = lammps_forces(tmp_path, f"breakage 0 creep 0.1 0 1 0.5 {a!r} {m!r}",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}", u)
    stress, _ = perfectly_plastic(strain_of(u[1:]), E_B, Y_B, 0.5, creep=(a, m))
    np.testing.assert_allclose(f[:, 0], stress * A, rtol=1e-12, atol=1e-12 * Y_B * A)
    # creep is not nothing: without it the forces differ
    plain, _ = perfectly_plastic(strain_of(u[1:]), E_B, Y_B, 0.5)
    assert np.abs(plain - stress).max() > 1e-3 * Y_B
    assert not breaks


@pytest.mark.parametrize("E", [1.5, 5e8])
def test_linear_plastic_normal_law(tmp_path, E):
    kl, ku = 1e8, 4e8
    u = stretch_path(300, 0.03 * L0, -0.03 * L0)
    f, _ = lammps_forces(tmp_path, f"breakage 0 linear/plastic {kl!r} {ku!r}",
                         f"{E!r} {E / 2.44!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r}", u)
    strain = strain_of(u[1:])
    # MUSEN: a bond whose E is above 2 is elastic (E the modulus), at or below a factor
    want = linear_plastic(strain, E, kl, ku) if E <= 2 else strain * A * E
    np.testing.assert_allclose(f[:, 0], want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    if E <= 2:
        # continuous through loading, yield and unloading until the force first passes zero;
        # after that MUSEN's test |KU (strain - eps_p)| > |KL strain| compares magnitudes only,
        # so a bond unloaded into compression at positive strain takes the loading branch
        # again with the opposite sign: the force reverses in one step (MUSEN's law, kept;
        # the reference above has the same reversals)
        cross = int(np.flatnonzero(np.sign(want[1:]) * np.sign(want[:-1]) < 0)[0])
        _no_jump(f[:cross + 2, 0], u[1:cross + 3], A * ku * E / L0)
        elastic = A * ku * E / L0 * np.abs(np.diff(u[1:]))
        assert (np.abs(np.diff(f[:, 0])) > 2 * elastic).any()
        # unloading is along KU from the plastic strain: not the loading line KL strain
        assert np.abs(f[:, 0] - A * kl * strain * E).max() > 0.5 * np.abs(f[:, 0]).max()


def weakening(strain: np.ndarray, E: float, Y: float) -> np.ndarray:
    """ModelSBWeakening with WEAKENING_FACTOR 0, normal stress per step: elastic from the
    plastic strain; beyond Y the plastic strain becomes the whole strain (no stress)."""
    eps_p, out = 0.0, []
    for e in strain:
        s = (e - eps_p) * E
        if abs(s) > Y:
            eps_p, s = e, 0.0
        out.append(s)
    return np.array(out)


def test_weakening_normal_law(tmp_path):
    u = stretch_path(300, 0.03 * L0, -0.03 * L0)
    f, breaks = lammps_forces(tmp_path, "breakage 0 weakening 0 0.1 0",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}", u)
    stress = weakening(strain_of(u[1:]), E_B, Y_B)
    np.testing.assert_allclose(f[:, 0], stress * A, rtol=1e-12, atol=1e-12 * Y_B * A)
    assert (stress == 0).sum() > 3 and np.abs(f[:, 0]).max() <= Y_B * A     # it weakened
    assert not breaks
    # its strain test (CONSIDER_BREAKAGE 1): tension above BREAKAGE_STRAIN, compression below
    # twice it with COMPRESSIVE_BREAK 1
    (tmp_path / "b").mkdir()
    _, breaks = lammps_forces(tmp_path / "b", "breakage 1 weakening 1 0.012 0",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}", u)
    assert breaks == [(int(np.flatnonzero(strain_of(u) > 0.012)[0]), 1, 2)]


def aerogel(strain: np.ndarray, p: dict) -> tuple[np.ndarray, list[int]]:
    """ModelSBAerogel's normal force F / (A E) per step (positive: tension) and the steps
    where it breaks (force above BREAK_STRAIN_TENS A E while not in a broken state)."""
    eps_p, state, out, breaks = 0.0, 0, [], []
    for k, e in enumerate(strain):
        if state == 0:
            if e < -abs(p["psc"]):
                d = e + abs(p["psc"])
                F = -abs(p["psc"]) + d * p["src"]
                eps_p = d * (1 - p["src"])
                if F > 0:
                    state, F = -1, 0.0
            elif e > abs(p["pst"]):
                d = e - abs(p["pst"])
                F = abs(p["pst"]) + d * p["srt"]
                eps_p = d * (1 - p["srt"])
                if F < 0:
                    state, F = 1, 0.0
            else:
                F = e - eps_p
            if F > abs(p["bst"]):
                breaks.append(k)
        elif state < 0:
            eps_p = min(eps_p, e)
            F = p["hrc"] * (e - eps_p)
        else:
            eps_p = max(eps_p, e)
            F = p["hrt"] * (e - eps_p)
        out.append(F)
    return np.array(out), breaks


AEROGEL = dict(psc=0.01, pst=0.005, src=-2.0, srt=-0.5, bst=0.5, hrc=0.1, hrt=0.1)


@pytest.mark.parametrize("peak,low", [(0.008, -0.03), (0.03, -0.008)],
                         ids=["broken-in-compression", "broken-in-tension"])
def test_aerogel_normal_law(tmp_path, peak, low):
    u = stretch_path(300, peak * L0, low * L0)
    words = " ".join(repr(v) for v in AEROGEL.values())
    f, breaks = lammps_forces(tmp_path, f"breakage 0 aerogel {words}",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r}", u)
    force, ref_breaks = aerogel(strain_of(u[1:]), AEROGEL)
    np.testing.assert_allclose(f[:, 0], force * A * E_B, rtol=1e-9, atol=1e-12 * A * E_B)
    assert not breaks and not ref_breaks
    # it softened and reached a broken state: the force came back to zero on that side
    side = force[np.argmin(u[1:]) if low < -peak else np.argmax(u[1:])]
    assert abs(side) < abs(AEROGEL["psc"])


def test_aerogel_breaks_above_its_force(tmp_path):
    """Without softening (ratio 1 in tension) the force grows past BREAK_STRAIN_TENS A E."""
    p = dict(AEROGEL, srt=1.0, bst=0.02)
    u = stretch_path(300, 0.03 * L0, -0.008 * L0)
    words = " ".join(repr(v) for v in p.values())
    _, breaks = lammps_forces(tmp_path, f"breakage 0 aerogel {words}",
                              f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r}", u)
    _, ref = aerogel(strain_of(u[1:]), p)
    assert ref and breaks == [(ref[0] + 1, 1, 2)]


def concrete(strain: np.ndarray, E: float, Y: float) -> tuple[np.ndarray, list[int]]:
    """ModelSBPlasticConcrete's normal stress per step and its break steps: tension capped at
    0.7 Y - 0.3 E eps_p (eps_p += excess 1.3 / E; breaks when the stress is then negative),
    compression at -Y + 0.5 E eps_p (eps_p += excess 0.5 / E)."""
    eps_p, out, breaks = 0.0, [], []
    for k, e in enumerate(strain):
        s = (e - eps_p) * E
        if e - eps_p >= 0:
            limit = 0.7 * Y - eps_p * E * 0.3
            if s > limit:
                eps_p += (s - limit) * 1.3 / E
                s = (e - eps_p) * E
            if s < 0:
                breaks.append(k)
        else:
            limit = -Y + eps_p * E * 0.5
            if s < limit:
                eps_p += (s - limit) * 0.5 / E
                s = (e - eps_p) * E
        out.append(s)
    return np.array(out), breaks


def test_plastic_concrete_normal_law(tmp_path):
    """MUSEN's sign: the force on the left sphere is n sigma A, n pointing from the right
    sphere to it: a stretched bond pushes the left sphere away (-x)."""
    u = stretch_path(300, 0.03 * L0, -0.03 * L0)
    coeff = f"{E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r} yield {Y_B!r}"
    f, breaks = lammps_forces(tmp_path, "breakage 0 concrete", coeff, u)
    stress, ref = concrete(strain_of(u[1:]), E_B, Y_B)
    np.testing.assert_allclose(f[:, 0], -stress * A, rtol=1e-9, atol=1e-12 * Y_B * A)
    # it yields in the first stretch (above 0.7 Y) and in compression (below -Y)
    strain = strain_of(u[1:])
    stretch = np.arange(len(strain)) < 90
    assert np.abs(stress - strain * E_B)[stretch].max() > 0.1 * Y_B
    assert np.abs(stress - strain * E_B)[strain < -Y_B / E_B].max() > 0.1 * Y_B
    assert not breaks and ref        # the sign test is off with CONSIDER_BREAKAGE 0
    (tmp_path / "b").mkdir()
    _, breaks = lammps_forces(tmp_path / "b", "breakage 1 concrete", coeff, u)
    assert breaks == [(ref[0] + 1, 1, 2)]


COEFF = f"1 {E_B!r} {G_B!r} {NEVER!r} {NEVER!r} 0.0 {D!r} {L0!r}"


@pytest.mark.parametrize("style,coeff,message", [
    ("breakage 0 plastic 0.1 0 1 1", COEFF, "need each bond type's yield strength"),
    ("breakage 1 plastic 0.1 0 1 1 ", COEFF + " yield 1e6", "plastic takes breakage 0..0"),
    ("breakage 0 then creep 2 0.1 0 1 1 0.2 0.5", COEFF + " yield 1e6",
     "then creep: breakage must be 0..1"),
    ("breakage 0 linear/plastic 1e6 0", COEFF, "KUnLoad must not be 0"),
    ("breakage 0 creep 0.1 0 1 1 0.2", COEFF + " yield 1e6", "creep command: missing argument"),
    ("breakage 0 then viscous 0", COEFF, "unknown law viscous"),
    ("breakage 0 plastic 0.1 0 1 1", COEFF + " yield -1", "yield strength must be >= 0"),
])
def test_bad_law_settings_are_errors(tmp_path, style, coeff, message):
    x0 = np.array([[0.0, 0.0, 0.0], [L0, 0.0, 0.0]])
    write_data(tmp_path / "data.bonds", x0, [4e-4, 4e-4], [(0, 1)])
    with pytest.raises(Exception, match=message):
        lmp = Lmp(tmp_path, tmp_path / "data.bonds", f"musen/elastic {style}", coeff, DT)
        try:
            lmp.run(0)
        finally:
            lmp.close()
