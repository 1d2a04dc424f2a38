"""fix musen/inlet's agglomerate mode (MUSEN's generator of agglomerates) on its own: rigid
copies of an agglomerate inserted into a box without motion (no integrator), checked against
MUSEN's rule written independently here: every copy is the agglomerate turned by a proper
rotation (all pair distances kept, no mirror image) about a centre in the box, every sphere
totally inside the box and free of the spheres of other copies, the orientations uniform
(the turned body axes: Kolmogorov-Smirnov at 1 %), one velocity per copy, the bonds on the
left sphere with their type, diameter and initial length; the same
spheres and bonds on 2 ranks and across a restart."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.post.lammps_dump.reader import iter_frames

from .test_style_musen_wall import _run_lmp_script

LO, HI = np.array([-0.02, -0.02, -0.01]), np.array([0.02, 0.02, 0.01])
# an L-shaped agglomerate (not symmetric: a mirror image or a wrong turn shows), centred
# at the origin by volume: (type, radius, density, x, y, z)
PARTS = [(1, 0.001, 2500.0, 0.0, 0.0, 0.0), (1, 0.001, 2500.0, 0.002, 0.0, 0.0),
         (2, 0.0015, 1000.0, 0.0, 0.0025, 0.0), (2, 0.0008, 1000.0, 0.0, 0.0, 0.0018)]
_V = np.array([p[1] ** 3 for p in PARTS])
_X = np.array([p[3:] for p in PARTS])
PARTS = [(t, r, rho, *map(float, x - (_V @ _X) / _V.sum())) for (t, r, rho, *_), x in zip(PARTS, _X)]
BONDS = [(0, 1, 1, 0.0005), (2, 0, 2, 0.0007), (0, 3, 1, 0.0004)]   # left, right, type, diameter
EVENTS = [(1, 60), (3, 40), (5, 20)]


def _script(plugin: str, seed: int, restart_in: str | None = None,
            restart_out: str | None = None) -> str:
    parts = " ".join(f"{t} {r!r} {rho!r} {x!r} {y!r} {z!r}" for t, r, rho, x, y, z in PARTS)
    bonds = " ".join(f"{i} {j} {t} {d!r}" for i, j, t, d in BONDS)
    box = " ".join(f"{float(a)!r} {float(b)!r}" for a, b in zip(LO, HI))
    events = " ".join(f"{s} {n}" for s, n in EVENTS)
    if restart_in:
        head = [f"plugin load {plugin}", f"read_restart {restart_in}"]
    else:
        head = [f"plugin load {plugin}", "units si", "atom_style bpm/sphere", "atom_modify map array",
                "boundary f f f", "newton on", "region b block -0.05 0.05 -0.05 0.05 -0.05 0.05",
                "create_box 2 b bond/types 2 extra/bond/per/atom 3 extra/special/per/atom 4"]
    lines = head + ["fix fl_bgeom1 all property/atom i_fl_bp1 d2_fl_bv1 2",
                    "fix fl_bgeom2 all property/atom i_fl_bp2 d2_fl_bv2 2",
                    "fix fl_bgeom3 all property/atom i_fl_bp3 d2_fl_bv3 2"] if not restart_in else head + [
        "fix fl_bgeom1 all property/atom i_fl_bp1 d2_fl_bv1 2",
        "fix fl_bgeom2 all property/atom i_fl_bp2 d2_fl_bv2 2",
        "fix fl_bgeom3 all property/atom i_fl_bp3 d2_fl_bv3 2"]
    lines += [
        "pair_style zero 0.01", "pair_coeff * *", "bond_style zero", "bond_coeff *",
        "special_bonds lj 0.0 1.0 1.0 coul 1.0 1.0 1.0",
        "comm_modify vel yes cutoff 0.02", "neighbor 0.001 bin", "timestep 1e-6",
        "group spheres empty",
        f"fix in spheres musen/inlet {seed} box {box} tries 30 walls none velocity random 0.5 "
        f"agglomerate {len(PARTS)} {parts} bonds {len(BONDS)} {bonds} events {len(EVENTS)} "
        f"{events} first_id 1 log inlets.log geometry fl_bp fl_bv 3",
        "compute bp all property/local batom1 batom2 btype", "compute sp all property/atom nbonds"]
    if restart_out:
        lines += ["run 3", f"write_restart {restart_out}"]
    else:
        lines += ["run 3" if not restart_in else "run 0", "run 3"]
    lines += ["write_dump all local bonds.dump c_bp[1] c_bp[2] c_bp[3]",
              "write_dump all custom out.dump id type x y z vx vy vz radius mass mol "
              "i_fl_bp1 i_fl_bp2 i_fl_bp3 d2_fl_bv1[1] d2_fl_bv1[2] d2_fl_bv2[1] d2_fl_bv2[2] "
              "d2_fl_bv3[1] d2_fl_bv3[2] c_sp modify sort id format float %.17g"]
    return "\n".join(lines) + "\n"


def _run(plugin: str, folder: Path, seed: int = 7, ranks: int = 1) -> tuple[dict, np.ndarray]:
    folder.mkdir(parents=True, exist_ok=True)
    _run_lmp_script(folder, _script(plugin, seed), ranks)
    return _read(folder)


def _read(folder: Path) -> tuple[dict, np.ndarray]:
    atoms = next(iter_frames(folder / "out.dump")).columns
    b = next(iter_frames(folder / "bonds.dump")).columns
    bonds = np.column_stack([b["c_bp[1]"], b["c_bp[2]"], b["c_bp[3]"]]).astype(np.int64).reshape(-1, 3)
    return atoms, bonds[np.lexsort(bonds.T[::-1])]


@pytest.fixture(scope="module")
def inserted(plugin_path, tmp_path_factory) -> tuple[dict, np.ndarray, Path]:
    folder = tmp_path_factory.mktemp("agglo") / "a"
    c, b = _run(plugin_path, folder)
    return c, b, folder


def _ks_uniform(sample: np.ndarray, lo: float, hi: float) -> float:
    s = np.sort((np.asarray(sample) - lo) / (hi - lo))
    n = len(s)
    return float(max((np.arange(1, n + 1) / n - s).max(), (s - np.arange(n) / n).max()))


def _copies(c: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(copies, 4, 3) positions, their best-fit rotations (Kabsch) and centres."""
    n = len(PARTS)
    x = np.column_stack([c["x"], c["y"], c["z"]]).reshape(-1, n, 3)
    body = np.array([p[3:] for p in PARTS])
    rot, centre = [], []
    for xs in x:
        h = (body - body.mean(0)).T @ (xs - xs.mean(0))
        u, _, vt = np.linalg.svd(h)
        r = (u @ vt).T
        rot.append(r)
        centre.append(xs.mean(0) - r @ body.mean(0))
    return x, np.array(rot), np.array(centre)


def test_copies_are_turned_agglomerates_inside_and_apart(inserted):
    c, _, folder = inserted
    n, total = len(PARTS), sum(k for _, k in EVENTS)
    assert len(c["id"]) == n * total and (c["id"] == np.arange(1, n * total + 1)).all()
    lines = [ln.split() for ln in (folder / "inlets.log").read_text().splitlines()]
    log = np.array([ln for ln in lines if len(ln) == 2], np.int64)
    assert (log[:, 1] == c["id"]).all()
    bond_lines = [ln for ln in lines if len(ln) == 4]          # STEP LEFT RIGHT L0
    assert len(bond_lines) == len(BONDS) * total
    x = np.column_stack([c["x"], c["y"], c["z"]])
    for step, left, right, length0 in bond_lines:
        d = x[int(right) - 1] - x[int(left) - 1]
        assert float(length0) == np.sqrt((d ** 2).sum())
    assert (log[:, 0] == np.repeat([s for s, _ in EVENTS], [n * k for _, k in EVENTS])).all()
    types = np.tile([p[0] for p in PARTS], total)
    r = np.tile([p[1] for p in PARTS], total)
    np.testing.assert_array_equal(c["type"], types)
    np.testing.assert_array_equal(c["radius"], r)
    rho = np.tile([p[2] for p in PARTS], total)
    np.testing.assert_array_equal(c["mass"], 4.0 / 3.0 * math.pi * r ** 3 * rho)
    x, rot, centre = _copies(c)
    body = np.array([p[3:] for p in PARTS])
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-12)       # proper, no mirror
    np.testing.assert_allclose(x, centre[:, None] + body @ rot.transpose(0, 2, 1), atol=1e-15)
    assert ((centre >= LO) & (centre <= HI)).all()
    flat = x.reshape(-1, 3)
    assert ((flat - r[:, None] >= LO) & (flat + r[:, None] <= HI)).all()
    d = np.linalg.norm(flat[:, None] - flat[None], axis=2)
    copy = np.repeat(np.arange(total), n)
    other = copy[:, None] != copy[None]
    assert (d[other] >= (r[:, None] + r[None])[other]).all()
    v = np.column_stack([c["vx"], c["vy"], c["vz"]]).reshape(-1, n, 3)
    assert (v == v[:, :1]).all()                              # one velocity per copy
    np.testing.assert_allclose(np.linalg.norm(v[:, 0], axis=1), 0.5, rtol=1e-14)


def test_orientations_are_uniform(inserted):
    """A uniform rotation turns a fixed axis to a direction uniform on the sphere: its z
    component uniform on [-1, 1] and its azimuth on [-pi, pi] (KS below 1.63/sqrt(n))."""
    c, _, _ = inserted
    _, rot, _ = _copies(c)
    n = len(rot)
    for k in range(3):
        axis = rot[:, :, k]
        assert _ks_uniform(axis[:, 2], -1.0, 1.0) < 1.63 / math.sqrt(n)
        assert _ks_uniform(np.arctan2(axis[:, 1], axis[:, 0]), -math.pi, math.pi) < 1.63 / math.sqrt(n)


def test_bonds_geometry_slots_and_specials(inserted):
    c, bonds, _ = inserted
    n, total = len(PARTS), sum(k for _, k in EVENTS)
    base = 1 + n * np.arange(total)[:, None]
    want = np.stack([np.stack([base[:, 0] + i, base[:, 0] + j, np.full(total, t)], 1)
                     for i, j, t, _ in BONDS], 1).reshape(-1, 3)
    want = want[np.lexsort(want.T[::-1])]
    np.testing.assert_array_equal(bonds, want)
    x = np.column_stack([c["x"], c["y"], c["z"]])
    ids = c["id"].astype(np.int64)
    for obj in range(total):
        slot_of: dict[int, int] = {}
        for i, j, _, d in BONDS:
            left, right = obj * n + i, obj * n + j
            k = slot_of.get(left, 0) + 1
            slot_of[left] = k
            assert c[f"i_fl_bp{k}"][left] == ids[right]
            assert c[f"d2_fl_bv{k}[1]"][left] == d
            assert c[f"d2_fl_bv{k}[2]"][left] == np.sqrt(((x[right] - x[left]) ** 2).sum())
    stored = np.zeros(n, int)                 # each bond on its left sphere
    for i, _, _, _ in BONDS:
        stored[i] += 1
    np.testing.assert_array_equal(c["c_sp"], np.tile(stored, total))


def test_two_ranks_insert_the_same_agglomerates(plugin_path, inserted, tmp_path):
    c, b, _ = inserted
    two, b2 = _run(plugin_path, tmp_path / "two", ranks=2)
    for col in c:
        np.testing.assert_array_equal(two[col], c[col])
    np.testing.assert_array_equal(b2, b)


def test_restart_continues_the_ids_and_bonds(plugin_path, inserted, tmp_path):
    c, b, _ = inserted
    first = tmp_path / "first"
    first.mkdir()
    _run_lmp_script(first, _script(plugin_path, 7, restart_out="mid.restart"))
    second = tmp_path / "second"
    second.mkdir()
    shutil.copy(first / "mid.restart", second)
    _run_lmp_script(second, _script(plugin_path, 7, restart_in="mid.restart"))
    c2, b2 = _read(second)
    for col in c:
        np.testing.assert_array_equal(c2[col], c[col])
    np.testing.assert_array_equal(b2, b)


@pytest.mark.parametrize("weights, pairs", [("lj/coul 0.0 1.0 1.0", 0), ("lj/coul 1.0 1.0 1.0", 1)])
def test_bonded_spheres_are_special_neighbours(plugin_path, tmp_path, weights, pairs):
    """A generated two-sphere agglomerate whose spheres overlap (MUSEN allows it): with 1-2
    weight 0 the bonded pair leaves LAMMPS's neighbour list (the fix made them each other's
    1-2 special neighbours), with weight 1 it is a contact."""
    box = "-0.01 0.01 -0.01 0.01 -0.01 0.01"
    text = "\n".join([
        f"plugin load {plugin_path}", "units si", "atom_style bpm/sphere", "atom_modify map array",
        "boundary f f f", "newton on", "region b block -0.05 0.05 -0.05 0.05 -0.05 0.05",
        "create_box 1 b bond/types 1 extra/bond/per/atom 1 extra/special/per/atom 1",
        "fix g1 all property/atom i_fl_bp1 d2_fl_bv1 2",
        # a sphere of the same size far away: gran/hooke sizes its cutoff from those at init
        "create_atoms 1 single 0.04 0.04 0.04", "set atom 1 diameter 0.002 density 2500.0",
        "pair_style gran/hooke 2000.0 NULL 0.0 NULL 0.0 0", "pair_coeff * *",
        "bond_style zero", "bond_coeff *", f"special_bonds {weights}",
        "comm_modify vel yes", "neighbor 0.0005 bin", "timestep 1e-7", "group spheres empty",
        f"fix in spheres musen/inlet 3 box {box} tries 30 walls none velocity fixed 0 0 0 "
        "agglomerate 2 1 0.001 2500.0 -0.00075 0.0 0.0 1 0.001 2500.0 0.00075 0.0 0.0 "
        "bonds 1 0 1 1 0.0005 events 1 1 1 first_id 10 geometry fl_bp fl_bv 1",
        "compute pl all pair/local dist", "run 2",
        "variable n equal count(all)",
        'print "atoms ${n}" file atoms.txt',
        "write_dump all local pairs.dump c_pl"])
    _run_lmp_script(tmp_path, text + "\n")
    assert (tmp_path / "atoms.txt").read_text().split() == ["atoms", "3"]
    dump = (tmp_path / "pairs.dump").read_text().split("ITEM: ENTRIES c_pl")[1].split()
    assert len(dump) == pairs


def test_taken_reserved_id_is_an_error(plugin_path, tmp_path):
    """first_id 1 while atom 1 exists: the fix stops with an error rather than give an ID twice."""
    text = "\n".join([
        f"plugin load {plugin_path}", "units si", "atom_style bpm/sphere", "atom_modify map array",
        "boundary f f f", "newton on", "region b block -0.05 0.05 -0.05 0.05 -0.05 0.05",
        "create_box 1 b bond/types 1 extra/bond/per/atom 1 extra/special/per/atom 1",
        "create_atoms 1 single 0.04 0.04 0.04", "set atom 1 diameter 0.002",
        "pair_style zero 0.01", "pair_coeff * *",
        "bond_style zero", "bond_coeff *", "timestep 1e-7", "group spheres empty",
        "fix in spheres musen/inlet 3 box -0.01 0.01 -0.01 0.01 -0.01 0.01 tries 30 walls none "
        "velocity fixed 0 0 0 agglomerate 1 1 0.001 2500.0 0 0 0 bonds 0 events 1 1 1 first_id 1",
        "run 2"])
    with pytest.raises(AssertionError, match="is taken by another atom"):
        _run_lmp_script(tmp_path, text + "\n")
