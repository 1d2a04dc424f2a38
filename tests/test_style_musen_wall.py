"""fix musen/wall/mesh (fibrelmp's LAMMPS plugin) against an independent numpy implementation
of MUSEN's particle-wall contact, and the physics the triangle walls must show.

The reference (``Reference`` below) is written from MUSEN's sources (github.com/msolids/musen
e0ff360), not from the C++ style:
- contact point and kind on a triangle: GeometricFunctions.h IsSphereIntersectTriangle;
- one contact per flat patch: VerletList.cpp GetPWContacts;
- contact list, new contacts taking the tangential overlap of an ended contact on a triangle
  sharing a vertex: CollisionsCalculator.cpp CheckPWCollisions, SimplifiedScene.cpp
  FindAdjacentWalls;
- force and torque: ModelPWHertzMindlin.cpp CalculatePW, with E*, G*, alpha from
  SimplifiedScene.cpp CalculateInteractionProperty;
- the wall velocity the law sees, kept after a geometry stops: CPUSimulator.cpp MoveWalls.

LAMMPS is driven through the python module: the sphere states of a real impact (leapfrog with
the forces LAMMPS returns) are scattered in, ``run 1`` evaluates the wall forces at the next
step's time (no integrator: the state stays as given), and forces, torques and per-triangle
wall forces are compared each step.  Dynamic checks integrate with fix nve/sphere.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles
from fibrelmp._lammps import new_lammps

from .conftest import REPO

PI = 3.14159265358979323846                  # MUSENDefinitions.h
TWO_SQRT_5_6 = 1.825741858350553711523232609336
G = 9.81
NO, FACE, EDGE, VERTEX = 0, 1, 2, 3


# =======================================================================================
# the reference: MUSEN's formulas in numpy / python floats, operation by operation
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def unit_normal(v):
    c = cross(v[1] - v[0], v[2] - v[0])
    return c / math.sqrt(dot(c, c))


def alpha_of(e):
    return math.log(e) / math.sqrt(PI * PI + math.log(e) ** 2)


def intersect(v, n, p, r):
    """(kind, contact point) of sphere (p, r) and triangle v (3,3) with unit normal n."""
    lo, hi = v.min(0), v.max(0)
    if any(p[k] <= lo[k] - r or p[k] >= hi[k] + r for k in range(3)):
        return NO, None
    centre = (v[0] + v[1] + v[2]) / 3.0
    ppd = dot(p - centre, n)
    if abs(ppd) >= r:
        return NO, None
    a = p - n * ppd
    e21, e31, w = v[1] - v[0], v[2] - v[0], a - v[0]
    d00, d01, d11 = dot(e21, e21), dot(e21, e31), dot(e31, e31)
    d20, d21 = dot(w, e21), dot(w, e31)
    inv = 1.0 / (d00 * d11 - d01 * d01)
    gam = (d11 * d20 - d01 * d21) * inv
    bet = (d00 * d21 - d01 * d20) * inv
    alp = 1.0 - gam - bet
    if 0 < gam < 1 and 0 < alp < 1 and 0 < bet < 1:
        return FACE, a
    best = None
    for s, e in ((0, 1), (1, 2), (2, 0)):
        edge = v[e] - v[s]
        lc = min(max(dot(a - v[s], edge) / dot(edge, edge), 0.0), 1.0)
        c = v[s] + lc * edge
        d2 = dot(c - p, c - p)
        if best is None or d2 < best[0]:          # ties: the first edge (MUSEN's <=)
            best = (d2, c, lc)
    if best[0] >= r * r:
        return NO, None
    return (VERTEX if best[2] in (0.0, 1.0) else EDGE), best[1]


def one_per_patch(kinds, normals):
    """VerletList::GetPWContacts: among touched triangles with the same normal (|dn|^2 < 1e-6)
    a face beats edges/vertices, the first of two edges stays, a vertex yields to anything."""
    kinds = list(kinds)
    for i in range(len(kinds) - 1):
        if kinds[i] == NO:
            continue
        for j in range(i + 1, len(kinds)):
            if kinds[j] == NO or kinds[i] == NO:
                continue
            dn = normals[i] - normals[j]
            if not dot(dn, dn) < 1e-6:
                continue
            if kinds[i] == FACE and kinds[j] in (EDGE, VERTEX):
                kinds[j] = NO
            elif kinds[i] == EDGE:
                if kinds[j] == FACE:
                    kinds[i] = NO
                else:
                    kinds[j] = NO
            elif kinds[i] == VERTEX:
                kinds[i] = NO
    return kinds


def pw_law(R, m, x, v, w, cp, n, wall, law, xi_old, dt):
    """ModelPWHertzMindlin::CalculatePW: (force, torque, new tangential overlap)."""
    wall_v, wall_w, wall_c = wall
    rc = x - cp
    rc_len = math.sqrt(dot(rc, rc))
    rcn = rc / rc_len
    delta = R - rc_len
    assert delta >= 0
    rot = cross(cp - wall_c, wall_w) if np.any(wall_w != 0) else np.zeros(3)
    rel = v - wall_v + rot + cross(rcn, w) * R
    vn = dot(n, rel)
    vt = rel - vn * n
    a = math.sqrt(R * delta)
    kn = 2 * law["E"] * a
    fel = 2.0 / 3.0 * delta * kn * abs(dot(rcn, n))
    fdamp = TWO_SQRT_5_6 * law["alpha"] * vn * math.sqrt(kn * m)
    fn = n * (fel + fdamp)
    rot_xi = xi_old - n * dot(n, xi_old)
    if np.any(np.abs(rot_xi) > 1e-100):
        rot_xi = rot_xi * (math.sqrt(dot(xi_old, xi_old)) / math.sqrt(dot(rot_xi, rot_xi)))
    xi = rot_xi + vt * dt
    kt = 8 * law["G"] * a
    shear = xi * -kt
    damp = vt * (TWO_SQRT_5_6 * law["alpha"] * math.sqrt(kt * m))
    shear_len = math.sqrt(dot(shear, shear))
    limit = law["mu"] * abs(fel + fdamp)
    if shear_len > limit:
        ft = shear * limit / shear_len
        xi = ft / -kt
    else:
        ft = shear + damp
    roll = np.zeros(3)
    if np.any(np.abs(w) > 1e-100):
        roll = w * (-law["mur"] * abs(fel) * R / math.sqrt(dot(w, w)))
    return fn + ft, cross(n, ft) * -R + roll, xi


class Reference:
    """MUSEN's particle-wall contacts of a set of spheres with a triangle mesh."""

    def __init__(self, vertices0, geometry, material, laws):
        self.geometry, self.material, self.laws = np.asarray(geometry), np.asarray(material), laws
        self.normals0 = np.array([unit_normal(v) for v in vertices0])
        n = len(vertices0)
        self.adjacent = [set() for _ in range(n)]       # FindAdjacentWalls: a shared vertex
        for i in range(n):
            for j in range(i + 1, n):
                if self.geometry[i] != self.geometry[j]:
                    continue
                d = vertices0[i][:, None, :] - vertices0[j][None, :, :]
                if ((d ** 2).sum(-1) < 1e-18).any():
                    self.adjacent[i].add(j)
                    self.adjacent[j].add(i)
        self.contacts: dict[int, list] = {}             # sphere -> [[triangle, xi], ...]
        self.kept_kinds: set[int] = set()               # kinds of the contacts that acted
        self.most = 0                                   # most contacts of one sphere at once
        self.carried = 0                                # new contacts that took an old overlap

    def forces(self, vertices, normals, walls, spheres, dt, commit=True):
        """walls[g] = (v, w, centre); spheres: list of dicts (id, type, R, m, x, v, w)."""
        F = np.zeros((len(spheres), 3))
        T = np.zeros((len(spheres), 3))
        FW = np.zeros((len(vertices), 3))
        for k, s in enumerate(spheres):
            kinds, cps = [], []
            for t in range(len(vertices)):
                kind, cp = intersect(vertices[t], normals[t], s["x"], s["R"])
                kinds.append(kind)
                cps.append(cp)
            kinds = one_per_patch(kinds, normals)
            touched = [t for t in range(len(vertices)) if kinds[t] != NO]
            self.kept_kinds |= {kinds[t] for t in touched}
            self.most = max(self.most, len(touched))
            old = self.contacts.get(s["id"], [])
            old_tris = [c[0] for c in old]
            work = [[t, xi.copy()] for t, xi in old if t in touched]
            for t in touched:
                if t in old_tris:
                    continue
                xi = np.zeros(3)
                for t_old, xi_old in old:
                    if t_old not in touched and t_old in self.adjacent[t]:
                        xi = xi_old.copy()
                        self.carried += commit
                        break
                work.append([t, xi])
            new = []
            for t, xi in work:
                law = self.laws[(s["type"], int(self.material[t]))]
                f, tq, xi_new = pw_law(s["R"], s["m"], s["x"], s["v"], s["w"], cps[t], normals[t],
                                       walls[int(self.geometry[t])], law, xi, dt)
                F[k] += f
                T[k] += tq
                FW[t] -= f
                new.append([t, xi_new])
            if commit:
                self.contacts[s["id"]] = new
        return F, T, FW


def make_law(E, G_, e, mu, mur):
    return {"E": E, "G": G_, "e": e, "alpha": alpha_of(e), "mu": mu, "mur": mur}


# =======================================================================================
# the mesh file and LAMMPS
def mesh_text(vertices, geometry, material, laws, geometries):
    """geometries: list of dicts (name, around, segments[(t0, t1, w, kr(4,3,3), kb(4,3))],
    intervals[(tb, te, v, c, w)])."""
    r = repr
    out = ["musen/wall/mesh 1", f"laws {len(laws)}"]
    for (t, m), law in laws.items():
        out.append(f"{t} {m} {r(law['E'])} {r(law['G'])} {r(law['e'])} {r(law['mu'])} {r(law['mur'])}")
    out.append(f"geometries {len(geometries)}")
    for g in geometries:
        out.append(f"geometry {g['name']} {int(g.get('around', False))} {len(g.get('segments', []))} "
                   f"{len(g.get('intervals', []))}")
        for t0, t1, w, kr, kb in g.get("segments", []):
            vals = [t0, t1, w, 0.0, 0.0, 1.0, *np.ravel(kr), *np.ravel(kb)]
            out.append("seg " + " ".join("inf" if math.isinf(x) else r(float(x)) for x in vals))
        for tb, te, v, c, w in g.get("intervals", []):
            out.append("int " + " ".join(r(float(x)) for x in [tb, te, *v, *c, *w]))
    out.append(f"triangles {len(vertices)}")
    for v, gi, m in zip(vertices, geometry, material):
        out.append(f"{gi} {m} " + " ".join(r(float(x)) for x in np.ravel(v)))
    return "\n".join(out) + "\n"


def translation_segments(v, t0=0.0, t1=math.inf):
    """x(t) = x0 + v (t - t0) on [t0, t1), still afterwards."""
    kr = np.zeros((4, 3, 3))
    kr[0] = np.eye(3)
    kb = np.zeros((4, 3))
    kb[1] = v
    segs = [(t0, t1, 0.0, kr, kb)]
    if math.isfinite(t1):
        kb2 = np.zeros((4, 3))
        kb2[0] = np.asarray(v) * (t1 - t0)
        segs.append((t1, math.inf, 0.0, kr, kb2))
    return segs


def rotation_segment(axis, w, centre, t0=0.0):
    """Rotation by w (t - t0) about a fixed axis through centre: R = A + B cos + C sin."""
    n = np.asarray(axis, float) / np.linalg.norm(axis)
    A = np.outer(n, n)
    B = np.eye(3) - A
    C = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    c = np.asarray(centre, float)
    kr = np.zeros((4, 3, 3))
    kr[0], kr[2], kr[3] = A, B, C
    kb = np.zeros((4, 3))
    kb[0] = c - A @ c
    kb[2] = -B @ c
    kb[3] = -C @ c
    return [(t0, math.inf, w, kr, kb)]


def rodrigues(axis, angle):
    n = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


class Lammps:
    """A LAMMPS instance with spheres and fix musen/wall/mesh (no pair style)."""

    def __init__(self, plugin, folder: Path, mesh: str, spheres, dt, ntypes=1,
                 box=(-0.02, 0.02, -0.02, 0.02, -0.02, 0.02), boundary="f f f", integrate=False,
                 gravity=None, fix_id="walls"):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "mesh.txt").write_text(mesh)
        self.L = L = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
        self.fix_id = fix_id
        self.n = len(spheres)
        cmds = [f"plugin load {plugin}", "units si", "atom_style sphere", "atom_modify map array",
                f"boundary {boundary}", "region box block " + " ".join(repr(float(b)) for b in box),
                f"create_box {ntypes} box"]
        for s in spheres:
            x0, y0, z0 = (float(c) for c in s["x"])
            cmds.append(f"create_atoms {s['type']} single {x0!r} {y0!r} {z0!r} units box")
        for i, s in enumerate(spheres):
            rho = float(s["m"] / (4.0 / 3.0 * math.pi * s["R"] ** 3))
            cmds.append(f"set atom {i + 1} diameter {float(2 * s['R'])!r} density {rho!r}")
        cmds += [f"timestep {float(dt)!r}", "neighbor 0.001 bin", "comm_modify vel yes"]
        if integrate:
            cmds.append("fix nve all nve/sphere")
        if gravity is not None:
            gx, gy, gz = (float(c) for c in gravity)
            cmds.append(f"fix grav all gravity {G!r} vector {gx!r} {gy!r} {gz!r}")
        cmds.append(f"fix {fix_id} all musen/wall/mesh {folder / 'mesh.txt'}")
        self.pre = cmds
        for c in cmds:
            L.command(c)
        # the exact masses the reference uses (set density rounds through 4/3 pi R^3)
        self.mass = np.array([s["m"] for s in spheres])
        self._scatter("rmass", self.mass, 1)

    def _scatter(self, name, values, k):
        import ctypes
        arr = np.ascontiguousarray(np.asarray(values, float).ravel())
        self.L.scatter_atoms(name, 1, k, arr.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))

    def _gather(self, name, k=3):
        return np.array(self.L.gather_atoms(name, 1, k)[:k * self.n]).reshape(self.n, k) if k > 1 else \
            np.array(self.L.gather_atoms(name, 1, 1)[:self.n])

    def set_state(self, x, v, w):
        self._scatter("x", x, 3)
        self._scatter("v", v, 3)
        self._scatter("omega", w, 3)

    def state(self):
        return self._gather("x"), self._gather("v"), self._gather("omega")

    def run(self, n=1):
        self.L.command(f"run {n}")
        return self._gather("f"), self._gather("torque")

    def wall_array(self, ntri):
        out = np.zeros((ntri, 12))
        for i in range(ntri):
            for j in range(12):
                out[i, j] = self.L.extract_fix(self.fix_id, 0, 2, i, j)
        return out

    @property
    def time(self):
        return float(self.L.extract_global("atime")) + (int(self.L.extract_global("ntimestep"))
                                                        - int(self.L.extract_global("atimestep"))) * \
            float(self.L.extract_global("dt"))

    def close(self):
        self.L.close()


# =======================================================================================
# meshes
def valley_mesh():
    """A floor z = 0 of 4 triangles around a centre vertex (seams along its diagonals), an
    inclined wall (45 deg) rising from x = 0.004 (a valley: two normals) and a roof whose two
    faces meet in a convex ridge.  Geometry 0 = floor + wall, geometry 1 = roof; wall
    materials 0 (floor, roof) and 1 (inclined wall).  Normals face the spheres."""
    a = 0.004
    c = np.array([0.0, 0.0, 0.0])
    corners = np.array([[-a, -a, 0], [a, -a, 0], [a, a, 0], [-a, a, 0]])
    floor = [np.array([c, corners[k], corners[(k + 1) % 4]]) for k in range(4)]
    wall = [np.array([[a, -a, 0], [a + 0.004, -a, 0.004], [a + 0.004, a, 0.004]]),
            np.array([[a, -a, 0], [a + 0.004, a, 0.004], [a, a, 0]])]
    roof = [np.array([[-0.010, -0.002, 0.0], [-0.008, -0.002, 0.001], [-0.008, 0.002, 0.001]]),
            np.array([[-0.008, -0.002, 0.001], [-0.006, -0.002, 0.0], [-0.008, 0.002, 0.001]])]
    verts = np.array(floor + wall + roof)
    geometry = [0] * 6 + [1] * 2
    material = [0, 0, 0, 0, 1, 1, 0, 0]
    return verts, geometry, material


def impact_spheres(R=0.0005, rho=2500.0):
    """Six spheres (two types) about to hit the valley mesh, with spins: a face (oblique), the
    centre vertex of four triangles, a diagonal seam they slide across, the valley (two
    faces at once), the roof ridge (two edges at once) and the floor's outer corner (a vertex
    seen from the side)."""
    m = rho * 4.0 / 3.0 * math.pi * R ** 3
    rng = np.random.default_rng(7)
    gap = R + 5e-6
    valley_b = np.array([0.0, 0.0, 1.0]) + np.array([-1.0, 0.0, 1.0]) / math.sqrt(2)
    valley_b /= np.linalg.norm(valley_b)
    d = math.sqrt(((R + 5e-6) ** 2 - (0.3 * R) ** 2) / 2)
    corner = np.array([-0.004 - d, 0.004 + d, 0.3 * R])
    to_corner = np.array([-0.004, 0.004, 0.0]) - corner
    seam = np.array([0.002, 0.002 - 2e-5 * math.sqrt(2), R])
    specs = [  # position, velocity
        ([0.0015, -0.0011, gap], [0.3, 0.1, -0.5]),
        ([0.0, 0.0, gap], [0.02, 0.01, -0.5]),
        (seam, [-0.35, 0.35, -0.1]),
        ([0.004 - (math.sqrt(2) - 1) * gap, 0.001, gap], -0.5 * valley_b),
        ([-0.008, 0.0004, 0.001 + gap], [0.05, 0.0, -0.5]),
        (corner, 0.5 * to_corner / np.linalg.norm(to_corner)),
    ]
    out = []
    for k, (x, v) in enumerate(specs):
        out.append({"id": k + 1, "type": 1 + k % 2, "R": R, "m": m, "x": np.array(x, float),
                    "v": np.array(v, float), "w": rng.normal(size=3) * 200.0})
    return out


def laws_valley():
    return {(1, 0): make_law(1.2e8, 4.5e7, 0.7, 0.3, 0.02),
            (1, 1): make_law(9e7, 3.2e7, 0.6, 0.2, 0.005),
            (2, 0): make_law(1.5e8, 5.5e7, 0.9, 0.45, 0.05),
            (2, 1): make_law(1.1e8, 4e7, 0.5, 0.15, 0.0)}


# =======================================================================================
def drive(plugin, tmp_path, verts, geometry, material, laws, geometries, spheres, steps, dt,
          wall_state, place=None, name="job", check_vertices=None):
    """Leapfrog the spheres with the forces LAMMPS returns; every step compare forces,
    torques and triangle forces with the reference.  wall_state(t) -> per geometry (v, w, c);
    place(t, verts0) -> vertices at t (None: static)."""
    ref = Reference(verts, geometry, material, laws)
    lmp = Lammps(plugin, tmp_path / name, mesh_text(verts, geometry, material, laws, geometries),
                 spheres, dt, ntypes=2)
    x = np.array([s["x"] for s in spheres])
    v = np.array([s["v"] for s in spheres])
    w = np.array([s["w"] for s in spheres])
    mass = np.array([s["m"] for s in spheres])
    inertia = 0.4 * mass * np.array([s["R"] for s in spheres]) ** 2
    worst = 0.0
    kinds_seen = set()
    rotating = any(g.get("segments") and any(sg[2] != 0 for sg in g["segments"]) for g in geometries)
    try:
        for step in range(steps):
            lmp.set_state(x, v, w)
            f, tq = lmp.run(1)
            t = lmp.time
            arr = lmp.wall_array(len(verts))
            now = arr[:, 3:].reshape(-1, 3, 3)
            if place is not None:
                expect = place(t, verts)
                np.testing.assert_allclose(now, expect, rtol=0, atol=1e-15)
            else:
                assert (now == verts).all()
            normals = np.array([unit_normal(q) for q in now]) if rotating else ref.normals0
            cur = [dict(s, x=x[k], v=v[k], w=w[k]) for k, s in enumerate(spheres)]
            for k, s in enumerate(cur):
                for tr in range(len(now)):
                    kinds_seen.add(intersect(now[tr], normals[tr], s["x"], s["R"])[0])
            F, T, FW = ref.forces(now, normals, wall_state(t), cur, dt)
            scale_f = max(np.abs(F).max(), 1e-300)
            scale_t = max(np.abs(T).max(), 1e-300)
            np.testing.assert_allclose(f, F, rtol=1e-12, atol=1e-12 * scale_f)
            np.testing.assert_allclose(tq, T, rtol=1e-12, atol=1e-12 * scale_t)
            np.testing.assert_allclose(arr[:, :3], FW, rtol=1e-12, atol=1e-12 * scale_f)
            if np.abs(F).max() > 0:
                worst = max(worst, np.abs(f - F).max() / scale_f, np.abs(tq - T).max() / scale_t)
            v = v + f / mass[:, None] * dt
            x = x + v * dt
            w = w + tq / inertia[:, None] * dt
    finally:
        lmp.close()
    return worst, kinds_seen, ref


def test_static_mesh_face_edge_vertex_impacts(plugin_path, tmp_path):
    """Six spheres (two types, two wall materials) hit a static mesh at a face, a vertex shared
    by four triangles, a seam, a valley (two normals), a convex ridge and an outer corner:
    forces, torques and triangle forces equal the reference at every step of the impacts."""
    verts, geometry, material = valley_mesh()
    geoms = [{"name": "floor"}, {"name": "ridge"}]
    still = lambda t: [(np.zeros(3), np.zeros(3), np.zeros(3))] * 2   # noqa: E731
    worst, kinds, ref = drive(plugin_path, tmp_path, verts, geometry, material, laws_valley(), geoms,
                              impact_spheres(), 500, 5e-7, still)
    print(f"\nworst relative difference {worst:.2e}; contact kinds acting {sorted(ref.kept_kinds)}, "
          f"up to {ref.most} contacts on one sphere, {ref.carried} overlaps carried to a neighbour")
    assert {FACE, EDGE, VERTEX} <= kinds and {FACE, EDGE, VERTEX} <= ref.kept_kinds
    assert ref.most >= 2 and ref.carried >= 1
    assert worst < 1e-12


@pytest.mark.parametrize("motion", ["translate", "rotate", "rotate-around-centre", "stop"])
def test_moving_mesh_impacts(plugin_path, tmp_path, motion):
    """The same impacts on a moving mesh: translating, rotating about a fixed axis, rotating
    about its own centroid, and translating then stopping (MUSEN keeps the wall velocity in
    its law after the interval ends)."""
    verts, geometry, material = valley_mesh()
    c_fixed = np.array([0.001, -0.0005, -0.002])
    vel = np.array([0.05, -0.02, 0.1])
    omega = np.array([0.0, 0.0, 40.0])      # 0.01 rad over the run: contacts see the rotation
    if motion in ("translate", "stop"):
        t1 = math.inf if motion == "translate" else 1.2e-4
        segs = translation_segments(vel, 0.0, t1)
        intervals = [(0.0, t1 if math.isfinite(t1) else 10.0, vel, np.zeros(3), np.zeros(3))]
        def place(t, v0):
            out = v0.copy()
            out[:6] = v0[:6] + vel * min(t, t1)
            return out

        def walls(t):          # geometry 0 keeps its velocity after t1 (MUSEN)
            return [(vel, np.zeros(3), np.zeros(3)), (np.zeros(3), np.zeros(3), np.zeros(3))]
        around = False
    else:
        around = motion == "rotate-around-centre"
        ids = [0, 1, 2, 3, 4, 5]
        if around:
            a = np.array([0.5 * np.linalg.norm(np.cross(q[1] - q[0], q[2] - q[0])) for q in verts[ids]])
            centre = (a[:, None] * verts[ids].mean(1)).sum(0) / a.sum()
        else:
            centre = c_fixed
        segs = rotation_segment(omega, float(np.linalg.norm(omega)), centre)
        intervals = [(0.0, 10.0, np.zeros(3), c_fixed, omega)]

        def place(t, v0):
            out = v0.copy()
            Rm = rodrigues(omega, float(np.linalg.norm(omega)) * t)
            out[ids] = (v0[ids] - centre) @ Rm.T + centre
            return out

        def walls(t):
            return [(np.zeros(3), omega, centre), (np.zeros(3), np.zeros(3), np.zeros(3))]
    geoms = [{"name": "floor", "around": around, "segments": segs, "intervals": intervals},
             {"name": "ridge"}]
    worst, kinds, _ = drive(plugin_path, tmp_path, verts, geometry, material, laws_valley(), geoms,
                            impact_spheres(), 500, 5e-7, walls, place=place)
    print(f"\n{motion}: worst relative difference {worst:.2e}; kinds {sorted(kinds)}")
    assert worst < 1e-12


def test_reference_can_fail(plugin_path, tmp_path):
    """The comparison is sharp: a reference that drops MUSEN's |rc_n . n| factor on edge and
    vertex contacts (or that scales the damping differently) no longer matches LAMMPS."""
    verts, geometry, material = valley_mesh()
    geoms = [{"name": "floor"}, {"name": "ridge"}]
    still = lambda t: [(np.zeros(3), np.zeros(3), np.zeros(3))] * 2   # noqa: E731
    global TWO_SQRT_5_6
    saved = TWO_SQRT_5_6
    TWO_SQRT_5_6 = saved * (1 + 1e-9)
    try:
        with pytest.raises(AssertionError):
            drive(plugin_path, tmp_path, verts, geometry, material, laws_valley(), geoms,
                  impact_spheres(), 200, 5e-7, still)
    finally:
        TWO_SQRT_5_6 = saved


# =======================================================================================
# the must-shows: slope, rest height, seams
def slope_mesh(theta, length=0.06, width=0.01, n_strips=23, rng_seed=3, single=False):
    """A plane through the origin tilted by theta about y (downhill +x): one big triangle, or
    an irregular triangulation (jittered interior vertices, strips of unequal length)."""
    Ry = rodrigues([0, 1, 0], theta)
    if single:
        tri = np.array([[[-0.5 * length, -3 * width, 0], [1.5 * length, -3 * width, 0],
                         [-0.5 * length, 5 * width, 0]]])
        return tri @ Ry.T
    rng = np.random.default_rng(rng_seed)
    xs = np.sort(np.concatenate([[-0.01, length], rng.uniform(-0.01, length, n_strips - 1)]))
    ys = np.array([-width, -0.3 * width, 0.0, 0.45 * width, width])
    P = np.zeros((len(xs), len(ys), 3))
    for i, x in enumerate(xs):
        for j, y in enumerate(ys):
            P[i, j] = [x, y, 0.0]
    tris = []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            a, b, c, d = P[i, j], P[i + 1, j], P[i + 1, j + 1], P[i, j + 1]
            if (i + j) % 2:
                tris += [[a, b, c], [a, c, d]]
            else:
                tris += [[a, b, d], [b, c, d]]
    return np.array(tris) @ Ry.T


def one_sphere(R=0.001, rho=2500.0, x=(0, 0, 0), v=(0, 0, 0), w=(0, 0, 0)):
    return {"id": 1, "type": 1, "R": R, "m": rho * 4.0 / 3.0 * math.pi * R ** 3,
            "x": np.array(x, float), "v": np.array(v, float), "w": np.array(w, float)}


def static_overlap(law, m, R, g_normal):
    return (m * g_normal / (4.0 / 3.0 * law["E"] * math.sqrt(R))) ** (2.0 / 3.0)


def run_on(plugin, folder, verts, law, sphere, dt, steps, every, theta,
           box=(-0.05, 0.12, -0.05, 0.05, -0.05, 0.05), boundary="f f f"):
    mesh = mesh_text(verts, [0] * len(verts), [0] * len(verts), {(1, 0): law}, [{"name": "slope"}])
    lmp = Lammps(plugin, folder, mesh, [sphere], dt, integrate=True, gravity=(0.0, 0.0, -1.0),
                 box=box, boundary=boundary)
    lmp.set_state(sphere["x"][None], sphere["v"][None], sphere["w"][None])
    out = []
    try:
        for _ in range(steps // every):
            f, tq = lmp.run(every)
            x, v, w = lmp.state()
            out.append((lmp.time, x[0].copy(), v[0].copy(), w[0].copy(), f[0].copy(), tq[0].copy()))
    finally:
        lmp.close()
    return out


def test_frictionless_sphere_slides_down_triangulated_2deg_slope(plugin_path, tmp_path):
    """A frictionless sphere released at its rest overlap on a 2 deg slope made of 184
    irregular triangles slides as 1/2 g sin(theta) t^2 (within 1e-3), crossing seams and
    vertices, and follows the single-triangle plane to rounding."""
    theta = math.radians(2.0)
    law = make_law(1e8, 4e7, 0.5, 0.0, 0.0)
    R = 0.001
    s = one_sphere(R)
    d0 = static_overlap(law, s["m"], R, G * math.cos(theta))
    n = rodrigues([0, 1, 0], theta) @ [0, 0, 1.0]
    down = rodrigues([0, 1, 0], theta) @ [1.0, 0, 0]
    s["x"] = np.array([0.0, 0.0013, 0.0]) + (R - d0) * n
    mesh = slope_mesh(theta)
    dt, steps, every = 2e-5, 15000, 1500
    a = run_on(plugin_path, tmp_path / "mesh", mesh, law, s, dt, steps, every, theta)
    b = run_on(plugin_path, tmp_path / "plane", slope_mesh(theta, single=True), law, s, dt, steps, every, theta)
    for (t, x, *_), (_, xp, *_) in zip(a, b):
        travelled = (x - s["x"]) @ down
        expect = 0.5 * G * math.sin(theta) * t ** 2
        print(f"t={t:.3f}: travelled {travelled:.9e}, 1/2 g sin t^2 = {expect:.9e} "
              f"(rel {travelled / expect - 1:+.1e}), |mesh - plane| {np.abs(x - xp).max():.1e}")
        assert travelled == pytest.approx(expect, rel=1e-3)
        assert abs((x - s["x"]) @ n) < 1e-6 * d0
        np.testing.assert_allclose(x, xp, rtol=0, atol=1e-12 * R)
    assert (a[-1][1] - s["x"]) @ down > 0.005        # crossed several triangles


@pytest.mark.parametrize("where", ["face", "seam", "vertex", "near-seam"])
def test_rest_height_on_mesh_equals_plane(plugin_path, tmp_path, where):
    """A sphere settling (damped, with friction and rolling friction) on a triangulated floor
    comes to rest at the height it has on one big triangle (to 1e-9 relative), wherever it
    sits: inside a face, on a seam, on a vertex shared by 8 triangles, just off a seam."""
    law = make_law(1e8, 4e7, 0.3, 0.5, 0.05)
    R = 0.001
    # an 8-triangle fan around the origin + outer ring
    ring = [np.array([0.004 * math.cos(k * math.pi / 4), 0.004 * math.sin(k * math.pi / 4), 0.0]) for k in range(8)]
    fan = np.array([[np.zeros(3), ring[k], ring[(k + 1) % 8]] for k in range(8)])
    big = np.array([[[-0.05, -0.05, 0.0], [0.05, -0.05, 0.0], [0.0, 0.08, 0.0]]])
    xy = {"face": (0.0021, 0.0008), "seam": (0.0025 * math.cos(math.pi / 4), 0.0025 * math.sin(math.pi / 4)),
          "vertex": (0.0, 0.0), "near-seam": (0.0022, 0.00003)}[where]
    s = one_sphere(R, x=(xy[0], xy[1], 1.02 * R), v=(0.0, 0.0, -0.05), w=(0.0, 0.0, 5.0))
    dt, steps = 2e-6, 60000
    out = {}
    for name, verts in (("mesh", fan), ("plane", big)):
        out[name] = run_on(plugin_path, tmp_path / name, verts, law, s, dt, steps, steps // 4, 0.0)
    zm, zp = float(out["mesh"][-1][1][2]), float(out["plane"][-1][1][2])
    vm = np.abs(out["mesh"][-1][2]).max()
    d0 = static_overlap(law, s["m"], R, G)
    print(f"\n{where}: rest height mesh {zm!r}, plane {zp!r} (R - delta0 = {R - d0!r}); |v| {vm:.1e}")
    assert vm < 1e-6                                   # at rest
    assert zm == pytest.approx(R - d0, rel=1e-6)
    assert abs(zm - zp) <= 1e-9 * zp


def test_rolling_across_seams_is_smooth(plugin_path, tmp_path):
    """A sphere thrown with spin onto the irregular triangulated floor slides, then rolls
    across many seams and through vertices: force, torque and trajectory equal those on one
    big triangle at every saved step (the tangential overlap carries over to the next
    triangle: no jump)."""
    # soft (overlap 2e-3 R): the overlap R - |x - c| is not swamped by the rounding of |x - c|
    law = make_law(1e6, 4e5, 0.5, 0.4, 0.02)
    R = 0.001
    s = one_sphere(R, x=(0.0, 0.0003, R - 1.5e-6), v=(0.25, 0.02, 0.0), w=(0.0, 150.0, 30.0))
    dt, steps, every = 1e-5, 10000, 100
    a = run_on(plugin_path, tmp_path / "mesh", slope_mesh(0.0), law, s, dt, steps, every, 0.0)
    b = run_on(plugin_path, tmp_path / "plane", slope_mesh(0.0, single=True), law, s, dt, steps, every, 0.0)
    worst = 0.0
    for (t, x, v, w, f, tq), (_, xp, vp, wp, fp, tqp) in zip(a, b):
        for mine, plane in ((x, xp), (v, vp), (w, wp), (f, fp), (tq, tqp)):
            scale = max(np.abs(plane).max(), 1e-300)
            worst = max(worst, np.abs(mine - plane).max() / scale)
    print(f"\nworst relative difference mesh vs plane over {len(a)} saves: {worst:.2e}; "
          f"travelled {a[-1][1][0]:.4f} m")
    assert a[-1][1][0] > 0.02                   # crossed many triangles
    assert worst < 1e-12


def test_periodic_floor_acts_like_a_plane(plugin_path, tmp_path):
    """A floor spanning a periodic box (x periodic, 4 triangles): a sphere rolling with spin
    across the periodic boundary touches the triangles on both sides of it at once through its
    periodic image (MUSEN's virtual particles); one contact acts, so it stays on the floor
    with the plane's normal force.  Until it first reaches the boundary it moves exactly as on
    one big triangle; crossing it, the tangential overlap restarts, as in MUSEN (its
    adjacency of triangles ignores periodicity)."""
    law = make_law(1e6, 4e5, 0.5, 0.4, 0.02)
    R, L = 0.001, 0.01
    h = L / 2
    floor = np.array([[[-h, -0.004, 0], [0.0, -0.004, 0], [0.0, 0.004, 0]],
                      [[-h, -0.004, 0], [0.0, 0.004, 0], [-h, 0.004, 0]],
                      [[0.0, -0.004, 0], [h, -0.004, 0], [h, 0.004, 0]],
                      [[0.0, -0.004, 0], [h, 0.004, 0], [0.0, 0.004, 0]]])
    s = one_sphere(R, v=(0.2, 0.0, 0.0), w=(0.0, 120.0, 10.0))
    d0 = static_overlap(law, s["m"], R, G)
    s["x"] = np.array([h - 0.004, 0.0003, R - d0])
    dt, steps, every = 1e-5, 10000, 50
    a = run_on(plugin_path, tmp_path / "periodic", floor, law, s, dt, steps, every, 0.0,
               box=(-h, h, -0.004, 0.004, -0.004, 0.004), boundary="p f f")
    b = run_on(plugin_path, tmp_path / "plane", slope_mesh(0.0, single=True), law, s, dt, steps, every, 0.0)
    before, fz_worst = 0, 0.0
    for (t, x, v, w, f, tq), (_, xp, vp, wp, fp, tqp) in zip(a, b):
        if xp[0] + R < h:                  # not yet near the boundary: the plane's motion exactly
            before += 1
            assert (x == xp).all() and (f == fp).all() and (tq == tqp).all()
        weight = s["m"] * G                              # f includes gravity: the wall's part
        assert fp[2] + weight > 0.5 * weight
        fz_worst = max(fz_worst, abs((f[2] + weight) / (fp[2] + weight) - 1))
        assert abs(x[2] - xp[2]) < 1e-3 * d0          # on the floor: one contact, never two or none
    crossings = int((b[-1][1][0] - s["x"][0] + 0.004) // L)
    print(f"\nperiodic floor: {before} saves as the plane before the boundary, {crossings} crossings, "
          f"normal force within {fz_worst:.1e} of the plane's")
    assert before >= 5 and crossings >= 2 and fz_worst < 1e-3


# =======================================================================================
def _lammps_script(plugin, folder: Path, restart_out=None, restart_in=None, steps=4000, fix_id="walls",
                   write_state=None):
    """A rotating faceted drum (24 facets, closed ends) with 40 spheres (no sphere-sphere
    contact: no pair style): LAMMPS input text."""
    n = 24
    ang = 2 * math.pi * np.arange(n) / n
    Rd, L = 0.008, 0.006
    ring = np.stack([Rd * np.cos(ang), np.zeros(n), Rd * np.sin(ang)], 1)
    tris = []
    for k in range(n):               # normals point inwards
        a, b = ring[k], ring[(k + 1) % n]
        lo, hi = np.array([0, -L / 2, 0]), np.array([0, L / 2, 0])
        tris += [[a + lo, b + hi, a + hi], [a + lo, b + lo, b + hi]]
        tris += [[lo, b + lo, a + lo], [hi, a + hi, b + hi]]
    tris = np.array(tris)
    law = make_law(1e8, 4e7, 0.6, 0.5, 0.05)
    geoms = [{"name": "drum", "segments": rotation_segment([0, 1, 0], 8.0, [0, 0, 0]),
              "intervals": [(0.0, 10.0, np.zeros(3), np.zeros(3), np.array([0, 8.0, 0]))]}]
    (folder / "mesh.txt").write_text(mesh_text(tris, [0] * len(tris), [0] * len(tris), {(1, 0): law}, geoms))
    lines = [f"plugin load {plugin}", "units si", "atom_style sphere", "atom_modify map array",
             "comm_modify vel yes"]
    if restart_in:
        lines += [f"read_restart {restart_in}"]
    else:
        lines += ["boundary f f f", "region box block -0.01 0.01 -0.004 0.004 -0.01 0.01",
                  "create_box 1 box"]
        for i in range(-3, 3):
            for j in range(-1, 1):
                for m in range(4):
                    x, y, z = 0.0022 * (i + 0.5), 0.0025 * (j + 0.5), -0.0068 + 0.0022 * m
                    if x * x + z * z < 0.0071 ** 2:
                        lines.append(f"create_atoms 1 single {x!r} {y!r} {z!r} units box")
        lines += ["set group all diameter 0.0016 density 2500", "timestep 2e-6"]
    lines += ["neighbor 0.0005 bin", "fix nve all nve/sphere", "fix grav all gravity 9.81 vector 0 0 -1",
              f"fix {fix_id} all musen/wall/mesh mesh.txt", f"run {steps}"]
    if restart_out:
        lines.append(f"write_restart {restart_out}")
        lines.append(f"run {steps}")
    if write_state:
        lines.append(f"write_dump all custom {write_state} id x y z vx vy vz omegax omegay omegaz "
                     "fx fy fz modify sort id format float %.17g")
        lines.append(f"fix_modify {fix_id} write {write_state}.walls")
    return "\n".join(lines) + "\n"


def _mpiexec():
    cand = Path(sys.prefix) / "bin" / "mpiexec"
    return str(cand) if cand.exists() else shutil.which("mpiexec")


def _run_lmp_script(folder: Path, text: str, ranks: int = 1):
    """Run a LAMMPS input through the python module (under mpiexec when ranks > 1)."""
    (folder / "in.lammps").write_text(text)
    runner = folder / "run.py"
    runner.write_text(f"import sys; sys.path.insert(0, {str(REPO)!r})\n"
                      "from fibrelmp._lammps import new_lammps\n"
                      "L = new_lammps(['-log', 'none', '-screen', 'none', '-nocite'])\n"
                      "L.file('in.lammps')\nL.close()\n")
    cmd = [sys.executable, str(runner)]
    if ranks > 1:
        mpi = _mpiexec()
        if mpi is None:
            pytest.skip("no mpiexec")
        cmd = [mpi, "-n", str(ranks)] + cmd
    env = dict(os.environ, OMP_NUM_THREADS="1")
    env.pop("PMI_RANK", None)
    proc = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _read_dump(path: Path):
    from fibrelmp.post.lammps_dump.reader import iter_frames
    return list(iter_frames(path))


def test_serial_and_two_ranks_agree(plugin_path, tmp_path):
    """36 spheres tumbling in a rotating drum mesh: serial and mpiexec -n 2 give the same
    sphere states bit for bit (each sphere's wall forces are summed by its owner in one
    order) and the same triangle forces to rounding."""
    res = {}
    for ranks in (1, 2):
        folder = tmp_path / f"n{ranks}"
        folder.mkdir()
        _run_lmp_script(folder, _lammps_script(plugin_path, folder, steps=12000, write_state="state.dump"), ranks)
        res[ranks] = (_read_dump(folder / "state.dump")[-1], _read_dump(folder / "state.dump.walls")[-1])
    (a, wa), (b, wb) = res[1], res[2]
    for col in ("x", "y", "z", "vx", "vz", "omegay", "fx", "fz"):
        np.testing.assert_array_equal(a.columns[col], b.columns[col])
    fa = np.column_stack([wa.columns[c] for c in ("fx", "fy", "fz")])
    fb = np.column_stack([wb.columns[c] for c in ("fx", "fy", "fz")])
    assert np.abs(fa).max() > 0
    np.testing.assert_allclose(fa, fb, rtol=1e-12, atol=1e-12 * np.abs(fa).max())
    weight = len(a.columns["x"]) * 2500 * 4 / 3 * math.pi * 0.0008 ** 3 * G
    touching = int((np.abs(fa).sum(1) > 0).sum())
    print(f"\ntotal wall force z {fa[:, 2].sum():.6e} N (weight {weight:.6e} N) on {touching} triangles")
    assert touching >= 1 and np.abs(a.columns["vx"]).max() > 1e-3     # carried along by the drum


def test_restart_round_trip(plugin_path, tmp_path):
    """write_restart in the middle of a drum run and read_restart + the same fix continue
    exactly as the uninterrupted run (the contacts' tangential overlaps travel in the restart
    file); without them (another fix ID) the continuation differs."""
    one = tmp_path / "through"
    one.mkdir()
    _run_lmp_script(one, _lammps_script(plugin_path, one, restart_out="mid.restart", steps=8000,
                                        write_state="state.dump"))
    two = tmp_path / "restarted"
    two.mkdir()
    shutil.copy(one / "mid.restart", two / "mid.restart")
    _run_lmp_script(two, _lammps_script(plugin_path, two, restart_in="mid.restart", steps=8000,
                                        write_state="state.dump"))
    three = tmp_path / "no_history"
    three.mkdir()
    shutil.copy(one / "mid.restart", three / "mid.restart")
    _run_lmp_script(three, _lammps_script(plugin_path, three, restart_in="mid.restart", steps=8000,
                                          fix_id="other", write_state="state.dump"))
    a, b, c = (_read_dump(d / "state.dump")[-1] for d in (one, two, three))
    assert a.step == b.step == 16000
    for col in ("x", "z", "vx", "vz", "omegay", "fx"):
        np.testing.assert_array_equal(a.columns[col], b.columns[col])
    assert not np.array_equal(a.columns["vx"], c.columns["vx"])


def test_wall_keeps_velocity_after_its_interval(plugin_path, tmp_path):
    """A plate rises at V until t1 and stops; a sphere rests on it.  After t1 the triangles
    stand still but MUSEN's law still sees them rising: the normal damping pushes the sphere
    up by -C alpha V sqrt(k_n m) and it settles where elastic + damping force carry its weight
    (not at the static overlap)."""
    law = make_law(1e8, 4e7, 0.5, 0.3, 0.0)
    R, V, t1 = 0.001, 1e-4, 0.01
    floor = np.array([[[-0.01, -0.01, 0.0], [0.01, -0.01, 0.0], [0.01, 0.01, 0.0]],
                      [[-0.01, -0.01, 0.0], [0.01, 0.01, 0.0], [-0.01, 0.01, 0.0]]])
    s = one_sphere(R)
    d0 = static_overlap(law, s["m"], R, G)
    s["x"] = np.array([0.001, 0.002, R - d0])
    s["v"] = np.array([0.0, 0.0, V])
    geoms = [{"name": "plate", "segments": translation_segments([0, 0, V], 0.0, t1),
              "intervals": [(0.0, t1, np.array([0, 0, V]), np.zeros(3), np.zeros(3))]}]
    mesh = mesh_text(floor, [0, 0], [0, 0], {(1, 0): law}, geoms)
    lmp = Lammps(plugin_path, tmp_path / "job", mesh, [s], 1e-6, integrate=True, gravity=(0.0, 0.0, -1.0))
    lmp.set_state(s["x"][None], s["v"][None], s["w"][None])
    try:
        lmp.run(10000)                                        # to t1: carried up at V
        x_mid, v_mid, _ = lmp.state()
        lmp.run(40000)                                        # wall stopped at V t1
        x, v, _ = lmp.state()
        top = lmp.wall_array(2)[:, 3:].reshape(2, 3, 3)[:, :, 2]
    finally:
        lmp.close()
    assert np.all(top == V * t1)
    # equilibrium: 4/3 E* sqrt(R) d^1.5 - C alpha V sqrt(2 E* sqrt(R d) m) = m g   (alpha < 0)
    m = s["m"]
    def excess(d):
        kn = 2 * law["E"] * math.sqrt(R * d)
        return 4 / 3 * law["E"] * math.sqrt(R) * d ** 1.5 + TWO_SQRT_5_6 * law["alpha"] * (-V) * math.sqrt(kn * m) - m * G
    lo, hi = 1e-12, d0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    d_kept = 0.5 * (lo + hi)
    gap = x[0, 2] - V * t1
    print(f"\nat t1: vz {v_mid[0, 2]:.6f} (V = {V}); after: overlap {R - gap:.6e}, expected "
          f"{d_kept:.6e} with the kept velocity, static {d0:.6e}")
    assert v_mid[0, 2] == pytest.approx(V, rel=1e-3)
    assert abs(v[0, 2]) < 1e-6
    assert R - gap == pytest.approx(d_kept, rel=1e-6)
    assert abs((R - gap) - d0) > 0.02 * d0


def musen_wall_travel(v: float, t_begin: float, t_end: float, dt: float, end_time: float) -> float:
    """How far cmusen moves a wall with one time interval (velocity v from t_begin to t_end),
    written from its loop (CBaseSimulator::StartSimulation, CCPUSimulator::MoveWalls): the
    prediction iteration moves it by v dt at t = 0 without advancing the time, then each step
    moves it by v dt when t_begin <= t <= t_end at the step's summed time t, then t += dt."""
    z, t = 0.0, 0.0
    if t_begin <= t <= t_end:
        z += v * dt
    while t < end_time:
        if t_begin <= t <= t_end:
            z += v * dt
        t += dt
    return z


def _sphere_on_lifting_floor(radius: float, t_end: float):
    """One sphere above a floor of two triangles ("lift") rising at 0.01 m/s until 0.002 s."""
    from . import granular_models as gm
    mats, contacts = gm.two_materials()
    m = gm.model(gm.spheres([[0.0, 0.0, 0.0006]], radius, [0], mats), mats, contacts, dt=1e-6,
                 t_end=t_end, save_every_time=0.001, gravity=np.array([0, 0, -G]))
    floor = np.array([[[-0.004, -0.004, 0.0], [0.004, -0.004, 0.0], [0.004, 0.004, 0.0]],
                      [[-0.004, -0.004, 0.0], [0.004, 0.004, 0.0], [-0.004, 0.004, 0.0]]])
    gm.add_geometry(m, "lift", floor, 1, motion=[gm.interval(0.0, 0.002, v=(0, 0, 0.01))])
    return m


def test_kept_velocity_is_reported_and_warned(plugin_path, tmp_path):
    """Through fibrelmp: the frames report MUSEN's kept wall velocity and the translation says
    so; without the plugin the same job names the stock representation."""
    from fibrelmp.pipeline.run_model import run_granular
    from fibrelmp.translate.granular_job import build_granular_job

    Rs = 0.0005
    m = _sphere_on_lifting_floor(Rs, 0.004)
    previous = lammps_styles.request_stock(False)
    try:
        job, _, _ = build_granular_job(m, tmp_path / "dry")
        kept = [msg for kind, msg in job.warnings if kind == "MUSEN kept wall velocity"]
        assert kept and "reproduced" in kept[0] and "t = 0.002" in kept[0]
        frames = []
        job = run_granular(m, tmp_path / "run", frames.append, progress=False)
        assert "musen/wall/mesh" in job.walls[0][1]
        assert frames[-1].triangle_velocity[0].tolist() == [0.0, 0.0, 0.01]
        # MUSEN's walls travel by MoveWalls' steps (one more in the prediction iteration), not
        # by v (t_end - t_begin)
        assert frames[-1].triangle_vertices[0, 0, 2] == pytest.approx(
            musen_wall_travel(0.01, 0.0, 0.002, 1e-6, 0.004), rel=1e-12)
        lammps_styles.request_stock(True)
        job, _, _ = build_granular_job(m, tmp_path / "stock")
        kinds = [kind for kind, _ in job.warnings]
        assert "approximate MUSEN physics" in kinds
        assert any("wall geometry 'lift' represented as" in msg for _, msg in job.warnings)
        assert any("NOT reproduced" in msg for kind, msg in job.warnings if kind == "MUSEN kept wall velocity")
    finally:
        lammps_styles.request_stock(previous)


def test_bad_mesh_files_are_clear_errors(plugin_path, tmp_path):
    verts, geometry, material = valley_mesh()
    good = mesh_text(verts, geometry, material, laws_valley(), [{"name": "a"}, {"name": "b"}])
    cases = {
        "no law": (good.replace("laws 4", "laws 3").replace(
            "\n".join(good.splitlines()[2:3]) + "\n", ""), "has no law for atom type"),
        "bad restitution": (good.replace(" 0.7 0.3 0.02", " 1.7 0.3 0.02"), "restitution must be in"),
        "zero area": (good.replace(mesh_text(verts[:1], [0], [0], {}, []).splitlines()[-1],
                                   "0 0 0 0 0 1 1 1 2 2 2"), "zero area"),
        "truncated": ("\n".join(good.splitlines()[:-2]) + "\n", "the file ends early"),
        "garbage": (good.replace("geometries 2", "geometries two"), "not an integer"),
    }
    for name, (text, msg) in cases.items():
        folder = tmp_path / name.replace(" ", "_")
        folder.mkdir()
        (folder / "mesh.txt").write_text(text)
        L = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
        try:
            for c in [f"plugin load {plugin_path}", "units si", "atom_style sphere", "boundary f f f",
                      "region box block -0.02 0.02 -0.02 0.02 -0.02 0.02", "create_box 2 box",
                      "create_atoms 1 single 0 0 0.01 units box", "create_atoms 2 single 0 0.003 0.01 units box"]:
                L.command(c)
            with pytest.raises(Exception, match=msg):
                L.command(f"fix w all musen/wall/mesh {folder / 'mesh.txt'}")
                L.command("run 0")
        finally:
            L.close()


def test_time_driven_walls_with_different_start_velocities_are_warned(plugin_path, tmp_path):
    """A time-driven geometry moves step by step as cmusen moves it (one step ahead of x0 + v t)
    only when its walls start with one stored velocity; otherwise it keeps the exact motion and
    the translation says so."""
    from fibrelmp.translate.granular_job import build_granular_job

    m = _sphere_on_lifting_floor(0.0005, 0.001)
    previous = lammps_styles.request_stock(False)
    try:
        job, _, _ = build_granular_job(m, tmp_path / "same")
        assert not any("one step ahead" in msg for _, msg in job.warnings)
        m.triangles.velocity[-1] = [0.0, 0.0, 0.01]
        job, _, _ = build_granular_job(m, tmp_path / "different")
        assert any(kind == "approximate MUSEN physics" and "'lift'" in msg and "one step ahead" in msg
                   for kind, msg in job.warnings)
    finally:
        lammps_styles.request_stock(previous)


def test_sphere_lists_of_a_static_mesh_follow_a_rolling_sphere(plugin_path, tmp_path):
    """A static mesh keeps each sphere's nearby triangles between steps (MUSEN's Verlet list),
    refreshed when the sphere moved half a neighbour skin.  With LAMMPS never re-neighbouring
    during the run (``neigh_modify once yes``) only that refresh brings the next triangles in:
    the sphere rolling across ~40 skins of the irregular floor moves exactly as on the same
    floor given a (zero) motion, which tests every triangle of its cell at every step."""
    law = make_law(1e6, 4e5, 0.5, 0.4, 0.02)
    R = 0.001
    s = one_sphere(R, x=(0.0, 0.0003, R - 1.5e-6), v=(0.25, 0.02, 0.0), w=(0.0, 150.0, 30.0))
    dt, steps = 1e-5, 8000
    verts = slope_mesh(0.0)
    out = {}
    for name, geometry in (("listed", {"name": "floor"}),
                           ("tested", {"name": "floor", "segments": translation_segments([0.0, 0.0, 0.0])})):
        mesh = mesh_text(verts, [0] * len(verts), [0] * len(verts), {(1, 0): law}, [geometry])
        lmp = Lammps(plugin_path, tmp_path / name, mesh, [s], dt, integrate=True,
                     gravity=(0.0, 0.0, -1.0), box=(-0.05, 0.12, -0.05, 0.05, -0.05, 0.05))
        try:
            lmp.L.command("neigh_modify once yes")
            lmp.set_state(s["x"][None], s["v"][None], s["w"][None])
            f, tq = lmp.run(steps)
            out[name] = (*lmp.state(), f, tq)
        finally:
            lmp.close()
    x = out["listed"][0][0]
    assert x[0] > 0.015 and abs(x[2] - R) < 1e-5       # rolled ~40 half skins, still on the floor
    for mine, reference in zip(out["listed"], out["tested"]):
        np.testing.assert_array_equal(mine, reference)
