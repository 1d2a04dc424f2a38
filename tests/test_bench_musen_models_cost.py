"""benchmarks/musen_models_cost.py divides by the contacts its generated scenes have: count them
here from the scene text (numpy, minimum image), independently of the generator's own count."""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "musen_models_cost.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("musen_models_cost", BENCH)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod        # its dataclasses look their module up
    try:
        spec.loader.exec_module(mod)
        yield mod
    finally:
        sys.modules.pop(spec.name, None)


def spheres(scene: str) -> tuple[np.ndarray, np.ndarray]:
    pos, rad = [], []
    for line in scene.splitlines():
        tok = line.split()
        if tok[:1] == ["0"] and tok[3] == "1":
            i = tok.index("12", 6)
            pos.append([float(t) for t in tok[i + 1:i + 4]])
            rad.append(float(tok[5]))
    return np.array(pos), np.array(rad)


def overlaps(pos: np.ndarray, rad: np.ndarray, box: float | None) -> np.ndarray:
    d = pos[:, None, :] - pos[None, :, :]
    if box is not None:
        d -= box * np.round(d / box)
    gap = np.linalg.norm(d, axis=2) - rad[:, None] - rad[None, :]
    iu = np.triu_indices(len(pos), 1)
    return -gap[iu]


@pytest.mark.parametrize("spread", [False, True])
def test_pp_lattice_contacts(bench, spread):
    scene, contacts, _ = bench.pp_scene(5, spread)
    pos, rad = spheres(scene)
    box = [float(t) for t in next(ln for ln in scene.splitlines() if ln.startswith("28 ")).split()[8:11]]
    assert box[0] == box[1] == box[2]
    ov = overlaps(pos, rad, box[0])
    touching = ov[ov > 0]
    assert len(touching) == contacts == (0 if spread else 3 * 125)
    if not spread:
        assert np.allclose(touching, bench.OVERLAP, rtol=1e-6)


@pytest.mark.parametrize("spread", [False, True])
def test_pw_contacts(bench, spread):
    scene, contacts, _ = bench.pw_scene(6, spread)
    pos, rad = spheres(scene)
    walls = [np.array(ln.split()[ln.split().index("44") + 1:][:9], float).reshape(3, 3)
             for ln in scene.splitlines() if ln.split()[3:4] == ["14"]]
    assert len(walls) == 4
    assert not (overlaps(pos, rad, None) > 0).any()
    hits = 0
    for p, r in zip(pos, rad):
        for tri in walls:
            # nearest point of the triangle (all lie in a plane z = const): clamp the foot into it
            z = tri[0, 2]
            inside = min(tri[:, 0]) <= p[0] <= max(tri[:, 0]) and min(tri[:, 1]) <= p[1] <= max(tri[:, 1])
            lo = tri[:, :2].min(axis=0)
            # the two triangles of a plane split the square along its diagonal x - lo_x = y - lo_y
            below = (p[1] - lo[1]) < (p[0] - lo[0])
            first = np.isclose(tri[1, 1], tri[0, 1]) or np.isclose(tri[2, 1], tri[0, 1])
            owns = inside and (below == first)
            dist_diag = abs((p[0] - lo[0]) - (p[1] - lo[1])) / np.sqrt(2)
            if owns and abs(p[2] - z) < r:
                hits += 1
            elif abs(p[2] - z) < r:
                # the other triangle of the plane: only its diagonal edge is near, out of reach
                assert np.hypot(p[2] - z, dist_diag) > r
    assert hits == contacts == (0 if spread else 2 * 36)


def test_bonded_lattice(bench):
    side = 4
    scene, bonds, _ = bench.bond_scene(side, 9)
    pos, rad = spheres(scene)
    assert not (overlaps(pos, rad, None) > 0).any()
    lines = [ln.split() for ln in scene.splitlines() if ln.split()[3:4] == ["9"]]
    assert len(lines) == bonds == 3 * side * side * (side - 1)
    for tok in lines:
        left, right, length = int(tok[5]), int(tok[6]), float(tok[8])
        assert np.isclose(np.linalg.norm(pos[right] - pos[left]), length, rtol=1e-12)
    assert bench.bond_scene(side, None)[1] == 0
    assert len([ln for ln in bench.bond_scene(side, 13)[0].splitlines() if ln.split()[3:4] == ["13"]]) == bonds
