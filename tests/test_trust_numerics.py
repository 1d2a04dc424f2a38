"""Numerical robustness: oversized MUSEN/DEMDF domains, huge coordinates, tiny time steps,
FibreNet springs across periodic boxes and beads pressed into FibreNet's finite walls.

Each test failed before its fix (see the git history of this file)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

from fibrelmp.pipeline.run_model import run_fibrenet
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.errors import InputError, RunError
from fibrelmp.translate.fibrenet import target as to_fibrenet
from fibrelmp.post.lammps_dump.reader import Frame, iter_frames
from fibrelmp.translate.fibrenet.target import write_fibrenet
from fibrelmp.translate import granular_job as gj
from fibrelmp.translate.granular import reach, tiles
from fibrelmp.translate.granular.geometry import tile_triangles, tile_triangles_within

from . import granular_models as gm
from .granular_models import run
from .conftest import REPO

R = 0.0005
G = 9.81




# ---------------------------------------------------------------------------------------
# 1. the LAMMPS box follows the spheres, not an oversized domain
def test_musen_scene_with_default_2m_domain_runs_small_and_fast(tmp_path):
    """tests/bad_inputs/musen/good.txt: 1 mm spheres in MUSEN's usual 2 m domain above a 1 m
    triangle.  It used to die in LAMMPS ("Too many atom sorting bins") after ~30-65 s and
    2.6 GB (4 million wall particles, ~4e9 bins); now: 2 atoms, a box of a few mm, < 1 s."""
    out = tmp_path / "r.txt"
    cmd = [sys.executable, "-m", "fibrelmp.cli", "run", str(REPO / "tests/bad_inputs/musen/good.txt"),
           "--end-time", "1e-4", "--step", "1e-6", "--save-step", "5e-5", "-o", str(out)]
    # a fresh parent whose only child is the run: its RUSAGE_CHILDREN is the run's peak memory
    probe = ("import resource, subprocess, sys, time; t = time.monotonic(); "
             "p = subprocess.run(sys.argv[1:], capture_output=True, text=True); "
             "print(p.returncode, time.monotonic() - t, "
             "resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss); print(p.stderr)")
    proc = subprocess.run([sys.executable, "-c", probe, *cmd], capture_output=True, text=True,
                          timeout=600, cwd=tmp_path, env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"})
    head, _, stderr = proc.stdout.partition("\n")
    rc, seconds, rss_kb = head.split()
    print(f"\ngood.txt: {float(seconds):.1f} s, peak {int(rss_kb) / 1024:.0f} MB")
    assert rc == "0", stderr
    assert float(seconds) < 60 and int(rss_kb) < 600 * 1024
    work = tmp_path / "r_work"
    script = (work / "in.lammps").read_text()
    assert "boundary        m m m" in script and "evaporate" in script
    frames = list(iter_frames(work / "frames.dump"))
    assert frames[-1].count == 2
    assert (frames[-1].hi - frames[-1].lo).max() < 0.01          # a few mm, not 2 m
    # free fall: no contact (the plate is 9 mm below), in MUSEN's leapfrog (prediction half
    # kick, then kick and move): z = z0 - g dt^2 (n^2/2 + n), vz = -g dt (n + 1/2) at step n;
    # the last is cmusen's, step 101, whose summed time first reaches END_TIME
    n, dt = frames[-1].step, 1e-6
    assert n == 101
    drop = G * dt * dt * (n * n / 2 + n)
    z = frames[-1].column("z")
    assert z == pytest.approx([0.01 - drop, 0.012 - drop], rel=0, abs=1e-15)
    assert frames[-1].column("vz") == pytest.approx([-G * dt * (n + 0.5)] * 2, rel=1e-9)


def _pair_leaving(domain_half: float):
    """A sphere at rest at the origin and a bonded pair at 1 m/s along +x that crosses the
    domain face x = domain_half at t = 7e-4."""
    mats, contacts = gm.two_materials()
    x0 = domain_half - 0.0007
    x = [[0.0, 0.0, 0.0], [x0, 0.0, 0.0], [x0, 0.0015, 0.0]]
    v = [[0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]]
    m = gm.model(gm.spheres(x, R, [0] * 3, mats, v=v), mats, contacts, dt=1e-7, t_end=0.0015,
                 save_every_time=0.0005, domain=(np.full(3, -domain_half), np.full(3, domain_half)))
    m.bonds = gm.bonds([[1, 2]], 0.0004, 0.0015)
    return m


def test_oversized_domain_still_removes_spheres_at_its_faces(tmp_path):
    """A 20 cm domain around 1 mm spheres: shrink-wrapped box, and spheres crossing a domain
    face are still removed there (fix evaporate), with the same bookkeeping as 'f' faces."""
    job, frames = run(_pair_leaving(0.1), tmp_path)
    script = job.script.read_text()
    assert "boundary        m m m" in script
    assert "region          fl_domain block -0.1 0.1 -0.1 0.1 -0.1 0.1 side out units box" in script
    assert "thermo_modify   lost ignore lost/bond ignore" in script     # the bond loses a sphere
    assert any(k == "oversized domain" for k, _ in job.warnings)
    assert frames[0].sphere_rows.tolist() == [0, 1, 2]
    assert frames[-1].sphere_rows.tolist() == [0]
    last = frames[-1]
    assert last.bond_alive.tolist() == [False]
    assert last.bond_end_time[0] == pytest.approx(0.0007, abs=2e-7)
    # LAMMPS itself deleted them (the dump, not only the frame filter) near the face
    raw = list(iter_frames(job.frames))
    assert raw[-1].column("id").tolist() == [1]
    assert raw[-1].hi[0] < 0.1 + 0.0005 and (raw[-1].hi - raw[-1].lo)[1:].max() < 0.01


def test_oversized_domain_with_a_periodic_axis(tmp_path):
    """Periodic x (a 20 cm periodic box) stays periodic; y and z are shrink-wrapped and a
    sphere leaving through y = 0.1 is removed, one crossing x = 0.1 wraps."""
    mats, contacts = gm.two_materials()
    box = (np.full(3, -0.1), np.full(3, 0.1))
    m = gm.model(gm.spheres([[0.0995, 0, 0], [0, 0.0993, 0]], R, [0, 0], mats, v=[[1.0, 0, 0], [0, 1.0, 0]]),
                 mats, contacts, dt=1e-7, t_end=0.0015, save_every_time=0.0005, domain=box,
                 periodic=(True, False, False), periodic_box=box)
    job, frames = run(m, tmp_path)
    script = job.script.read_text()
    assert "boundary        p m m" in script
    assert "region          fl_domain block INF INF -0.1 0.1 -0.1 0.1 side out units box" in script
    assert frames[-1].sphere_rows.tolist() == [0]
    assert frames[-1].position[0, 0] == pytest.approx(0.0995 + 0.0015 - 0.2, abs=1e-12)


def test_domain_that_fits_keeps_f_faces(tmp_path):
    """Not oversized: exactly the previous translation ('f' faces at the domain)."""
    job, frames = run(_pair_leaving(0.01), tmp_path)
    script = job.script.read_text()
    assert "boundary        f f f" in script and "evaporate" not in script
    assert frames[-1].sphere_rows.tolist() == [0]
    assert frames[-1].bond_end_time[0] == pytest.approx(0.0007, abs=2e-7)


def test_sparse_spheres_get_bounded_bins(tmp_path):
    """Spheres 2 m apart without a domain: default bins would be ~3e10 (LAMMPS: "Too many
    neighbor bins"); bins are coarsened instead, and the run is exact free flight."""
    mats, contacts = gm.two_materials()
    x = [[0, 0, 0], [2.0, 0, 0], [0, 2.0, 0], [0, 0, 2.0]]
    v = [[0.1, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]]
    m = gm.model(gm.spheres(x, R, [0] * 4, mats, v=v), mats, contacts, dt=1e-6, t_end=1e-3,
                 save_every_time=5e-4)
    job, frames = run(m, tmp_path)
    script = job.script.read_text()
    assert "neigh_modify    binsize" in script and "atom_modify     sort 1000" in script
    assert frames[-1].position[0, 0] == pytest.approx(0.1 * 1e-3, rel=1e-9)


def test_one_far_sphere_uses_neighbour_lists_without_bins(tmp_path):
    """Two spheres 1e6 m apart along x only: no bin size fits LAMMPS' limits (bins <= 100 x
    the thinnest box extent), so neighbour lists are built without bins."""
    mats, contacts = gm.two_materials()
    m = gm.model(gm.spheres([[0, 0, 0], [1e6, 0, 0]], R, [0, 0], mats, v=[[0, 0, -1.0], [0, 0, 0]]),
                 mats, contacts, dt=1e-6, t_end=1e-4, save_every_time=5e-5)
    job, frames = run(m, tmp_path)
    assert "neighbor        0.00025 nsq" in job.script.read_text()
    assert frames[-1].step == 101          # cmusen's last step: its summed time reaches 1e-4 s
    assert frames[-1].position[0, 2] == pytest.approx(-101e-6, rel=1e-9)


def test_clipped_tiling_is_the_full_tiling_inside_the_box():
    rng = np.random.default_rng(7)
    for k in range(30):
        v = rng.normal(size=(4, 3, 3)) * 0.01
        lo = rng.normal(size=3) * 0.004 - 0.003
        hi = lo + np.abs(rng.normal(size=3)) * 0.012
        if k % 3 == 0:
            lo[k % 2], hi[k % 2] = -np.inf, np.inf
        p, o = tile_triangles(v, 0.0004)
        inside = ((p >= lo) & (p <= hi)).all(axis=1)
        q, w = tile_triangles_within(v, 0.0004, lo, hi)
        assert np.array_equal(p[inside], q) and np.array_equal(o[inside], w)
        assert gj.tile_estimate(v, 0.0004) >= len(p)


@pytest.fixture
def stock_styles():
    """The wall-particle tiling is the stock representation: fibrelmp's styles off."""
    from fibrelmp import lammps_styles

    previous = lammps_styles.request_stock(True)
    yield
    lammps_styles.request_stock(previous)


def _drop_on_triangle():
    """A sphere falling 0.3 mm onto a 4 cm triangle (tiled, not a box) and bouncing."""
    mats, contacts = gm.two_materials()
    m = gm.model(gm.spheres([[0.0, 0.0, R + 0.0003]], R, [0], mats, v=[[0.05, 0, 0]]), mats, contacts,
                 dt=1e-6, t_end=0.012, save_every_time=0.003, gravity=np.array([0, 0, -G]))
    gm.add_geometry(m, "Plate", np.array([[[-0.02, -0.02, 0], [0.02, -0.02, 0], [0.0, 0.03, 0]]]), 1)
    return m


def test_tiles_within_reach_give_the_same_bounce(tmp_path, monkeypatch, stock_styles):
    full_job, full = run(_drop_on_triangle(), tmp_path, "full")
    monkeypatch.setattr(tiles, "TILE_CLIP_MIN", 0)
    clip_job, clipped = run(_drop_on_triangle(), tmp_path, "clipped")
    n_full = len(full_job.wall_plans[0].tile_ids)
    n_clip = len(clip_job.wall_plans[0].tile_ids)
    assert n_clip < n_full / 4
    assert "fl_sphere_beyond_wall_particles" in clip_job.script.read_text()
    assert full[-1].velocity[0, 2] != 0.0            # it did bounce
    for a, b in zip(full, clipped):
        np.testing.assert_allclose(b.position, a.position, rtol=0, atol=1e-12)
        np.testing.assert_allclose(b.velocity, a.velocity, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(b.triangle_force, a.triangle_force, rtol=1e-9, atol=1e-12)


def test_sphere_leaving_the_tiled_region_stops_the_run(tmp_path, monkeypatch, stock_styles):
    monkeypatch.setattr(tiles, "TILE_CLIP_MIN", 0)
    monkeypatch.setattr(reach, "REACH_SAFETY", 1e-6)       # a wrong reach estimate
    m = _drop_on_triangle()
    m.spheres.velocity[0] = [2.0, 0, 0]
    with pytest.raises(RunError, match="fl_sphere_beyond_wall_particles"):
        run(m, tmp_path)


# ---------------------------------------------------------------------------------------
# 2. huge DEMDF coordinates: no cKDTree overflow
def test_close_pairs_any_finite_coordinates():
    from fibrelmp.sanity import close_pairs

    x = np.array([[-1e308, 0, 0], [1e308, 0, 0], [1, 0, 0], [1.5, 0, 0], [1e200, 0, 0], [1e200, 1, 0]])
    assert close_pairs(x, 1.0).tolist() == [[2, 3], [4, 5]]
    rng = np.random.default_rng(0)
    y = rng.random((500, 3))
    from scipy.spatial import cKDTree
    want = {tuple(p) for p in cKDTree(y).query_pairs(0.05, output_type="ndarray").tolist()}
    assert {tuple(p) for p in close_pairs(y, 0.05).tolist()} == want


def _demdf_doc(tmp_path, far: float, domain_hi: float):
    doc = json.loads((REPO / "tests/bad_inputs/demdf/good.json").read_text())
    doc["domain"] = [[0, 0, 0], [domain_hi] * 3]
    doc["bodyForce"] = [0, 0, 0]
    doc["timeEnd"] = 0.01
    for p in doc["objects"]["particles"]:
        p[3] = 0
    doc["objects"]["particles"][1][0] = far
    path = tmp_path / "huge.json"
    path.write_text(json.dumps(doc))
    return path


def test_demdf_huge_domain_and_coordinates(tmp_path):
    """A 1e300 domain with a particle at x = 1e200 used to end in a traceback (cKDTree:
    "Encountering floating point overflow"); now it reads and runs."""
    from fibrelmp.translate.demdf import reader as demdf

    path = _demdf_doc(tmp_path, 1e200, 1e300)
    model = demdf.read(path)
    assert model.spheres.position[1, 0] == 1e200
    job, frames = run(model, tmp_path)
    assert frames[-1].position[:, 0].tolist() == [1.0, 1e200]


def test_demdf_huge_domain_normal_particles_run(tmp_path):
    from fibrelmp.translate.demdf import reader as demdf

    job, frames = run(demdf.read(_demdf_doc(tmp_path, 3.0, 1e300)), tmp_path)
    assert "boundary        m m m" in job.script.read_text()
    assert frames[-1].position[:, 0].tolist() == [1.0, 3.0]


# ---------------------------------------------------------------------------------------
# 3. tiny time steps: InputError, never OverflowError
def test_rolling_spring_tiny_step_is_an_input_error():
    k, g = gj.rolling_spring(1e-6, 1e-6)
    assert k == pytest.approx(0.4 * 1e-6 * 1e10) and g == pytest.approx(2 * math.sqrt(0.4 * k * 1e-6))
    with pytest.raises(InputError, match=r"scene.txt: time step 1e-200 is too small"):
        gj.rolling_spring(1e-6, 1e-200, "scene.txt")


@pytest.mark.parametrize("dt,t_end,what", [(1e-310, 1e-300, "rolling-resistance spring"),
                                          (1e-200, 1e-4, "more than LAMMPS can count"),
                                          (1e-320, 1e-4, "more than LAMMPS can count")])
def test_tiny_step_model_is_an_input_error(tmp_path, dt, t_end, what):
    mats, contacts = gm.two_materials()
    m = gm.model(gm.spheres([[0, 0, 0]], R, [0], mats), mats, contacts, dt=dt, t_end=t_end,
                 save_every_time=t_end)
    with pytest.raises(InputError, match=what) as info:
        gj.build_granular_job(m, tmp_path)
    assert str(info.value).startswith("test_model.txt: time step")


# ---------------------------------------------------------------------------------------
# 4. FibreNet springs / angle legs spanning half a periodic box
FN_INPUT = """model_file model.txt
output_file out
type A
pair hs A A 100
box_size 10 10 10
box_type pbc
box_wall_rep 100
box_unit_cell 1.0
cutoff 1.0
step 0.001
lambda 0.5
run 20
output_freq 10
output_data all
output_type all
"""


def _bead(x, y=1.0, tag=1):
    return f"BEAD\tA\t{tag}\t0\t0.3\t1.0\t{x}\t{y}\t1.0\t0\t0\t0\t0\t0\t0\t{x}\t{y}\t1.0\n"


def _fibrenet_case(tmp_path, model: str, inp: str = FN_INPUT):
    (tmp_path / "model.txt").write_text(model)
    (tmp_path / "input.txt").write_text(inp)
    return tmp_path / "input.txt"


def test_fibrenet_spring_longer_than_half_the_periodic_box_is_refused(tmp_path):
    """FibreNet acts on the unwrapped vector (length 6, at rest: force 0); LAMMPS would take
    the nearest image (length 4: force 200).  Refused with the model line."""
    path = _fibrenet_case(tmp_path, _bead(1.0) + _bead(7.0, tag=2) + "SPRING\tHR\t0\t0\t1\t6.0\t100\n")
    with pytest.raises(InputError) as info:
        read_fibrenet(path)
    msg = str(info.value)
    assert "model.txt:3:" in msg and "beads 0 and 1" in msg and "nearest periodic image (length 4)" in msg


def test_fibrenet_angle_leg_longer_than_half_the_box_is_refused(tmp_path):
    model = (_bead(1.0) + _bead(2.0) + _bead(2.0, y=7.5) + "SPRING\tHR\t0\t0\t1\t1.0\t100\n"
             + "ANGLE\tHR\t0\t0\t1\t2\t0\t0\t1.5708\t10\n")
    with pytest.raises(InputError, match=r"model.txt:5: ANGLE: the angle leg between beads 1 and 2"):
        read_fibrenet(_fibrenet_case(tmp_path, model))


def test_fibrenet_long_spring_in_a_finite_box_is_fine(tmp_path):
    path = _fibrenet_case(tmp_path, _bead(1.0) + _bead(7.0, tag=2) + "SPRING\tHR\t0\t0\t1\t6.0\t100\n",
                          FN_INPUT.replace("box_type pbc", "box_type finite"))
    assert read_fibrenet(path).bonds.count == 1


# ---------------------------------------------------------------------------------------
# 5. FibreNet drops beads outside [0, L) of a finite box from its contact grid
def _divergence_warning():
    return getattr(to_fibrenet, "FibreNetDivergenceWarning", None) or type("Missing", (UserWarning,), {})


def _frame(step, x, boundary="mm"):
    x = np.asarray(x, float)
    n = len(x)
    return Frame(step=step, lo=np.full(3, -1.0), hi=np.full(3, 6.0), boundary=(boundary,) * 3,
                 columns={"id": np.arange(1, n + 1, dtype=float), "type": np.ones(n),
                          "x": x[:, 0], "y": x[:, 1], "z": x[:, 2],
                          "vx": np.zeros(n), "vy": np.zeros(n), "vz": np.zeros(n),
                          "fx": np.zeros(n), "fy": np.zeros(n), "fz": np.zeros(n)})


def test_write_fibrenet_warns_once_when_beads_leave_the_finite_box(tmp_path):
    inside = [[1, 1, 1], [2, 2, 2], [3, 3, 3]]
    frames = [_frame(0, inside), _frame(10, [[1, 1, 1], [-0.1, 2, 2], [3, 5.0, 3]]),
              _frame(20, [[-0.2, 1, 1], [-0.1, 2, 2], [3, 3, 3]])]
    got = []
    warning = _divergence_warning()
    write_fibrenet(frames, "out", tmp_path, ("position",), {1: "A"}, 0.001, np.full(3, 5.0), None,
                   warn=lambda kind, text: got.append((kind, text)))
    assert len(got) == 1 and got[0][0] == "beads outside finite box"
    assert "step 10" in got[0][1] and "(2 bead(s) then)" in got[0][1]      # x = -0.1 and y = L
    # no callback: Python's warnings module (what `fibrelmp run` prints today)
    with pytest.warns(warning, match="step 10"):
        write_fibrenet(frames, "out2", tmp_path, ("position",), {1: "A"}, 0.001, np.full(3, 5.0), None)
    # periodic boxes, or frames without FibreNet's box (post-processing): nothing to say
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_fibrenet([_frame(0, [[-0.1, 7, 1]], "pp")], "p", tmp_path, ("position",), {1: "A"}, 0.001,
                       np.full(3, 5.0), None)
        write_fibrenet(frames, "q", tmp_path, ("position",), {1: "A"}, 0.001, None, None)


def test_fibrenet_run_warns_when_a_bead_is_pressed_into_a_wall(tmp_path):
    model = _bead(0.5) + _bead(1.0, tag=2)
    inp = (FN_INPUT.replace("box_type pbc", "box_type finite").replace("run 20", "run 400")
           .replace("output_freq 10", "output_freq 100")
           + "modif_bead id 0 velocity -20 0 0\n")
    path = _fibrenet_case(tmp_path, model, inp)
    m = read_fibrenet(path)
    said = len(m.warnings)
    run_fibrenet(m, out=tmp_path / "out", progress=False)   # run warnings join the model's (the CLI prints them)
    assert any("outside the finite box" in text for _, text in m.warnings[said:]), m.warnings
    import subprocess
    import sys
    cli = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "run", str(path), "-o", str(tmp_path / "cli")],
                         capture_output=True, text=True, timeout=300)
    assert cli.returncode == 0 and "outside the finite box" in cli.stderr, cli.stderr
