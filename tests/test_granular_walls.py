"""Walls, wall motion, domain, periodicity and 2D of the granular LAMMPS translation.

Models are built directly in Python (tests/granular_models.py); expectations come from
kinematics, Hertz's law and a numerical integration of MUSEN's wall-motion equation
dx/dt = v + w x (x - c), all independent of the translator.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from fibrelmp import lammps_styles
from fibrelmp.errors import InputError
from fibrelmp.granmodel import ContactLaw, ForceInterval, hertz_effective
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.translate.granular_job import describe_walls
from fibrelmp.translate.granular.geometry import (detect_box, detect_cylinder, detect_oriented_box,
                                                  nearest_triangle, closest_points, tile_triangles)
from fibrelmp.translate.granular.kinematics import geometry_kinematics

from . import granular_models as gm
from .granular_models import run
from .conftest import REPO, data_path, styles_or_skip

R = 0.0005
G = 9.81


@pytest.fixture(autouse=True)
def stock_styles():
    """Most tests here check the stock LAMMPS representation (regions, wall particles, planes):
    fibrelmp's styles are switched off unless a test asks for them (``mesh_styles``)."""
    previous = lammps_styles.request_stock(True)
    yield
    lammps_styles.request_stock(previous)


def mesh_styles() -> None:
    """Use fibrelmp's styles (MUSEN geometries become fix musen/wall/mesh triangles)."""
    lammps_styles.request_stock(False)
    styles_or_skip()




def static_overlap(mats, r=R):
    es, _ = hertz_effective(mats[0], mats[1])
    m = mats[0].density * 4 / 3 * math.pi * r ** 3
    return (m * G / (4 / 3 * es * math.sqrt(r))) ** (2 / 3)


FLOOR = [[-0.004, -0.004, 0], [0.004, -0.004, 0], [0.004, 0.004, 0], [-0.004, 0.004, 0]]


# ---------------------------------------------------------------------------------------
# shape detection
def singel_particle_plate() -> np.ndarray:
    """The 12 triangles of geometry 'Plate' in MUSEN's SingelParticle_text.txt (old format:
    12 = V1, 31 = V2 (+0), 16 = V3), read straight from the reference copy."""
    path = data_path("real-inputs", "musen", "SingelParticle_text.txt")
    tris = []
    for line in path.read_text().splitlines():
        w = line.split()
        if len(w) > 3 and w[0] == "0" and w[2] == "1" and w[3] == "14":
            def after(tag, k):
                i = w.index(tag, w.index("2"))
                return [float(t) for t in w[i + 1:i + 1 + k]]
            tris.append([after("12", 3), after("31", 3), after("16", 3)])
    return np.array(tris)


def test_singel_particle_plate_is_a_box():
    v = singel_particle_plate()
    assert v.shape == (12, 3, 3)
    box = detect_box(v)
    assert box is not None and box.open_faces == [] and box.flat_axis is None
    assert box.lo == pytest.approx([-0.00598675, -0.00594779, -0.002])
    assert box.hi == pytest.approx([0.00598675, 0.00594779, -0.001])


def test_shape_detection_variants():
    box = gm.box_triangles([0, 0, 0], [1, 2, 3])
    assert detect_box(box).open_faces == []
    no_lid = box[[k for k in range(12) if k not in (10, 11)]]          # drop the zhi face
    assert detect_box(no_lid).open_faces == [6]
    plate = gm.rect_triangles(FLOOR)
    assert detect_box(plate).flat_axis == 2
    assert detect_box(plate[:1]) is None                                # a lone triangle
    half = box[:11]                                                     # a face half missing
    assert detect_box(half) is None
    skew = plate.copy()
    skew[:, :, 2] += 0.1 * skew[:, :, 0]
    assert detect_box(skew) is None and detect_cylinder(skew) is None
    rot = gm.box_triangles([0, 0, 0], [1, 2, 3]) @ np.array([[0.6, -0.8, 0], [0.8, 0.6, 0], [0, 0, 1.0]]).T
    tilted = detect_oriented_box(rot)
    assert tilted is not None and tilted.frame is not None and tilted.open_faces == []
    assert sorted(np.round(tilted.hi - tilted.lo, 12)) == [1, 2, 3]
    assert detect_oriented_box(skew) is not None          # a plate, just tilted about y
    trap = gm.rect_triangles([[0, 0, 0], [1, 0, 0], [0.8, 1, 0], [0.2, 1, 0]])
    assert detect_oriented_box(trap) is None
    cyl = cylinder_triangles(0.01, 0.0, 0.05, 48, caps=(True, False))
    c = detect_cylinder(cyl)
    assert c is not None and c.axis == 2 and c.open_faces == [2] and c.nseg == 48
    assert c.radius == pytest.approx(0.01 * math.cos(math.pi / 48))
    assert detect_box(cyl) is None


def cylinder_triangles(radius, z0, z1, n, caps=(True, True), centre=(0.0, 0.0)):
    ang = 2 * math.pi * np.arange(n) / n
    ring = np.stack([centre[0] + radius * np.cos(ang), centre[1] + radius * np.sin(ang)], 1)
    tris = []
    for k in range(n):
        a, b = ring[k], ring[(k + 1) % n]
        tris.append([[*a, z0], [*b, z0], [*b, z1]])
        tris.append([[*a, z0], [*b, z1], [*a, z1]])
        for z, want in ((z0, caps[0]), (z1, caps[1])):
            if want:
                tris.append([[centre[0], centre[1], z], [*a, z], [*b, z]])
    return np.array(tris)


def test_tiles_cover_triangle_with_spacing():
    tri = np.array([[[0, 0, 0], [1.0, 0, 0], [0, 1.0, 0]]])
    p, owner = tile_triangles(np.vstack([tri, tri + [0, 0, 0]]), 0.1)
    assert (owner == 0).all()                      # the duplicate triangle adds no points
    assert len(p) == 136                           # longest edge sqrt(2): 15 divisions, 16 x 17 / 2 points
    # every point of the triangle is within spacing/sqrt(3) of a tile
    rng = np.random.default_rng(0)
    a, b = rng.uniform(size=(2, 2000))
    keep = a + b <= 1
    q = np.stack([a[keep], b[keep], np.zeros(keep.sum())], 1)
    d = np.sqrt(((q[:, None, :] - p[None]) ** 2).sum(-1)).min(1)
    assert d.max() <= 0.1 / math.sqrt(3) + 1e-12


def test_closest_triangle_distance_matches_brute_force():
    rng = np.random.default_rng(2)
    tri = rng.normal(size=(7, 3, 3))
    p = rng.normal(size=(50, 3)) * 2
    d2 = closest_points(p, tri)
    # brute force: dense barycentric sampling
    u, v = np.meshgrid(np.linspace(0, 1, 301), np.linspace(0, 1, 301))
    keep = u + v <= 1
    u, v = u[keep], v[keep]
    for k in range(len(tri)):
        s = tri[k, 0] + u[:, None] * (tri[k, 1] - tri[k, 0]) + v[:, None] * (tri[k, 2] - tri[k, 0])
        brute = ((p[:, None, :] - s[None]) ** 2).sum(-1).min(1)
        assert np.all(d2[:, k] <= brute + 1e-12)
        assert np.allclose(d2[:, k], brute, rtol=2e-2, atol=1e-4)
    assert (nearest_triangle(p, tri) == d2.argmin(1)).all()


def test_describe_walls_and_motion_errors():
    mats, contacts = gm.two_materials()
    m = gm.model(gm.spheres([[0, 0, 0.002]], R, [0], mats), mats, contacts, dt=1e-7, t_end=0.01)
    gm.add_geometry(m, "Plate", gm.box_triangles([-0.006, -0.006, -0.002], [0.006, 0.006, -0.001]), 1)
    gm.add_geometry(m, "Funnel", gm.rect_triangles(FLOOR)[:1] + [0, 0, -0.01], 1)
    m.planes.append(gm.plane([0, 0, 1], [0, 0, -0.05], 1))
    lines = describe_walls(m)
    assert lines[0].startswith("Plate: axis-aligned box") and "region block" in lines[0]
    assert lines[1].startswith("Funnel: tiled with frozen wall particles")
    assert lines[2].startswith("plane 1: plane z = -0.05") and "wall/gran zplane" in lines[2]
    m.geometries[0].motion_type = 2
    m.geometries[0].force_motion = [ForceInterval(1.0, True, np.zeros(3), np.zeros(3), np.zeros(3))]
    with pytest.raises(InputError, match="force-dependent geometry motion needs fibrelmp's LAMMPS styles"):
        describe_walls(m)


def test_describe_walls_with_fibrelmp_styles():
    """With the plugin every MUSEN geometry is its own triangles in fix musen/wall/mesh; walls
    in no geometry are not simulated (MUSEN's simulator ignores them); DEMDF-style planes keep
    fix wall/gran."""
    mesh_styles()
    mats, contacts = gm.two_materials()
    m = gm.model(gm.spheres([[0, 0, 0.002]], R, [0], mats), mats, contacts, dt=1e-7, t_end=0.01)
    gm.add_geometry(m, "Plate", gm.box_triangles([-0.006, -0.006, -0.002], [0.006, 0.006, -0.001]), 1)
    gm.add_geometry(m, "Drum", cylinder_triangles(0.004, 0.0, 0.01, 24), 1,
                    motion=[gm.interval(0.0, 0.005, w=(0, 0, 2.0))])
    m.triangles.ids = np.arange(m.triangles.count + 1)
    extra = gm.rect_triangles(FLOOR)[:1]
    m.triangles.vertices = np.concatenate([m.triangles.vertices, extra])
    for name in ("material", "active_start", "active_end"):
        a = getattr(m.triangles, name)
        setattr(m.triangles, name, np.concatenate([a, a[:1]]))
    m.triangles.velocity = np.concatenate([m.triangles.velocity, np.zeros((1, 3))])
    m.planes.append(gm.plane([0, 0, 1], [0, 0, -0.05], 1))
    lines = describe_walls(m)
    assert lines[0] == ("Plate: 12 exact triangles -> fix musen/wall/mesh (MUSEN's particle-wall contact, "
                        "face/edge/vertex)")
    assert lines[1].startswith("Drum: 96 exact triangles -> fix musen/wall/mesh") and "moving" in lines[1]
    assert lines[2].startswith("(walls in no geometry): in no geometry: not simulated")
    assert lines[3].startswith("plane 1: plane z = -0.05") and "wall/gran zplane" in lines[3]


# ---------------------------------------------------------------------------------------
# kinematics against a numerical integration of dx/dt = v + w x (x - c)
def _integrate(verts0, intervals, t_end, around_centre, dt=1e-4, t=0.0):
    """RK4 from t to t_end, stepping exactly onto every interval boundary (the rate is
    discontinuous there)."""
    x = verts0.reshape(-1, 3).copy()
    edges = sorted({iv.t_begin for iv in intervals} | {iv.t_end for iv in intervals} | {t_end})

    def rate(x, iv):
        if iv is None:
            return np.zeros_like(x)
        c = x.mean(0) if around_centre else iv.centre
        return iv.velocity + np.cross(iv.angular_velocity, x - c)

    while t < t_end - 1e-15:
        nxt = min(e for e in edges if e > t + 1e-15)
        h = min(dt, nxt - t)
        iv = next((iv for iv in intervals if iv.t_begin <= t + h / 2 < iv.t_end), None)
        k1 = rate(x, iv)
        k2 = rate(x + h / 2 * k1, iv)
        k3 = rate(x + h / 2 * k2, iv)
        k4 = rate(x + h * k3, iv)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t = nxt if h == nxt - t else t + h
    return x.reshape(verts0.shape)


@pytest.mark.parametrize("around_centre", [False, True])
def test_kinematics_matches_numerical_integration(around_centre):
    verts = gm.box_triangles([0.0, 0.0, 0.0], [0.02, 0.01, 0.005]) + [0.03, -0.01, 0.0]
    intervals = [gm.interval(0.0, 0.1, v=(0.1, 0.0, 0.05), centre=(0.01, 0.0, 0.0), w=(0, 0, 3.0)),
                 gm.interval(0.15, 0.3, v=(0.0, -0.2, 0.0), centre=(0.0, 0.02, 0.0), w=(1.0, 0.5, -2.0)),
                 gm.interval(0.3, 0.4, v=(0.05, 0.0, 0.0))]
    geom = gm.Geometry("g", "G", 0.0, (False,) * 3, around_centre, 1, intervals, np.arange(12))
    kin = geometry_kinematics(geom, verts, 0.0, 1.0)
    assert kin.rotating and kin.single_axis is None          # two different rotation axes
    ref, t_prev = verts, 0.0
    for t in (0.05, 0.1, 0.12, 0.2, 0.35, 0.6):
        R, b = kin.transform(t)
        mine = verts @ R.T + b
        ref = _integrate(ref, intervals, t, around_centre, t=t_prev)
        t_prev = t
        assert np.abs(mine - ref).max() < 1e-11, t
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert kin.velocity(0.05).tolist() == [0.1, 0.0, 0.05]
    # between intervals the geometry stands still, but MUSEN keeps (and writes) the last
    # interval's wall velocity (CPUSimulator::MoveWalls skips still geometries)
    assert kin.velocity(0.12).tolist() == [0.1, 0.0, 0.05]
    assert kin.wall_state(0.12)[1] is False and kin.wall_state(0.05)[1] is True
    assert kin.velocity(0.6).tolist() == [0.05, 0.0, 0.0]
    assert kin.kept_velocity(0.0, 1.0)[0] == pytest.approx(0.1)


# ---------------------------------------------------------------------------------------
# moving walls push spheres
@pytest.mark.parametrize("representation", ["region", pytest.param("tiles", marks=pytest.mark.tier2), "mesh"])
def test_moving_plate_pushes_sphere(tmp_path, representation):
    """A plate rising at constant speed V under a resting sphere (gravity): the sphere ends up
    moving with the plate, at the plate height + R - static Hertz overlap."""
    mats, contacts = gm.two_materials()
    V = 0.02
    d0 = static_overlap(mats)
    sph = gm.spheres([[0.0003, 0.0002, R - d0]], R, [0], mats)
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.03, save_every_time=0.005,
                 gravity=np.array([0, 0, -G]))
    if representation == "mesh":
        mesh_styles()
    if representation in ("region", "mesh"):
        verts = gm.rect_triangles(FLOOR)
    else:      # a single triangle is not a box/plate shape: tiled with wall particles
        verts = np.array([[[-0.004, -0.004, 0], [0.008, -0.004, 0], [-0.004, 0.008, 0]]])
    gm.add_geometry(m, "plate", verts, 1, motion=[gm.interval(0.0, 1.0, v=(0, 0, V))])
    job, frames = run(m, tmp_path)
    assert ("tiled" in job.walls[0][1]) == (representation == "tiles")
    assert ("musen/wall/mesh" in job.walls[0][1]) == (representation == "mesh")
    last, prev = frames[-1], frames[-2]
    # MUSEN's walls (the mesh) are one step ahead: cmusen's prediction iteration moves them by
    # V dt before its first step (docs/musen.md, "Walls one step ahead")
    plate_z = V * (last.time + (1e-7 if representation == "mesh" else 0.0))
    assert last.triangle_vertices[:, :, 2] == pytest.approx(np.full((len(verts), 3), plate_z))
    assert last.triangle_velocity[0].tolist() == [0.0, 0.0, V]
    gap = last.position[0, 2] - (plate_z + R - d0)
    mean_v = (last.position[0, 2] - prev.position[0, 2]) / (last.time - prev.time)
    print(f"\n{representation}: sphere z - (plate + R - delta0) = {gap:.3e} m, mean vz {mean_v:.5f} (V = {V})")
    if representation in ("region", "mesh"):
        assert abs(gap) < 1e-3 * d0 + 1e-12
        assert last.velocity[0, 2] == pytest.approx(V, rel=1e-3)
        assert mean_v == pytest.approx(V, rel=1e-3)
    else:      # bumpy tiled surface: spheres settle up to ~0.05 R into the hollows
        assert abs(gap) < 0.06 * R
        assert mean_v == pytest.approx(V, rel=0.05)


@pytest.mark.parametrize("representation", ["region", "mesh"])
def test_static_plate_triangle_forces_carry_weight(tmp_path, representation):
    """A sphere resting on SingelParticle's 'Plate' (a region block, or its triangles): the
    triangle forces sum to minus its weight, attributed to the top face's triangles only."""
    if representation == "mesh":
        mesh_styles()
    mats, contacts = gm.two_materials()
    d0 = static_overlap(mats)
    verts = gm.oriented(gm.box_triangles([-0.006, -0.006, -0.002], [0.006, 0.006, -0.001]))
    sph = gm.spheres([[0.001, 0.0005, -0.001 + R - d0]], R, [0], mats)
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.002, save_every_steps=10000,
                 gravity=np.array([0, 0, -G]))
    gm.add_geometry(m, "Plate", verts, 1)
    _, frames = run(m, tmp_path)
    f = frames[-1]
    weight = m.spheres.mass[0] * G
    assert f.triangle_force.sum(0) == pytest.approx([0, 0, -weight], rel=1e-6, abs=1e-15)
    if representation == "mesh":          # on one triangle: the one under the sphere
        assert len(np.flatnonzero(np.abs(f.triangle_force).sum(1) > 0)) == 1
    top = np.flatnonzero(np.abs(verts[:, :, 2] + 0.001).max(1) < 1e-12)
    assert set(np.flatnonzero(np.abs(f.triangle_force).sum(1) > 0)) <= set(top)
    assert np.all(f.triangle_velocity == 0)


@pytest.mark.parametrize("representation", ["region", "tilted-region", pytest.param("tiles", marks=pytest.mark.tier2),
                                            "mesh"])
def test_rotating_plate_stays_under_sphere(tmp_path, representation):
    """A plate tilting about the y axis through its centre: the sphere resting on it stays at
    distance R - delta from the plate where the frames say the plate is."""
    if representation == "mesh":
        mesh_styles()
    mats, contacts = gm.two_materials()
    contacts[(0, 1)] = ContactLaw(*hertz_effective(mats[0], mats[1]), 0.3, 2.0, 0.0)
    d0 = static_overlap(mats)
    tilt = 0.2 if representation == "tilted-region" else 0.0
    Ry = np.array([[math.cos(tilt), 0, math.sin(tilt)], [0, 1, 0], [-math.sin(tilt), 0, math.cos(tilt)]])
    sph = gm.spheres([Ry @ [0.0, 0.0, R - d0]], R, [0], mats)
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.004, save_every_time=0.001,
                 gravity=np.array([0, 0, -G]))
    if representation == "tiles":
        verts = np.array([[[-0.003, -0.003, 0], [0.005, -0.003, 0], [-0.003, 0.005, 0]]])
    else:
        verts = gm.rect_triangles(FLOOR) @ Ry.T
    gm.add_geometry(m, "tilt", verts, 1, motion=[gm.interval(0.0, 1.0, centre=(0, 0, 0), w=(0, 5.0, 0))])
    job, frames = run(m, tmp_path)
    assert ("tiled" in job.walls[0][1]) == (representation == "tiles")
    for f in frames[1:]:
        tri = f.triangle_vertices
        n = np.cross(tri[0, 1] - tri[0, 0], tri[0, 2] - tri[0, 0])
        n /= np.linalg.norm(n)
        th = 5.0 * f.time + tilt
        assert n @ [math.sin(th), 0, math.cos(th)] == pytest.approx(1.0, abs=1e-12)
        dist = abs((f.position[0] - tri[0, 0]) @ n)
        print(f"t={f.time:.4f}: distance to plate {dist:.6e} (R - delta0 = {R - d0:.6e})")
        tol = 0.06 * R if representation == "tiles" else 0.05 * d0
        assert abs(dist - (R - d0)) < tol
        assert np.linalg.norm(f.triangle_force.sum(0)) > 0 or representation == "tiles"


@pytest.mark.parametrize("mu, factor, representation", [(0.0, 1.0, "region"), (1.0, 5.0 / 7.0, "region"),
                                                         (0.0, 1.0, "mesh"), (1.0, 5.0 / 7.0, "mesh")])
def test_inclined_plate_slide_and_roll(tmp_path, mu, factor, representation):
    """A rectangle tilted by 25 deg (a rotated region block, or its two triangles): a sphere
    released on it slides with a = g sin(alpha) without friction and rolls with
    a = 5/7 g sin(alpha) with friction."""
    if representation == "mesh":
        mesh_styles()
    mats, contacts = gm.two_materials()
    contacts[(0, 1)] = ContactLaw(*hertz_effective(mats[0], mats[1]), 0.8, mu, 0.0)
    alpha = math.radians(25.0)
    Ry = np.array([[math.cos(alpha), 0, math.sin(alpha)], [0, 1, 0], [-math.sin(alpha), 0, math.cos(alpha)]])
    flat = gm.rect_triangles([[-0.02, -0.005, 0], [0.02, -0.005, 0], [0.02, 0.005, 0], [-0.02, 0.005, 0]])
    verts = flat @ Ry.T + [0.001, 0.002, 0.003]
    n = Ry @ [0, 0, 1.0]
    es, _ = hertz_effective(mats[0], mats[1])
    mass = mats[0].density * 4 / 3 * math.pi * R ** 3
    d0 = (mass * G * math.cos(alpha) / (4 / 3 * es * math.sqrt(R))) ** (2 / 3)
    x0 = np.array([0.001, 0.002, 0.003]) + (R - d0) * n
    m = gm.model(gm.spheres([x0], R, [0], mats), mats, contacts, dt=1e-7, t_end=0.02,
                 save_every_time=0.01, gravity=np.array([0, 0, -G]))
    gm.add_geometry(m, "chute", verts, 1)
    job, frames = run(m, tmp_path)
    assert ("rotated (25 deg about" in job.walls[0][1]) == (representation == "region")
    down = np.array([0, 0, -1.0]) - (-n[2]) * n
    down /= np.linalg.norm(down)
    f = frames[-1]
    s = (f.position[0] - x0) @ down
    expect = 0.5 * factor * G * math.sin(alpha) * f.time ** 2
    print(f"\nmu={mu}: travelled {s:.6e} m, expected {expect:.6e} m; off-plane {(f.position[0] - x0) @ n:.2e}")
    assert s == pytest.approx(expect, rel=1e-5 if mu == 0 else 2e-3)
    assert abs((f.position[0] - x0) @ n) < 1e-3 * d0 + 1e-12
    assert -f.triangle_force.sum(0) @ n == pytest.approx(mass * G * math.cos(alpha), rel=1e-3)


def test_closed_box_container_keeps_sphere_inside(tmp_path):
    """Particles inside a closed box bounce off its inner faces (region side in); a sphere
    outside the same box rests on its lid (side out)."""
    mats, contacts = gm.two_materials()
    sph = gm.spheres([[0.0, 0.0, 0.005], [0.0, 0.0, 0.0105]], R, [0, 0], mats, v=[[0.3, 0.2, 0], [0, 0, 0]])
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.05, save_every_time=0.01,
                 gravity=np.array([0, 0, -G]))
    gm.add_geometry(m, "Box", gm.box_triangles([-0.004, -0.004, 0.0], [0.004, 0.004, 0.01]), 1)
    job, frames = run(m, tmp_path)
    script = job.script.read_text()
    assert "side in" in script and "side out" in script
    for f in frames:
        x = f.position
        assert np.all(np.abs(x[0, :2]) < 0.004) and 0 < x[0, 2] < 0.01
        assert x[1, 2] > 0.01


@pytest.mark.parametrize("representation", ["region", "mesh"])
def test_cylinder_container(tmp_path, representation):
    """A closed faceted cylinder (region cylinder, side in, or its triangles): a sphere resting
    on the bottom cap loads only cap triangles with its weight; a sphere thrown sideways stays
    inside."""
    if representation == "mesh":
        mesh_styles()
    mats, contacts = gm.two_materials()
    d0 = static_overlap(mats)
    verts = gm.oriented(cylinder_triangles(0.004, 0.0, 0.01, 48), outward=False)
    sph = gm.spheres([[0.001, 0.0, R - d0], [-0.001, 0.0, 0.005]], R, [0, 0], mats,
                     v=[[0, 0, 0], [0.0, 0.4, 0.0]])
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.03, save_every_time=0.005,
                 gravity=np.array([0, 0, -G]))
    gm.add_geometry(m, "Drum", verts, 1)
    job, frames = run(m, tmp_path)
    if representation == "region":
        assert "region cylinder" in job.walls[0][1] and "cylinder z" in job.script.read_text()
    else:
        assert "musen/wall/mesh" in job.script.read_text() and "region" not in job.script.read_text()
    inner = 0.004 * math.cos(math.pi / 48)
    for f in frames:
        rho = np.hypot(f.position[:, 0], f.position[:, 1])
        assert np.all(rho < inner - 0.9 * R) and np.all(f.position[:, 2] > 0.9 * R)
    f = frames[0]
    bottom = np.flatnonzero(np.abs(verts[:, :, 2]).max(1) == 0)
    loaded = np.flatnonzero(np.abs(f.triangle_force).sum(1) > 0)
    assert len(loaded) and set(loaded) <= set(bottom)
    assert f.triangle_force.sum(0)[2] == pytest.approx(-m.spheres.mass[0] * G, rel=1e-3)


# ---------------------------------------------------------------------------------------
# planes (DEMDF walls)
def test_planes_axis_aligned_and_tilted(tmp_path):
    mats, contacts = gm.two_materials()
    v = 0.5
    # sphere 0 falls on z = 0 (fix wall/gran), sphere 1 hits a tilted plane head-on (region plane)
    n = np.array([-1.0, 0.0, 1.0]) / math.sqrt(2)
    p = np.array([0.05, 0.0, 0.01])
    x1 = p + n * (1.02 * R)
    sph = gm.spheres([[0, 0, 1.02 * R], x1], R, [0, 0], mats, v=[[0, 0, -v], -v * n])
    m = gm.model(sph, mats, contacts, dt=2e-9, t_end=6e-5, save_every_steps=10000)
    m.planes = [gm.plane([0, 0, 1], [0, 0, 0], 1), gm.plane(n, p, 1)]
    job, frames = run(m, tmp_path)
    f = frames[-1]
    assert f.velocity[0, 2] / v == pytest.approx(0.8, rel=0.01)
    assert (f.velocity[1] @ n) / v == pytest.approx(0.8, rel=0.01)
    assert np.linalg.norm(f.velocity[1] - (f.velocity[1] @ n) * n) < 1e-9
    assert "zplane 0.0 NULL" in job.script.read_text() and "plane 0.05 0.0 0.01" in job.script.read_text()


# ---------------------------------------------------------------------------------------
# domain, activity, periodicity, 2D
def test_domain_drops_outside_and_removes_leaving_spheres(tmp_path):
    mats, contacts = gm.two_materials()
    x = [[0.0, 0.0, 0.0], [0.0095, 0.0, 0.0], [0.02, 0.0, 0.0], [0.0095, 0.0015, 0.0]]
    v = [[0, 0, 0], [1.0, 0, 0], [0, 0, 0], [1.0, 0, 0]]
    sph = gm.spheres(x, R, [0] * 4, mats, v=v)
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.002, save_every_time=0.0005,
                 domain=(np.full(3, -0.01), np.full(3, 0.01)))
    m.bonds = gm.bonds([[0, 2], [1, 3]], 0.0004, [0.02, 0.0015])
    job, frames = run(m, tmp_path)
    assert job.outside_rows.tolist() == [2]
    assert frames[0].sphere_rows.tolist() == [0, 1, 3]
    assert frames[-1].sphere_rows.tolist() == [0]
    # bond 0 lost its sphere at the start; bond 1 ends when its spheres left the domain
    assert frames[0].bond_alive.tolist() == [False, True]
    assert frames[0].bond_end_time[0] == 0.0
    last = frames[-1]
    assert last.bond_alive.tolist() == [False, False]
    # the pair moves rigidly at 1 m/s: it crosses x = 0.01 after 0.0005 s (from x = 0.0095)
    print(f"\nremoval time estimate {last.bond_end_time[1]!r} (exact crossing 0.0005)")
    assert last.bond_end_time[1] == pytest.approx(0.0005, abs=2e-7)


def test_activity_end_removes_sphere_exactly(tmp_path):
    mats, contacts = gm.two_materials()
    sph = gm.spheres([[0, 0, 0], [0.002, 0, 0]], R, [0, 0], mats)
    sph.active_end[1] = 0.00123
    m = gm.model(sph, mats, contacts, dt=1e-5, t_end=0.003, save_every_steps=100)
    m.bonds = gm.bonds([[0, 1]], 0.0004, 0.002)
    job, frames = run(m, tmp_path)
    assert job.deletions[0][0] == 123
    for f in frames:
        assert (1 in f.sphere_rows.tolist()) == (f.step < 123)
    assert frames[-1].bond_alive.tolist() == [False]
    assert frames[-1].bond_end_time[0] == pytest.approx(0.00123, abs=1e-15)


def test_periodic_boundary_wraps(tmp_path):
    mats, contacts = gm.two_materials()
    sph = gm.spheres([[0.009, 0.0, 0.0]], R, [0], mats, v=[[1.0, 0, 0]])
    box = (np.full(3, -0.01), np.full(3, 0.01))
    m = gm.model(sph, mats, contacts, dt=1e-6, t_end=0.004, save_every_steps=1000,
                 domain=box, periodic=(True, False, False), periodic_box=box)
    job, frames = run(m, tmp_path)
    assert job.script.read_text().count("boundary        p f f") == 1
    xs = [f.position[0, 0] for f in frames]
    expect = [((0.009 + 1.0 * f.time + 0.01) % 0.02) - 0.01 for f in frames]
    # equal up to the period: a sphere exactly on the boundary may show on either side of it
    gap = [((x - e + 0.01) % 0.02) - 0.01 for x, e in zip(xs, expect)]
    assert gap == pytest.approx([0.0] * len(xs), abs=1e-12)
    assert all(-0.01 <= x <= 0.01 for x in xs)
    assert len(frames[-1].sphere_rows) == 1


def test_two_dimensional_run(tmp_path):
    mats, contacts = gm.two_materials()
    sph = gm.spheres([[0.0, 0.002, 0.0], [0.0012, 0.004, 0.0]], R, [0, 0], mats, v=[[0.1, 0, 0], [0, 0, 0]])
    m = gm.model(sph, mats, contacts, dt=1e-7, t_end=0.02, save_every_time=0.005,
                 gravity=np.array([0, -G, 0]), dimension=2)
    m.planes = [gm.plane([0, 1, 0], [0, 0, 0], 1)]
    job, frames = run(m, tmp_path)
    script = job.script.read_text()
    assert "dimension       2" in script and "enforce2d" in script
    for f in frames:
        assert np.all(f.position[:, 2] == 0) and np.all(f.velocity[:, 2] == 0)
        assert np.all(f.position[:, 1] > R * 0.99)


# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("representation", ["region", "mesh"])
def test_replay_with_lmp_matches_run(tmp_path, representation):
    """The rendered job replays: the wheel's lmp executable writes the same dumps (with the
    plugin: its plugin load line and fix musen/wall/mesh's triangle forces too)."""
    from fibrelmp._lammps import lmp_executable_env

    if representation == "mesh":
        mesh_styles()

    mats, contacts = gm.two_materials()
    sph = gm.spheres([[0, 0, 0.003], [0.0002, 0.0001, 0.0045]], R, [0, 0], mats)
    m = gm.model(sph, mats, contacts, dt=1e-6, t_end=0.01, save_every_time=0.002,
                 gravity=np.array([0, 0, -G]))
    gm.add_geometry(m, "Plate", gm.oriented(gm.box_triangles([-0.006, -0.006, -0.002], [0.006, 0.006, -0.001])),
                    1, motion=[gm.interval(0.002, 0.008, v=(0, 0, 0.05), w=(0, 0, 1.0))])
    m.bonds = gm.bonds([[0, 1]], 0.0004, 0.0015)
    job, frames = run(m, tmp_path, "run")
    exe = [sys.executable, "-c", "import sys; from lammps.executable import lmp; sys.argv[0]='lmp'; sys.exit(lmp())"]
    proc = subprocess.run(exe + ["-in", "in.lammps", "-log", "none", "-screen", "none"], cwd=job.folder,
                          env=lmp_executable_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    if representation == "mesh":
        forces = list(iter_frames(job.wall_forces))
        assert len(forces) == len(frames) and forces[-1].count == 12
        for fr, fw in zip(frames, forces):
            np.testing.assert_array_equal(fr.triangle_force[job.mesh_rows, 2], fw.columns["fz"])
    replay = list(iter_frames(job.frames))
    assert [f.step for f in replay] == [f.step for f in frames]
    for fr, fd in zip(frames, replay):
        np.testing.assert_array_equal(fr.position[:, 0], fd.columns["x"])
        np.testing.assert_array_equal(fr.velocity[:, 2], fd.columns["vz"])


@pytest.mark.parametrize("representation", ["region", "mesh"])
def test_mpi_two_ranks_match_serial(tmp_path, representation):
    """LAMMPS on every rank, frames on rank 0 only: 2 ranks give the serial frames."""
    import os
    import pickle
    import shutil

    mpiexec = os.path.join(sys.prefix, "bin", "mpiexec")
    if not os.path.exists(mpiexec) and shutil.which("mpiexec") is None:
        pytest.skip("no mpiexec")
    mpiexec = mpiexec if os.path.exists(mpiexec) else shutil.which("mpiexec")
    script = tmp_path / "case.py"
    script.write_text(f"""
import pickle, sys
import numpy as np
sys.path.insert(0, {str(REPO)!r})
from tests import granular_models as gm
from fibrelmp.pipeline.run_model import run_granular
from fibrelmp.runner import mpi_rank_size
mats, contacts = gm.two_materials()
x = np.array([[i * 0.0011, j * 0.0011, 0.002 + k * 0.0011] for i in range(6) for j in range(6) for k in range(3)])
v = np.random.default_rng(0).normal(size=(len(x), 3)) * 0.05
m = gm.model(gm.spheres(x, 0.0005, [0] * len(x), mats, v=v), mats, contacts, dt=1e-7, t_end=0.001,
             save_every_time=0.0005, gravity=np.array([0, 0, -9.81]),
             domain=(np.array([-0.004, -0.004, -0.003]), np.array([0.01, 0.01, 0.01])))
gm.add_geometry(m, "Plate", gm.oriented(gm.box_triangles([-0.003, -0.003, -0.002], [0.009, 0.009, -0.001])), 1)
m.bonds = gm.bonds([[0, 1], [1, 2], [5, 6]], 0.0004, 0.0011)
frames = []
run_granular(m, sys.argv[1], frames.append, progress=False)
rank, size = mpi_rank_size()
if rank == 0:
    pickle.dump([(f.step, f.sphere_rows, f.position, f.bond_alive, f.triangle_force) for f in frames],
                open(sys.argv[1] + ".pkl", "wb"))
else:
    assert not frames
""")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    env.pop("PMI_RANK", None)
    if representation == "mesh":
        mesh_styles()
        env.pop(lammps_styles.ENV_STOCK, None)
    else:
        env[lammps_styles.ENV_STOCK] = "1"
    serial = subprocess.run([sys.executable, str(script), str(tmp_path / "one")], capture_output=True,
                            text=True, timeout=300, env=env)
    assert serial.returncode == 0, serial.stderr
    par = subprocess.run([mpiexec, "-n", "2", sys.executable, str(script), str(tmp_path / "two")],
                         capture_output=True, text=True, timeout=300, env=env)
    assert par.returncode == 0, par.stdout + par.stderr
    a = pickle.loads((tmp_path / "one.pkl").read_bytes())
    b = pickle.loads((tmp_path / "two.pkl").read_bytes())
    # cmusen's summed clock reaches END_TIME one step late: the last time point is step 10001
    assert [x[0] for x in a] == [y[0] for y in b] == [0, 5000, 10000, 10001]
    script = next((tmp_path / "one").rglob("in.lammps")).read_text()
    assert ("musen/wall/mesh" in script) == (representation == "mesh")
    for x, y in zip(a, b):
        assert (x[1] == y[1]).all() and (x[3] == y[3]).all()
        np.testing.assert_allclose(x[2], y[2], rtol=0, atol=1e-12)
        np.testing.assert_allclose(x[4], y[4], rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("where,normals", [
    ("face", [[0, 0, 1]]),                               # on the top face
    ("vertex", [[1, 0, 0], [0, 1, 0], [0, 0, 1]]),       # on the corner: three faces touch it
])
def test_sphere_centre_on_a_wall_gives_the_face_normal_force(tmp_path, where, normals):
    """Was: a sphere centre exactly on a triangle gave nan nan nan (exit 0): the contact
    direction divides by the zero centre-to-contact distance, as MUSEN does (the real cmusen
    1.74.2 gives nan for this scene too).  fibrelmp takes the face normal instead and warns:
    each touched face (one per normal) pushes with Hertz's 4/3 E* sqrt(R) R^1.5 at overlap R."""
    mesh_styles()
    mats, contacts = gm.two_materials()
    verts = gm.oriented(gm.box_triangles([-0.006, -0.006, -0.002], [0.006, 0.006, -0.001]))
    centre = [0.002, -0.001, -0.001] if where == "face" else [0.006, 0.006, -0.001]
    m = gm.model(gm.spheres([centre], R, [0], mats), mats, contacts, dt=1e-7, t_end=2e-7,
                 save_every_steps=1)
    gm.add_geometry(m, "Plate", verts, 1)
    job, frames = run(m, tmp_path)
    assert any(kind == "sphere centre on a wall" for kind, _ in job.warnings)
    glass, steel = mats
    e_star = 1 / ((1 - glass.poisson ** 2) / glass.youngs + (1 - steel.poisson ** 2) / steel.youngs)
    hertz = 4 / 3 * e_star * math.sqrt(R) * R ** 1.5
    np.testing.assert_allclose(frames[0].force[0], hertz * np.sum(normals, axis=0), rtol=1e-12)
    for f in frames:
        assert np.isfinite(f.position).all() and np.isfinite(f.force).all() and np.isfinite(f.triangle_force).all()


def test_sphere_centre_on_a_stock_wall_particle_is_an_input_error(tmp_path):
    """Without fibrelmp's styles a single triangle is tiled with wall particles; a sphere centred
    in its plane on a tile (here its corner) met stock pair granular's zero distance: nan, exit 0
    before the guard.  It is refused before anything runs (MUSEN gives nan there too)."""
    mats, contacts = gm.two_materials()
    tri = np.array([[[0, 0, 0], [0.004, 0, 0], [0, 0.004, 0]]], float)
    m = gm.model(gm.spheres([[0.0, 0.0, 0.0]], R, [0], mats), mats, contacts, dt=1e-7, t_end=2e-7,
                 save_every_steps=1)
    gm.add_geometry(m, "Tri", tri, 1)
    with pytest.raises(InputError, match="sphere 0 has its centre exactly on a wall particle of geometry 'Tri'"):
        run(m, tmp_path)
    assert not (tmp_path / "job" / "in.lammps").exists()
