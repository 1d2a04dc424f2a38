"""Closed triangle meshes (MUSEN's analysis volumes) for the generators: volume, inside test,
closest points of spheres on the surface.

A mesh is a ``(T, 3, 3)`` array of triangle vertices.  Normals are made to point inwards
(``inward_normals``), as in the inverted mesh MUSEN's package generator turns the volume
into, whichever way the file winds them.
"""

from __future__ import annotations

import numpy as np


def signed_volume(tri: np.ndarray) -> float:
    """Divergence theorem: positive when the triangles wind counter-clockwise seen from
    outside."""
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


def volume(tri: np.ndarray) -> float:
    """``CTriangularMesh::Volume`` of a closed mesh (m^3)."""
    return abs(signed_volume(tri))


def inward_normals(tri: np.ndarray) -> np.ndarray:
    """Unit normals pointing into the volume."""
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    return -n if signed_volume(tri) > 0 else n


def inside(points: np.ndarray, tri: np.ndarray, chunk: int = 2048) -> np.ndarray:
    """Whether each point lies inside the closed mesh (generalised winding number: the
    solid angles of all triangles seen from the point sum to 4 pi inside, 0 outside)."""
    out = np.zeros(len(points), bool)
    for s in range(0, len(points), chunk):
        p = points[s:s + chunk, None, None, :]
        r = tri[None, :, :, :] - p                                # (n, T, 3, 3)
        ln = np.linalg.norm(r, axis=3)
        a, b, c = r[:, :, 0], r[:, :, 1], r[:, :, 2]
        la, lb, lc = ln[:, :, 0], ln[:, :, 1], ln[:, :, 2]
        num = np.einsum("ntk,ntk->nt", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ntk,ntk->nt", a, b) * lc
               + np.einsum("ntk,ntk->nt", b, c) * la + np.einsum("ntk,ntk->nt", c, a) * lb)
        winding = 2.0 * np.arctan2(num, den).sum(axis=1) / (4.0 * np.pi)
        out[s:s + chunk] = np.abs(winding) > 0.5
    return out


def closest_points(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The point of triangle (a, b, c) nearest to p, row by row (Ericson, Real-Time Collision
    Detection, 5.1.5, vectorised)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = p - b
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = p - c
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = 1.0 / (va + vb + vc)
        out = a + ab * (vb * denom)[:, None] + ac * (vc * denom)[:, None]       # face
        # edges (bc, ac, ab) then vertices, each overriding where its region holds
        w_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        on = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)
        out[on] = (b + (c - b) * w_bc[:, None])[on]
        w_ac = d2 / (d2 - d6)
        on = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
        out[on] = (a + ac * w_ac[:, None])[on]
        w_ab = d1 / (d1 - d3)
        on = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
        out[on] = (a + ab * w_ab[:, None])[on]
    on = (d6 >= 0) & (d5 <= d6)
    out[on] = c[on]
    on = (d3 >= 0) & (d4 <= d3)
    out[on] = b[on]
    on = (d1 <= 0) & (d2 <= 0)
    out[on] = a[on]
    return out


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", u, v)


def near_pairs(centres: np.ndarray, reach: np.ndarray, tri: np.ndarray,
               normals: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sphere rows, triangle rows, distances) of every sphere within ``reach`` of a
    triangle: the planes first (one matrix product), exact distances for the few left."""
    plane = np.abs((centres @ normals.T) - np.einsum("ij,ij->i", tri[:, 0], normals)[None, :])
    rows, tris = np.nonzero(plane < reach[:, None])
    q = closest_points(centres[rows], tri[tris, 0], tri[tris, 1], tri[tris, 2])
    dist = np.linalg.norm(centres[rows] - q, axis=1)
    keep = dist < reach[rows]
    return rows[keep], tris[keep], dist[keep]


def totally_inside(centres: np.ndarray, radii: np.ndarray, tri: np.ndarray,
                   normals: np.ndarray) -> np.ndarray:
    """``GetSpheresTotallyInside``: centre inside and no surface point closer than the radius."""
    ok = inside(centres, tri)
    rows, _, _ = near_pairs(centres, radii, tri, normals)
    ok[rows] = False
    return ok
