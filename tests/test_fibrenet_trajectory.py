"""A small damped fibre network run through ``fibrelmp.pipeline.run_model.run_fibrenet`` against the reference
integrator (tests/fibrenet_reference.py, FibreNet's modified velocity-Verlet).

Compared frame by frame: the full-precision LAMMPS dump (``<work>/frames.dump``) to 1e-6 in
positions and v~, and the FibreNet-format ``_coord/_vel/_force.xyz`` files (5 decimals).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.translate.fibrenet.writer import read_xyz
from fibrelmp.post.lammps_dump.reader import iter_frames

from . import fibrenet_reference as ref

TOL = 1e-6          # positions and v~ (absolute) after 1000 steps
XYZ = 5e-6          # rounding of the 5-decimal xyz files


def network(lam: float) -> ref.Net:
    """Three short, slightly curved fibres in a finite box: hs contacts between two radii, a
    crosslink spring between fibres, bent and straight rest angles, gravity, drag, a fixed
    mass-0 clamp, a mass-0 bead pulled at constant velocity, a model-file force for the first
    step, a model-file velocity and velocities set with modif_bead.  (No triple is exactly
    straight: there a bent rest angle's force has no defined direction.)"""
    net = ref.Net((6.0, 6.0, 5.0), wall_k=2000.0, cutoff=1.0, dt=1e-3, lam=lam, damping=2.0,
                  gravity=(0.0, 0.3, -2.0))
    net.type("F1", "F2")
    net.pair("hs", "F1", "F1", 1500.0)
    net.pair("hs", "F2", "F2", 1000.0)
    net.pair("hs", "F1", "F2", 800.0)
    # fibre 1 (tag 1) along x near the floor; bead 0 is a mass-0 clamp
    f1 = [net.bead("F1", (1.0 + 0.45 * k, 3.0 + 0.03 * math.sin(k), 0.6 + 0.02 * k * k), tag=1,
                   R=0.2, m=0.0 if k == 0 else 1.0,
                   v=(0.3, 0.3, 0.3) if k == 3 else (0.0, 0.0, 0.0)) for k in range(6)]
    # fibre 2 (tag 2) along y, crossing over fibre 1 in hs contact (gap < 0.2 + 0.25)
    f2 = [net.bead("F2", (2.3 + 0.02 * k * k, 1.9 + 0.45 * k, 1.0 + 0.03 * k), tag=2, R=0.25, m=1.5)
          for k in range(5)]
    # fibre 3 (tag 3) short and steep, thrown towards the floor
    f3 = [net.bead("F1", (3.8 + 0.1 * k, 2.2 + 0.03 * k * k, 0.35 + 0.4 * k), tag=3, R=0.2,
                   f=(3.0, -1.0, 2.5) if k == 1 else (0.0, 0.0, 0.0)) for k in range(4)]
    x = net.state().x
    for fib, k, c in ((f1, 1500.0, 40.0), (f2, 900.0, 25.0), (f3, 1200.0, 60.0)):
        springs = []
        for a, b in zip(fib, fib[1:]):
            r = float(np.linalg.norm(x[b] - x[a]))
            springs.append(net.spring(a, b, 0.97 * r, k, tag=net.beads[a]["tag"]))
        for j, (a, b, cc) in enumerate(zip(fib, fib[1:], fib[2:])):
            theta0 = "3.14159265358979" if j % 2 == 0 else "2.9"
            net.angle(a, b, cc, theta0, c, s1=springs[j], s2=springs[j + 1], tag=net.beads[a]["tag"])
    # a crosslink between fibres 2 and 3 (bonded pairs of different tags also touch via hs)
    net.spring(f2[3], f3[2], 1.0, 300.0, tag=9)
    net.modif_bead("tag", 2, "velocity", 0.1, 0.0, -0.3)
    net.modif_bead("tag", 3, "velocity", 0.5, -0.3, -1.0)
    net.modif_bead("id", f2[-1], "mass", 0.0)                 # pulled clamp
    net.modif_bead("id", f2[-1], "velocity", 0.0, 0.2, 0.0)
    net.pulled = f2[-1]
    return net


def _dump(job_folder):
    out = []
    for fr in iter_frames(job_folder / "frames.dump"):
        order = np.argsort(fr.column("id"))
        c = {k: v[order] for k, v in fr.columns.items()}
        xs = np.column_stack([c["x"], c["y"], c["z"]])
        img = np.column_stack([c["ix"], c["iy"], c["iz"]])
        out.append((fr.step, xs + img * (fr.hi - fr.lo),
                    np.column_stack([c["vx"], c["vy"], c["vz"]]),
                    np.column_stack([c["fx"], c["fy"], c["fz"]])))
    return out


def _compare(net: ref.Net, tmp_path, name: str, run=1000, every=250, floor=True, **minimize):
    model = read_fibrenet(net.write(tmp_path / name, name=name, run=run, output_freq=every,
                                     **minimize))
    out, work = tmp_path / f"{name}_out", tmp_path / f"{name}_work"
    run_fibrenet(model, out=out, work=work, progress=False)
    want = ref.simulate(net.system(), net.state(), run, every, **minimize)
    got = _dump(work)
    assert [g[0] for g in got] == [w.step for w in want] == list(range(0, run + 1, every))

    # sanity: the case exercises what it claims
    last = want[-1]
    if floor:
        assert min(w.x[:, 2].min() for w in want) < 0.0                # a bead is in the floor
    np.testing.assert_array_equal(last.x[0], want[0].x[0])             # the clamp stays
    errs = {"x": 0.0, "v~": 0.0, "F": 0.0}
    for (step, xu, vt, F), w in zip(got, want):
        errs["x"] = max(errs["x"], float(np.abs(xu - w.xu).max()))
        errs["v~"] = max(errs["v~"], float(np.abs(vt - w.vt).max()))
        errs["F"] = max(errs["F"], ref.max_rel_error(F, w.F) if np.abs(w.F).max() else float(np.abs(F).max()))
    print(f"\n[{name}] dump vs reference over {len(got)} frames: max |dx| {errs['x']:.3e}, "
          f"max |dv~| {errs['v~']:.3e}, max |dF|/max|F| {errs['F']:.3e}")
    assert errs["x"] <= TOL, errs
    assert errs["v~"] <= TOL, errs
    assert errs["F"] <= TOL, errs

    # the FibreNet files (5 decimals), every frame
    for field, attr in (("coord", "x"), ("vel", "vt"), ("force", "F")):
        frames = read_xyz(out / f"{name}_{field}.xyz")
        assert [f.step for f in frames] == [w.step for w in want]
        for f, w in zip(frames, want):
            ref_vals = getattr(w, attr)
            tol = XYZ + (TOL * np.abs(ref_vals).max() if attr == "F" else TOL)
            np.testing.assert_allclose(f.values, ref_vals, rtol=0, atol=tol,
                                       err_msg=f"{name}_{field}.xyz step {f.step}")
    return got, want


@pytest.mark.parametrize("lam", [0.5, 0.7])
def test_damped_network_matches_reference(tmp_path, lam):
    net = network(lam)
    got, want = _compare(net, tmp_path, f"net_l{int(lam * 10)}")
    # the pulled clamp moved at exactly its prescribed velocity
    pulled = net.pulled
    np.testing.assert_allclose(want[-1].xu[pulled] - want[0].xu[pulled], [0.0, 0.2, 0.0], atol=1e-12)
    np.testing.assert_allclose(got[-1][1][pulled] - got[0][1][pulled], [0.0, 0.2, 0.0], atol=1e-9)


@pytest.mark.parametrize("lam,reset", [(0.5, True), (0.7, True), (0.7, False)])
def test_minimize_chunks_then_run(tmp_path, lam, reset):
    """minimize_steps 300 in chunks of 100 (with minimize_reset: v, v_old, F, F_old zeroed
    before and after every chunk -- the modif_bead velocities, the pulled clamp's too, are
    erased), then frame 0 and the production run with the step counter restarted."""
    net = network(lam)
    _, want = _compare(net, tmp_path, f"min_l{int(lam * 10)}_{'reset' if reset else 'keep'}",
                       run=600, every=200, floor=False, minimize_steps=300,
                       minimize_substeps=100, minimize_reset=reset)
    start = net.state().xu[net.pulled]
    if reset:
        assert np.abs(want[0].vt).max() == 0 and np.abs(want[0].F).max() == 0
        np.testing.assert_array_equal(want[-1].xu[net.pulled], start)     # its velocity was erased
    else:
        assert np.abs(want[0].vt).max() > 0
        np.testing.assert_allclose(want[-1].xu[net.pulled] - start, [0.0, 0.18, 0.0], atol=1e-12)
