"""Each FibreNet force law, as translated to LAMMPS, against an independent numpy reference.

The inputs are written in FibreNet's own text formats, read with ``fibrelmp.translate.fibrenet.reader.read``
and evaluated by LAMMPS (``fibrelmp.pipeline.evaluate.evaluate``: one force evaluation, ``run 0``).  The
reference (tests/fibrenet_reference.py) is written from shared/research/fibrenet.md only.
Forces must agree to 1e-8 of the largest force component and energies to 1e-8 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fibrelmp.pipeline.evaluate import evaluate
from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.post.lammps_dump.reader import iter_frames

from . import fibrenet_reference as ref

TOL = 1e-8


def _evaluate(net: ref.Net, tmp_path, name: str, mutate=None, **options):
    """Write the case, evaluate it with fibrelmp, and compute the reference."""
    model = read_fibrenet(net.write(tmp_path / name, name=name, **options))
    sys_, st = net.system(), net.state()
    if mutate is not None:
        mutate(model, st)
    ev = evaluate(model, tmp_path / f"{name}_job")
    F, E = ref.total_forces(sys_, st.x, st.xu, st.v_old)
    return ev, F, E


def _check(law: str, ev, F, E, tol: float = TOL, energy: bool = True):
    assert ev.forces.shape == F.shape
    ferr = ref.max_rel_error(ev.forces, F)
    eerr = abs(ev.energy - E) / abs(E) if E != 0 else abs(ev.energy)
    print(f"\n[{law}] max force error {ferr:.3e} of max |F| = {np.abs(F).max():.6g}; "
          f"energy {ev.energy!r} vs {E!r} (rel err {eerr:.3e})")
    assert ferr <= tol, f"{law}: force error {ferr:.3e} > {tol:g}"
    if energy:
        assert eerr <= tol, f"{law}: energy {ev.energy!r} vs reference {E!r}"


def _along(p, direction, length):
    return np.asarray(p, float) + length * ref.unit(direction)


# ---------------------------------------------------------------------------------------
def test_reference_forces_are_minus_energy_gradient():
    """Self-check of the reference: every conservative force is -dE/dx (finite differences)."""
    rng = np.random.default_rng(3)
    net = ref.Net((6.0, 6.0, 6.0), periodic=True, cutoff=1.4)
    net.type("A", "B")
    net.pair("hs", "A", "A", 300.0)
    net.pair("st", "A", "B", 80.0, 240.0, 0.95, 1.2)
    net.pair("lj", "B", "B", 0.9, 3.0, 1.3)
    pts: list[np.ndarray] = []
    while len(pts) < 12:
        p = rng.uniform(0, 6, 3)
        if all(np.linalg.norm((p - q + 3) % 6 - 3) > 0.75 for q in pts):
            pts.append(p)
    for k, p in enumerate(pts):
        net.bead("A" if k % 2 else "B", p, tag=k, R=0.45)
    net.spring(0, 1, 1.0, 50.0)
    net.angle(0, 1, 2, 2.2, 30.0)
    net.angle(3, 4, 5, 3.1, 20.0)
    sys_, st = net.system(), net.state()
    zero = np.zeros_like(st.x)
    F, _ = ref.total_forces(sys_, st.x, st.xu, zero)
    h, G = 1e-6, np.zeros_like(F)
    for i in range(sys_.n):
        for a in range(3):
            e = []
            for sgn in (1, -1):
                xu = st.xu.copy()
                xu[i, a] += sgn * h
                e.append(ref.total_forces(sys_, np.mod(xu, 6.0), xu, zero)[1])
            G[i, a] = -(e[0] - e[1]) / (2 * h)
    assert ref.max_rel_error(F, G) < 1e-8


# ---------------------------------------------------------------------------------------
def test_hr_springs_on_unwrapped_positions(tmp_path):
    """F = k (r0 - r) along the bond, E = k/2 dr^2, on the unwrapped (ix) positions; one
    fibre crosses the periodic x face and one lies a whole box length away from its image."""
    L = 6.0
    net = ref.Net((L, L, L), periodic=True, cutoff=1.0)
    net.type("F")
    net.pair("hs", "F", "F", 500.0)
    # fibre 1 crosses x = L (unwrapped 5.3 .. 7.1)
    xs = [(5.3, 2.0, 2.0), (5.95, 2.3, 2.1), (6.7, 2.2, 1.8), (7.1, 2.9, 1.9)]
    ids = [net.bead("F", (x % L, y, z), tag=1, R=0.3, xu=(x, y, z)) for x, y, z in xs]
    for (a, b), (r0, k) in zip(zip(ids, ids[1:]), [(0.6, 800.0), (0.9, 1200.0), (0.7, 300.0)]):
        net.spring(a, b, r0, k, tag=1)
    # fibre 2: every unwrapped position is one box length off in y (it went round once)
    ys = [(3.0, 4.0, 4.0), (3.4, 4.6, 4.3), (3.2, 5.3, 4.9)]
    ids2 = [net.bead("F", p, tag=2, R=0.3, xu=(p[0], p[1] + L, p[2])) for p in ys]
    net.spring(ids2[0], ids2[1], 0.5, 2000.0, tag=2)      # stretched
    net.spring(ids2[1], ids2[2], 1.1, 700.0, tag=2)       # compressed
    net.spring(ids2[0], ids2[2], 1.6, 100.0, tag=2)       # a longer, compressed tie
    _check("spring HR", *_evaluate(net, tmp_path, "springs"))


def test_hr_fl_below_break_length_is_an_hr_spring(tmp_path):
    """HR_FL below its break length (|c1 (r-r0)/r| <= c2) pulls exactly like an HR spring."""
    net = ref.Net((8.0, 8.0, 8.0), cutoff=1.0)
    net.type("F")
    net.pair("hs", "F", "F", 500.0)
    # c1 = 10, c2 = 2: breaks beyond r0*10/8 = 1.25 r0 and below r0*10/12 = 0.833 r0
    cases = [((1.0, 1.0, 1.0), (1.0, 0.3, 0.2), 1.0, 1.2, 900.0, "10", "2"),   # 20% stretched
             ((4.0, 1.0, 1.0), (0.2, 1.0, 0.1), 1.0, 0.87, 600.0, "10", "2"),  # compressed
             # c1 "10.9" c2 "2.7" are read with std::stoi -> 10 and 2
             ((1.0, 4.0, 4.0), (0.3, 0.2, 1.0), 0.8, 0.99, 400.0, "10.9", "2.7")]
    for tag, (p, d, r0, r, k, c1, c2) in enumerate(cases):
        a = net.bead("F", p, tag=tag, R=0.2)
        b = net.bead("F", _along(p, d, r), tag=tag, R=0.2)
        net.spring(a, b, r0, k, tag=tag, c1=c1, c2=c2)
    a = net.bead("F", (5.0, 5.0, 5.0), tag=9, R=0.2)           # a plain HR for comparison
    b = net.bead("F", _along((5.0, 5.0, 5.0), (1, 1, 1), 1.2), tag=9, R=0.2)
    net.spring(a, b, 1.0, 900.0, tag=9)
    sys_, st = net.system(), net.state()
    assert not ref.hr_fl_overstressed(sys_, st.xu).any()
    ev, F, E = _evaluate(net, tmp_path, "hr_fl")
    _check("spring HR_FL (intact)", ev, F, E)
    # the 20%-stretched HR_FL spring and the HR spring of the same k, r0, r feel the same force
    np.testing.assert_allclose(np.linalg.norm(ev.forces[0]), np.linalg.norm(ev.forces[6]), rtol=1e-12)


def _dump_frames(job_folder):
    frames = list(iter_frames(job_folder / "frames.dump"))
    out = []
    for fr in frames:
        order = np.argsort(fr.column("id"))
        c = {k: v[order] for k, v in fr.columns.items()}
        L = fr.hi - fr.lo
        x = np.column_stack([c["x"], c["y"], c["z"]])
        img = np.column_stack([c["ix"], c["iy"], c["iz"]])
        out.append((fr.step, x + img * L,
                    np.column_stack([c["vx"], c["vy"], c["vz"]]),
                    np.column_stack([c["fx"], c["fy"], c["fz"]])))
    return out


def _run_and_compare(net: ref.Net, tmp_path, name, run, every):
    """Run with fibrelmp and compare every frame of frames.dump with the reference."""
    model = read_fibrenet(net.write(tmp_path / name, name=name, run=run, output_freq=every))
    result = run_fibrenet(model, out=tmp_path / f"{name}_out", work=tmp_path / f"{name}_work", progress=False)
    got = _dump_frames(result.job.folder)
    want = ref.simulate(net.system(), net.state(), run, every)
    assert [g[0] for g in got] == [w.step for w in want]
    worst = [0.0, 0.0, 0.0]
    for (step, xu, vt, F), w in zip(got, want):
        worst[0] = max(worst[0], float(np.abs(xu - w.xu).max()))
        worst[1] = max(worst[1], float(np.abs(vt - w.vt).max()))
        ferr = ref.max_rel_error(F, w.F) if np.abs(w.F).max() > 0 else float(np.abs(F).max())
        worst[2] = max(worst[2], ferr)
    print(f"\n[{name}] max |dx| {worst[0]:.3e}, max |dv~| {worst[1]:.3e}, max force rel err {worst[2]:.3e}")
    per_bead = np.abs(got[-1][1] - want[-1].xu).max(axis=1)
    print(f"[{name}] final |dx| per bead: " + " ".join(f"{e:.1e}" for e in per_bead))
    return got, want, worst, result


def test_hr_fl_beyond_break_length_exerts_no_force(tmp_path):
    """A HR_FL spring stretched beyond r0 c1/(c1-c2) breaks before its first force: its beads
    never feel it (FibreNet checks the stress every step before applying the force)."""
    net = ref.Net((8.0, 8.0, 8.0), cutoff=1.0, dt=1e-3)
    net.type("F")
    net.pair("hs", "F", "F", 500.0)
    # (a) c1=10, c2=2: break length 1.25, at 1.3;  (b) "10.9"/"2.7" -> stoi 10/2: break length
    # 1.25 (1.329 without the truncation), at 1.27;  (c) an intact HR_FL (1.1 < 1.25) that keeps pulling
    cases = [((1.0, 1.0, 1.0), (1, 0, 0), 1.3, "10", "2"),
             ((1.0, 4.0, 4.0), (0, 1, 1), 1.27, "10.9", "2.7"),
             ((4.0, 4.0, 1.0), (1, 1, 0), 1.1, "10", "2")]
    # (d) intact at first (1.2), its beads fly apart and it breaks in tension during the run
    cases.append(((4.0, 1.0, 4.0), (0, 0, 1), 1.2, "10", "2"))
    for tag, (p, d, r, c1, c2) in enumerate(cases):
        a = net.bead("F", p, tag=tag, R=0.2)
        b = net.bead("F", _along(p, d, r), tag=tag, R=0.2)
        net.spring(a, b, 1.0, 400.0, tag=tag, c1=c1, c2=c2)
    net.modif_bead("id", 6, "velocity", 0.0, 0.0, -3.0)
    net.modif_bead("id", 7, "velocity", 0.0, 0.0, 3.0)
    sys_, st = net.system(), net.state()
    assert ref.hr_fl_overstressed(sys_, st.xu).tolist() == [True, True, False, False]
    got, want, worst, _ = _run_and_compare(net, tmp_path, "hr_fl_break", 20, 10)
    final = ref.integrate(sys_, st, 20)[0]
    assert final.broken.tolist() == [True, True, False, True]
    step, xu, vt, F = got[-1]
    # the springs broken from the start: no force on their beads and no motion at all
    assert np.abs(F[:4]).max() == 0.0, F[:4]
    np.testing.assert_array_equal(xu[:4], st.xu[:4], err_msg="beads of HR_FL springs broken "
                                  "from the start moved: the spring acted during the first step")
    assert np.abs(F[4:6]).max() > 10.0        # the intact one still pulls
    assert np.abs(F[6:8]).max() == 0.0        # the one that broke during the run no longer does
    assert worst[0] <= 1e-9 and worst[1] <= 1e-9 and worst[2] <= TOL


# ---------------------------------------------------------------------------------------
def _triple(net, vertex, u_dir, v_dir, lu, lv, theta0, c, tag):
    b = np.asarray(vertex, float)
    a = net.bead("F", _along(b, u_dir, lu), tag=tag, R=0.1)
    m = net.bead("F", b, tag=tag, R=0.1)
    c_ = net.bead("F", _along(b, v_dir, lv), tag=tag, R=0.1)
    net.angle(a, m, c_, theta0, c, tag=tag)
    return a, m, c_


def _bent(theta):
    """Leg directions in the xy plane at angle theta."""
    return (1.0, 0.0, 0.0), (math.cos(theta), math.sin(theta), 0.0)


def test_angles_bent_and_near_straight(tmp_path):
    """E = c1 (theta - theta0)^2 with bent rest angles, a chain, and near-straight triples."""
    net = ref.Net((10.0, 10.0, 10.0), cutoff=1.0)
    net.type("F")
    net.pair("hs", "F", "F", 500.0)
    u, v = _bent(2.3)
    _triple(net, (2, 2, 2), u, v, 1.0, 0.8, 2.0, 40.0, tag=1)              # theta > theta0
    u, v = _bent(2.2)
    _triple(net, (5, 2, 2), u, v, 0.7, 0.9, 2.6, 25.0, tag=2)              # theta < theta0
    u, v = _bent(math.pi - 1e-4)
    _triple(net, (8, 2, 2), u, v, 0.5, 0.5, "3.141592653589793", 1864.19, tag=3)   # near straight
    u, v = _bent(math.pi - 2.5e-4)
    _triple(net, (2, 6, 2), u, (v[0], v[2], v[1]), 0.5, 0.6, "3.14159", 900.0, tag=4)
    u, v = _bent(2.9)
    _triple(net, (5, 6, 2), u, v, 0.5, 0.5, "3.14", 300.0, tag=5)
    # a four-bead chain: two angles share beads, different rest angles
    pts = [(2.0, 2.0, 6.0), (2.5, 2.1, 6.05), (3.0, 2.05, 6.2), (3.4, 2.4, 6.3)]
    ids = [net.bead("F", p, tag=6, R=0.1) for p in pts]
    net.angle(ids[0], ids[1], ids[2], "3.13", 500.0, tag=6)
    net.angle(ids[1], ids[2], ids[3], 2.4, 80.0, tag=6)
    _check("angle", *_evaluate(net, tmp_path, "angles"))


def test_angles_near_straight_only(tmp_path):
    """Only near-straight triples (1e-4 .. 1e-3 rad from straight, rest angle ~pi): LAMMPS'
    sin clamp (0.001) must not change the force; measured against these small forces alone."""
    net = ref.Net((10.0, 10.0, 10.0), cutoff=1.0)
    net.type("F")
    net.pair("hs", "F", "F", 500.0)
    for k, (dev, theta0) in enumerate([(1e-4, "3.14159265358979"), (3e-4, "3.1415927"),
                                       (8e-4, "3.1415926"), (1.5e-3, "3.14159265358979"),
                                       (1e-4, "3.1414")]):
        u, v = _bent(math.pi - dev)
        _triple(net, (2.0 + 1.5 * k, 5.0, 5.0), u, v, 0.5, 0.45, theta0, 1864.19, tag=k)
    _check("angle (near straight only)", *_evaluate(net, tmp_path, "straight"))


def test_angles_across_a_periodic_face_without_springs(tmp_path):
    """Angles use unwrapped positions; a triple crossing the periodic z face, no springs."""
    L = 5.0
    net = ref.Net((L, L, L), periodic=True, cutoff=0.5)
    net.type("F")
    net.pair("hs", "F", "F", 500.0)
    pts = [(2.0, 2.0, 4.3), (2.1, 2.2, 5.2), (2.0, 2.9, 5.9)]
    ids = [net.bead("F", (x, y, z % L), tag=1, R=0.1, xu=(x, y, z)) for x, y, z in pts]
    net.angle(*ids, 2.5, 60.0, tag=1)
    _check("angle (periodic, no bonds)", *_evaluate(net, tmp_path, "angle_pbc"))


# ---------------------------------------------------------------------------------------
def test_hs_two_radii_periodic_contacts(tmp_path):
    """hs: F = K (Ri + Rj - r) for r < Ri + Rj, any cutoff; two radii, three K, minimum image
    through the periodic faces."""
    L = 6.0
    net = ref.Net((L, L, L), periodic=True, cutoff=0.5)     # hs ignores the cutoff
    net.type("A", "B")
    net.pair("hs", "A", "A", 900.0)
    net.pair("hs", "B", "B", 700.0)
    net.pair("hs", "A", "B", 1100.0)
    Ra, Rb = 0.42, 0.3
    tag = iter(range(100))
    # A-A contact through the x face (overlap 0.14, Ri + Rj = 0.84 > cutoff 0.5)
    net.bead("A", (0.2, 1.0, 1.0), tag=next(tag), R=Ra)
    net.bead("A", (5.5, 1.1, 1.2), tag=next(tag), R=Ra)
    # A-B contact through the y and z faces at once
    net.bead("A", (3.0, 5.8, 5.9), tag=next(tag), R=Ra)
    net.bead("B", (3.1, 0.3, 0.2), tag=next(tag), R=Rb)
    # B-B contact inside the box; A-B just out of contact (r = Ri + Rj + 0.01)
    net.bead("B", (3.0, 3.0, 3.0), tag=next(tag), R=Rb)
    net.bead("B", _along((3.0, 3.0, 3.0), (1, 2, 0), 0.5), tag=next(tag), R=Rb)
    net.bead("A", _along((3.0, 3.0, 3.0), (0, -1, -1), Ra + Rb + 0.01), tag=next(tag), R=Ra)
    # a three-body cluster of both radii
    c = np.array([1.5, 4.0, 3.0])
    net.bead("A", c, tag=next(tag), R=Ra)
    net.bead("A", _along(c, (1, 0.2, 0), 0.7), tag=next(tag), R=Ra)
    net.bead("B", _along(c, (0.3, 1, 0.1), 0.6), tag=next(tag), R=Rb)
    _check("hs", *_evaluate(net, tmp_path, "hs"))


def test_st_both_sides_of_rstar_and_cutoffs(tmp_path):
    """st as FibreNet runs it: F = Katt (l0 - r) + Krep (2 l0 - rc - r) for r < min(rc, cutoff),
    E = B/2 (r - r*)^2.  Pairs on both sides of r*, and pairs beyond the effective cutoff."""
    net = ref.Net((12.0, 6.0, 6.0), cutoff=1.1)
    net.type("S1", "S2", "S3")
    net.pair("hs", "S1", "S1", 500.0)
    net.pair("st", "S1", "S2", 80.0, 240.0, 0.95, 1.2)     # r* = 0.8875, cutoff min(1.2, 1.1)
    net.pair("st", "S2", "S2", 100.0, 50.0, 1.0, 1.05)     # r* = 0.9667, cutoff rc = 1.05
    net.pair("hs", "S1", "S3", 300.0)
    net.pair("hs", "S2", "S3", 300.0)
    net.pair("hs", "S3", "S3", 300.0)
    tag = iter(range(100))
    for k, (t1, t2, r) in enumerate([("S1", "S2", 0.8), ("S1", "S2", 0.95), ("S1", "S2", 1.08),
                                     ("S1", "S2", 1.15),          # between cutoff 1.1 and rc 1.2
                                     ("S2", "S2", 0.9), ("S2", "S2", 1.02),
                                     ("S2", "S2", 1.07)]):        # beyond rc 1.05, < cutoff
        p = np.array([1.0 + 1.5 * k, 2.0 + 0.1 * k, 3.0])
        net.bead(t1, p, tag=next(tag), R=0.1)
        net.bead(t2, _along(p, (0.3, 1.0, 0.4 * (-1) ** k), r), tag=next(tag), R=0.1)
    sys_, st = net.system(), net.state()
    F, _ = ref.pair_forces(sys_, st.x)
    assert np.abs(F[6:8]).max() == 0 and np.abs(F[12:14]).max() == 0   # the two beyond-cutoff pairs
    assert F[0] @ (st.x[1] - st.x[0]) < 0 and F[2] @ (st.x[3] - st.x[2]) > 0  # both sides of r*
    _check("st", *_evaluate(net, tmp_path, "st"))


def test_lj_two_types(tmp_path):
    """FibreNet lj: F = 48 eps (s/r)^6 ((s/r)^6 - 1/2)/r^2 - Fc for r < min(c3, cutoff)."""
    net = ref.Net((8.0, 8.0, 8.0), cutoff=1.7)
    net.type("L1", "L2")
    net.pair("lj", "L1", "L1", 0.9, 3.0, 1.8)      # cutoff 1.7 < c3: force not 0 at the cutoff
    net.pair("lj", "L2", "L2", 0.8, 2.0, 1.5)
    net.pair("lj", "L1", "L2", 1.0, 1.5, 1.6)
    rng = np.random.default_rng(7)
    pts: list[np.ndarray] = []
    while len(pts) < 9:
        p = rng.uniform(3.0, 5.0, 3)
        if all(np.linalg.norm(p - q) > 0.95 for q in pts):
            pts.append(p)
    for k, p in enumerate(pts):
        net.bead("L1" if k % 3 else "L2", p, tag=k, R=0.3)
    _check("lj", *_evaluate(net, tmp_path, "lj"))


# ---------------------------------------------------------------------------------------
def test_walls_restart_positions_beyond_faces(tmp_path):
    """Finite box walls: F = k * penetration, E = k/2 pen^2.  Model positions must lie in
    [0, L], but a restart (restart_data position) may put beads into the soft walls -- as
    any run with gravity leaves them -- and FibreNet applies the wall force there."""
    net = ref.Net((5.0, 4.0, 6.0), wall_k=2000.0, cutoff=1.0)
    net.type("W")
    net.pair("hs", "W", "W", 100.0)
    inside = [(0.5, 2.0, 3.0), (4.5, 1.0, 1.0), (2.0, 0.5, 5.5), (1.0, 3.0, 0.5), (4.0, 3.5, 3.0)]
    outside = np.array([(-0.013, 2.0, 3.0), (5.021, 1.0, 1.0), (2.0, -0.004, 6.03),
                        (1.0, 3.0, 0.5), (4.0, 4.0017, 3.0)])
    for k, p in enumerate(inside):
        net.bead("W", p, tag=k, R=0.2)
    folder = tmp_path / "walls"
    folder.mkdir()
    zero = np.zeros_like(outside)
    (folder / "prev_restart.res").write_text(net.restart_text(outside, outside, zero, zero))

    def from_restart(model, st):
        st.x[:] = outside
        st.xu[:] = outside

    ev, F, E = _evaluate(net, tmp_path, "walls", mutate=from_restart,
                         extra=("restart_file\tprev_restart.res", "restart_data\tposition"))
    assert np.abs(F).max() > 10
    _check("walls", ev, F, E)


def test_walls_in_a_short_run(tmp_path):
    """Beads sent into the walls (velocity via modif_bead, gravity): trajectory vs reference."""
    net = ref.Net((4.0, 4.0, 4.0), wall_k=3000.0, cutoff=1.0, dt=1e-3, gravity=(0.0, 0.0, -5.0))
    net.type("W")
    net.pair("hs", "W", "W", 100.0)
    net.bead("W", (0.05, 2.0, 2.0), tag=1, R=0.2)
    net.bead("W", (3.97, 1.0, 3.99), tag=2, R=0.2, m=2.0)
    net.bead("W", (2.0, 2.0, 0.01), tag=3, R=0.2, m=0.5)
    net.modif_bead("tag", 1, "velocity", -2.0, 0.3, 0.0)
    net.modif_bead("tag", 2, "velocity", 1.5, 0.0, 2.0)
    got, want, worst, _ = _run_and_compare(net, tmp_path, "walls_run", 200, 50)
    assert min(w.xu.min() for w in want) < -1e-3          # the beads did enter the walls
    assert max((w.xu - net.L).max() for w in want) > 1e-3
    assert worst[0] <= 1e-9 and worst[1] <= 1e-8 and worst[2] <= TOL


def test_gravity_is_a_force_not_an_acceleration(tmp_path):
    net = ref.Net((5.0, 5.0, 5.0), cutoff=1.0, gravity=(0.1, 0.3, -2.0))
    net.type("G")
    net.pair("hs", "G", "G", 100.0)
    for k, m in enumerate([1.0, 2.5, 0.0, 0.3]):
        net.bead("G", (1.0 + k, 2.0, 2.0), tag=k, R=0.2, m=m)
    ev, F, E = _evaluate(net, tmp_path, "gravity")
    np.testing.assert_allclose(F, np.tile([0.1, 0.3, -2.0], (4, 1)))
    _check("gravity", ev, F, E, energy=False)
    assert abs(ev.energy) < 1e-12


@pytest.mark.parametrize("lam", [0.5, 0.7])
def test_damping_drag_on_set_velocities(tmp_path, lam):
    """Drag F = -damping v (not mass-scaled) on velocities set with modif_bead, mass-0 too."""
    net = ref.Net((5.0, 5.0, 5.0), cutoff=1.0, damping=2.0, lam=lam)
    net.type("D", "E")
    net.pair("hs", "D", "D", 100.0)
    net.pair("hs", "E", "E", 100.0)
    net.pair("hs", "D", "E", 100.0)
    for k, m in enumerate([1.0, 2.5, 0.0, 0.3]):
        net.bead("D" if k % 2 else "E", (1.0 + k, 2.0, 2.0), tag=k, R=0.2, m=m)
    net.modif_bead("tag", 0, "velocity", 0.3, -0.2, 0.5)
    net.modif_bead("tag", 1, "velocity", -1.0, 0.0, 0.25)
    net.modif_bead("id", 2, "velocity", 0.0, 0.7, 0.0)
    net.modif_bead("type", "E", "mass", 1.7)
    ev, F, E = _evaluate(net, tmp_path, f"drag{lam}")
    assert np.abs(F).max() > 0.1
    _check(f"damping (lambda {lam})", ev, F, E, energy=False)


def test_exclusion_same_tag(tmp_path):
    """No non-bonded force between beads of one tag (same loc_id, or loc_ids 1 apart);
    beads of different tags interact, bonded or not."""
    net = ref.Net((6.0, 6.0, 6.0), cutoff=1.0)
    net.type("X")
    net.pair("hs", "X", "X", 800.0)
    # same tag, same loc_id, strongly overlapping: nothing
    net.bead("X", (1.0, 1.0, 1.0), tag=1, R=0.4)
    net.bead("X", (1.3, 1.0, 1.0), tag=1, R=0.4)
    # same tag, loc_ids 0 and 1: excluded too
    net.bead("X", (3.0, 1.0, 1.0), tag=2, loc=0, R=0.4)
    net.bead("X", (3.3, 1.1, 1.0), tag=2, loc=1, R=0.4)
    # different tags, overlapping: hs force
    net.bead("X", (1.0, 4.0, 1.0), tag=3, R=0.4)
    net.bead("X", (1.5, 4.2, 1.0), tag=4, R=0.4)
    # different tags joined by a spring (a crosslink): spring AND hs force
    a = net.bead("X", (4.0, 4.0, 4.0), tag=5, R=0.4)
    b = net.bead("X", (4.6, 4.0, 4.1), tag=6, R=0.4)
    net.spring(a, b, 0.5, 300.0, tag=7)
    ev, F, E = _evaluate(net, tmp_path, "exclusion")
    assert np.abs(ev.forces[:4]).max() < 1e-12
    assert np.abs(ev.forces[4:6]).max() > 10
    _check("exclusion", ev, F, E)
