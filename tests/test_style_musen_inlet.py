"""fix musen/inlet (fibrelmp's LAMMPS plugin) on its own: spheres inserted into an empty box
without motion (no integrator), checked against MUSEN's rule written independently here:
every sphere totally inside the box and free of the others, the mixture fractions in
next_fraction's order (MUSEN's rule, checked against cmusen in test_musen_inlets.py), mass
4/3 pi r^3 rho, |v| the magnitude with directions uniform on the sphere (Kolmogorov-Smirnov at
1 %), compact ids and the inlet log; the same seed gives the same spheres, on 1 or 2 ranks and
across a restart."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.translate.musen.mdem.generators import next_fraction

from .test_style_musen_wall import _run_lmp_script

LO, HI = np.array([-0.04, -0.04, -0.02]), np.array([0.04, 0.04, 0.02])
FRACTIONS = [(1, 0.002, 2500.0, 0.3), (2, 0.004, 1000.0, 0.7)]     # type, diameter, density, share


PLATE = """musen/wall/mesh 1
laws 2
1 0 1e8 1e7 0.8 0.2 0.01
2 0 1e8 1e7 0.8 0.2 0.01
geometries 1
geometry Plate 0 0 0
triangles 2
0 0 -0.05 -0.05 0.0 0.05 -0.05 0.0 0.05 0.05 0.0
0 0 -0.05 -0.05 0.0 0.05 0.05 0.0 -0.05 0.05 0.0
"""


def _script(plugin: str, seed: int, restart_in: str | None = None, restart_out: str | None = None,
            walls: str = "none") -> str:
    fractions = " ".join(f"{t} {d} {rho} {s}" for t, d, rho, s in FRACTIONS)
    box = " ".join(f"{a} {b}" for a, b in zip(LO, HI))
    head = ([f"plugin load {plugin}", f"read_restart {restart_in}"] if restart_in else
            [f"plugin load {plugin}", "units si", "atom_style sphere", "atom_modify map array",
             "boundary f f f", "region b block -0.05 0.05 -0.05 0.05 -0.05 0.05",
             "create_box 2 b"])
    lines = head + [
        "pair_style zero 0.01", "pair_coeff * *", "comm_modify vel yes", "neighbor 0.001 bin",
        "timestep 1e-6", "group spheres empty", "group small type 1", "group large type 2"]
    if walls != "none":
        lines.append(f"fix {walls} spheres musen/wall/mesh plate.mesh")
    lines += [
        f"fix in spheres musen/inlet {seed} box {box} tries 30 walls {walls} velocity random 0.5 "
        f"fractions 2 {fractions} events 3 1 300 3 200 5 100 first_id 1 log inlets.log "
        "groups small large"]
    if restart_out:
        lines += ["run 3", f"write_restart {restart_out}"]
    else:
        lines += ["run 3" if not restart_in else "run 0", "run 3"]
    lines += ["variable small equal count(small)", "variable large equal count(large)",
              'print "groups ${small} ${large}" file groups.txt']
    lines.append("write_dump all custom out.dump id type x y z vx vy vz radius mass "
                 "modify sort id format float %.17g")
    return "\n".join(lines) + "\n"


def _run(plugin: str, folder: Path, seed: int = 7, ranks: int = 1, walls: str = "none") -> dict:
    folder.mkdir(parents=True)
    (folder / "plate.mesh").write_text(PLATE)
    _run_lmp_script(folder, _script(plugin, seed, walls=walls), ranks)
    return next(iter_frames(folder / "out.dump")).columns


@pytest.fixture(scope="module")
def inserted(plugin_path, tmp_path_factory) -> tuple[dict, Path]:
    folder = tmp_path_factory.mktemp("inlet") / "a"
    return _run(plugin_path, folder), folder


def _ks_uniform(sample: np.ndarray, lo: float, hi: float) -> float:
    u = np.sort((sample - lo) / (hi - lo))
    n = len(u)
    return float(max((np.arange(1, n + 1) / n - u).max(), (u - np.arange(n) / n).max()))


def test_spheres_follow_musens_rule(inserted):
    c, folder = inserted
    n = len(c["id"])
    assert n == 600 and (c["id"] == np.arange(1, 601)).all()     # uncrowded: every one made
    log = np.loadtxt(folder / "inlets.log", dtype=np.int64)
    assert (log[:, 1] == np.arange(1, 601)).all()
    assert (log[:, 0] == np.repeat([1, 3, 5], [300, 200, 100])).all()
    made, want = [0, 0], []
    for _ in range(n):
        k = next_fraction(made, [f[3] for f in FRACTIONS])
        made[k] += 1
        want.append(k)
    frac = [FRACTIONS[k] for k in want]
    assert (c["type"] == [f[0] for f in frac]).all()
    small = int((c["type"] == 1).sum())
    assert (folder / "groups.txt").read_text().split() == ["groups", str(small), str(n - small)]
    r = np.array([0.5 * f[1] for f in frac])
    np.testing.assert_array_equal(c["radius"], r)
    np.testing.assert_array_equal(c["mass"], [4.0 / 3.0 * math.pi * ri ** 3 * f[2] for ri, f in zip(r, frac)])
    x = np.column_stack([c["x"], c["y"], c["z"]])
    assert ((x - r[:, None] >= LO) & (x + r[:, None] <= HI)).all()
    d = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(n)
    assert (d >= r[:, None] + r[None]).all()


def test_velocity_directions_are_uniform(inserted):
    """|v| = 0.5; a uniform direction has z uniform on [-1, 1] (Archimedes) and an azimuth
    uniform on [-pi, pi]: Kolmogorov-Smirnov distance below the 1 % critical value 1.63/sqrt(n)."""
    c, _ = inserted
    v = np.column_stack([c["vx"], c["vy"], c["vz"]])
    speed = np.linalg.norm(v, axis=1)
    np.testing.assert_allclose(speed, 0.5, rtol=1e-14)
    u = v / speed[:, None]
    n = len(u)
    assert _ks_uniform(u[:, 2], -1.0, 1.0) < 1.63 / math.sqrt(n)
    assert _ks_uniform(np.arctan2(u[:, 1], u[:, 0]), -math.pi, math.pi) < 1.63 / math.sqrt(n)
    assert len({tuple(row) for row in v}) == n                       # one draw per sphere


def test_positions_are_uniform_in_the_allowed_box(inserted):
    c, _ = inserted
    r = c["radius"]
    for axis, col in enumerate(("x", "y", "z")):
        small = r == 0.001                    # one size: the allowed range is the box less r
        assert _ks_uniform(c[col][small], LO[axis] + 0.001, HI[axis] - 0.001) < 1.63 / math.sqrt(small.sum())


def test_same_seed_same_spheres_other_seed_others(plugin_path, inserted, tmp_path):
    c, _ = inserted
    again = _run(plugin_path, tmp_path / "again")
    other = _run(plugin_path, tmp_path / "other", seed=8)
    for col in ("x", "y", "z", "vx", "vy", "vz", "radius"):
        np.testing.assert_array_equal(again[col], c[col])
    assert not np.array_equal(other["x"], c["x"])


def test_two_ranks_insert_the_same_spheres(plugin_path, inserted, tmp_path):
    c, _ = inserted
    two = _run(plugin_path, tmp_path / "two", ranks=2)
    for col in ("id", "type", "x", "y", "z", "vx", "vy", "vz", "radius", "mass"):
        np.testing.assert_array_equal(two[col], c[col])


def test_restart_continues_the_mixture_and_ids(plugin_path, inserted, tmp_path):
    """write_restart after step 3 (500 made) and read_restart + the same fix: the last 100
    continue the fraction sequence and the ids as the uninterrupted run."""
    c, _ = inserted
    first = tmp_path / "first"
    first.mkdir()
    _run_lmp_script(first, _script(plugin_path, 7, restart_out="mid.restart"))
    second = tmp_path / "second"
    second.mkdir()
    shutil.copy(first / "mid.restart", second)
    _run_lmp_script(second, _script(plugin_path, 7, restart_in="mid.restart"))
    d = next(iter_frames(second / "out.dump")).columns
    for col in ("id", "type", "x", "y", "z", "vx", "vy", "vz", "radius", "mass"):
        np.testing.assert_array_equal(d[col], c[col])


def test_no_sphere_touches_a_wall_triangle(plugin_path, inserted, tmp_path):
    """A plate of two triangles (fix musen/wall/mesh) across the middle of the box: no new
    sphere reaches it (MUSEN's IsOverlapped with the walls), where without it some do."""
    c, _ = inserted
    crossing = np.abs(c["z"]) < c["radius"]
    assert crossing.sum() >= 10
    w = _run(plugin_path, tmp_path / "plate", walls="plate")
    assert len(w["id"]) == 600
    assert (np.abs(w["z"]) >= w["radius"]).all()


def _prism(sides: int, radius: float, z0: float, z1: float) -> np.ndarray:
    """A closed regular prism of ``sides`` faces about the z axis (MUSEN's cylinder volume is
    such a triangulation), triangles (n, 3, 3)."""
    a = 2 * np.pi * np.arange(sides) / sides
    ring = np.c_[radius * np.cos(a), radius * np.sin(a)]
    tri = []
    for i in range(sides):
        p, q = ring[i], ring[(i + 1) % sides]
        tri += [[[*p, z0], [*q, z0], [*q, z1]], [[*p, z0], [*q, z1], [*p, z1]],
                [[0, 0, z0], [*q, z0], [*p, z0]], [[0, 0, z1], [*p, z1], [*q, z1]]]
    return np.array(tri, float)


def test_triangle_volume_holds_musens_fifteen_points(plugin_path, tmp_path):
    """With ``volume`` (a 12-sided prism, not a box) every sphere's centre and the 14 points
    MUSEN tests (at r on the axes and on the diagonals) lie inside the prism, checked with its
    half-planes here; the spheres are free of each other and reach out to the prism's faces."""
    sides, radius, z0, z1 = 12, 0.03, -0.02, 0.02
    tri = _prism(sides, radius, z0, z1)
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    fractions = " ".join(f"{t} {d} {rho} {s}" for t, d, rho, s in FRACTIONS)
    box = " ".join(f"{float(a)!r} {float(b)!r}" for a, b in zip(lo, hi))
    words = " ".join(repr(float(v)) for v in tri.ravel())
    script = "\n".join([
        f"plugin load {plugin_path}", "units si", "atom_style sphere", "atom_modify map array",
        "boundary f f f", "region b block -0.05 0.05 -0.05 0.05 -0.05 0.05", "create_box 2 b",
        "pair_style zero 0.01", "pair_coeff * *", "neighbor 0.001 bin", "timestep 1e-6",
        "group spheres empty",
        f"fix in spheres musen/inlet 11 box {box} tries 50 walls none velocity fixed 0 0 0 "
        f"fractions 2 {fractions} events 2 1 300 2 300 first_id 1 volume {len(tri)} {words}",
        "run 2",
        "write_dump all custom out.dump id type x y z radius modify sort id format float %.17g"])
    (tmp_path / "v").mkdir()
    _run_lmp_script(tmp_path / "v", script + "\n", 1)
    c = next(iter_frames(tmp_path / "v" / "out.dump")).columns
    x = np.c_[c["x"], c["y"], c["z"]]
    r = np.asarray(c["radius"])
    assert len(r) >= 500
    s = r / 1.73205081
    offsets = [np.zeros(3)] + [sign * e for e in np.eye(3) for sign in (1, -1)]
    points = [x + o * r[:, None] for o in offsets]
    points += [x + np.array(d) * s[:, None] for d in np.array(np.meshgrid([1, -1], [1, -1], [1, -1])).T.reshape(-1, 3)]
    face = np.pi * (2 * np.arange(sides) + 1) / sides        # outward normals' angles
    normal = np.c_[np.cos(face), np.sin(face)]
    apothem = radius * np.cos(np.pi / sides)
    for p in points:
        assert (p[:, :2] @ normal.T <= apothem).all()
        assert ((p[:, 2] >= z0) & (p[:, 2] <= z1)).all()
    gap = np.linalg.norm(x[:, None] - x[None], axis=2) - (r[:, None] + r[None])
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= 0
    # the spheres reach the faces (the test is no smaller box): some sphere's axis point lies
    # within 2 % of the radius of the apothem
    reach = (x[:, :2] @ normal.T).max(axis=1) + r
    assert reach.max() > 0.98 * apothem
    # a box corner outside the prism is never used
    assert (np.hypot(x[:, 0], x[:, 1]) <= radius).all()
