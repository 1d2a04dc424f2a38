"""Small GranularModels built directly in Python for the granular tests (no readers)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.granmodel import (ContactLaw, Geometry, GranularModel, GranularPlan, Material,
                                MotionInterval, Plane, SolidBonds, Spheres, Triangles,
                                hertz_effective)

GLASS = dict(density=2500.0, youngs=5e10, poisson=0.22, normal_strength=5e7, shear_strength=5e7)
STEEL = dict(density=7750.0, youngs=2e11, poisson=0.3, normal_strength=4e9, shear_strength=4e9)


def material(key: str, **props) -> Material:
    return Material(key=key, name=key, **props)


def law_for(m1: Material, m2: Material, e: float = 0.9, mu: float = 0.45, mur: float = 0.0) -> ContactLaw:
    es, gs = hertz_effective(m1, m2)
    return ContactLaw(es, gs, e, mu, mur)


def spheres(x, r, mats, materials, v=None, w=None, q=None) -> Spheres:
    x = np.atleast_2d(np.asarray(x, float))
    n = len(x)
    r = np.broadcast_to(np.asarray(r, float), (n,)).copy()
    mats = np.broadcast_to(np.asarray(mats, np.int64), (n,)).copy()
    dens = np.array([materials[m].density for m in mats])
    mass = dens * 4.0 / 3.0 * math.pi * r ** 3
    quat = np.tile([1.0, 0, 0, 0], (n, 1)) if q is None else np.asarray(q, float)
    return Spheres(ids=np.arange(n, dtype=np.int64), material=mats, radius=r, contact_radius=r.copy(),
                   mass=mass, position=x,
                   velocity=np.zeros((n, 3)) if v is None else np.atleast_2d(np.asarray(v, float)),
                   omega=np.zeros((n, 3)) if w is None else np.atleast_2d(np.asarray(w, float)),
                   quaternion=quat, active_start=np.zeros(n), active_end=np.full(n, np.inf))


def model(sph: Spheres, materials, contacts, dt, t_end, save_every_steps=None, save_every_time=None,
          **plan_kw) -> GranularModel:
    plan = GranularPlan(dt=dt, t_start=0.0, t_end=t_end, save_every_steps=save_every_steps,
                        save_every_time=save_every_time, **plan_kw)
    return GranularModel(source=Path("test_model.txt"), kind="musen", materials=materials,
                         contacts=contacts, spheres=sph, plan=plan)


def bonds(pairs, d, L0, mat=0) -> SolidBonds:
    pairs = np.atleast_2d(np.asarray(pairs, np.int64))
    m = len(pairs)
    return SolidBonds(ids=np.arange(100, 100 + m), pair=pairs, material=np.full(m, mat),
                      diameter=np.full(m, float(d)), length0=np.broadcast_to(np.asarray(L0, float), (m,)).copy(),
                      active_start=np.zeros(m), active_end=np.full(m, np.inf))


def box_triangles(lo, hi) -> np.ndarray:
    """12 triangles of an axis-aligned box (2 per face), vertices (12,3,3)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c = np.array([[lo[0] if i & 1 == 0 else hi[0], lo[1] if i & 2 == 0 else hi[1],
                   lo[2] if i & 4 == 0 else hi[2]] for i in range(8)])
    quads = [(0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5)]
    tris = []
    for a, b, cc, d in quads:
        tris.append([c[a], c[b], c[cc]])
        tris.append([c[a], c[cc], c[d]])
    return np.array(tris)


def oriented(verts, outward: bool = True) -> np.ndarray:
    """The triangles of a closed convex shape with normals (V2-V1)x(V3-V1) pointing out of it
    (or into it): MUSEN pushes spheres along a wall's normal, so its normals face the spheres
    (outward for a plate the spheres sit on, inward for a container)."""
    v = np.array(verts, float)
    c = v.reshape(-1, 3).mean(0)
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    flip = ((v.mean(1) - c) * n).sum(1) < 0
    if not outward:
        flip = ~flip
    v[flip] = v[flip][:, [0, 2, 1]]
    return v


def rect_triangles(corners) -> np.ndarray:
    a, b, c, d = [np.asarray(p, float) for p in corners]
    return np.array([[a, b, c], [a, c, d]])


def add_geometry(m: GranularModel, name: str, verts: np.ndarray, mat: int, motion=None,
                 rotate_around_centre=False) -> Geometry:
    verts = np.asarray(verts, float)
    k = len(verts)
    old = m.triangles
    start = 0 if old is None else old.count
    new = Triangles(ids=np.arange(1000 + start, 1000 + start + k), material=np.full(k, mat),
                    vertices=verts, velocity=np.zeros((k, 3)), active_start=np.zeros(k),
                    active_end=np.full(k, np.inf))
    if old is not None:
        new = Triangles(ids=np.r_[old.ids, new.ids], material=np.r_[old.material, new.material],
                        vertices=np.vstack([old.vertices, new.vertices]),
                        velocity=np.vstack([old.velocity, new.velocity]),
                        active_start=np.r_[old.active_start, new.active_start],
                        active_end=np.r_[old.active_end, new.active_end])
    m.triangles = new
    g = Geometry(name=name, key=name.upper(), mass=0.0, free=(False, False, False),
                 rotate_around_centre=rotate_around_centre, motion_type=1 if motion else 0,
                 motion=list(motion or []), triangle_rows=np.arange(start, start + k))
    m.geometries.append(g)
    return g


def interval(t0, t1, v=(0, 0, 0), centre=(0, 0, 0), w=(0, 0, 0)) -> MotionInterval:
    return MotionInterval(t0, t1, np.asarray(v, float), np.asarray(centre, float), np.asarray(w, float))


def plane(normal, point, mat) -> Plane:
    n = np.asarray(normal, float)
    return Plane(n / np.linalg.norm(n), np.asarray(point, float), mat)


def two_materials():
    glass, steel = material("Glass", **GLASS), material("Steel", **STEEL)
    mats = [glass, steel]
    contacts = {(0, 0): law_for(glass, glass, 0.9, 0.45, 0.05),
                (0, 1): law_for(glass, steel, 0.8, 0.6, 0.05),
                (1, 1): law_for(steel, steel, 0.6, 0.7, 0.05)}
    return mats, contacts


def run(model: GranularModel, folder: Path, name: str = "job"):
    """Run ``model`` in ``folder/name``: (job, every saved frame in order)."""
    from fibrelmp.pipeline.run_model import run_granular

    frames = []
    job = run_granular(model, Path(folder) / name, frames.append, progress=False)
    return job, frames
