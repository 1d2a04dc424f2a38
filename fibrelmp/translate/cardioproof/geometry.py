"""Geometry of a CardioProof case: the surface's triangles, the fluid that fills the cavity
and the wall particles that follow the moving mesh.

Rules (docs/cardioproof.md):

* **Surface.** Shell elements only (triangles; quads split along 0-2).  Walls are every shell
  element that no opening takes; walls and openings together must close the cavity.
* **Inside.** A point is inside when a vertical ray from it crosses the surface an odd number
  of times (any winding, open or closed parts).  Triangles are turned so their normals point
  away from the fluid (tested at each triangle's centroid, on both sides).
* **Fluid.** A simple cubic lattice of spacing ``dx`` over the mesh's bounding box, points at
  cell centres; a point is fluid when it is inside and at least CLEARANCE spacings from every
  wall triangle (closer, it starts half a spacing from the first wall sheet and the flow
  pushes it through the wall's surface); the particles share the cavity's volume.
* **Wall particles.** ``layers`` sheets at distances dx/2, 3dx/2, ... behind the wall (away
  from the fluid; a wall aligned with the lattice is then continued by the wall particles at
  the lattice spacing), each sampled finely and thinned to one particle per ``dx`` cube at the
  start; they stretch with their triangles (a warning when a wall triangle grows by more than
  30 %: its particles are then more than dx apart and fluid may get through).  Each
  keeps its triangle and barycentric coordinates, so it moves with the mesh: its position at
  any frame is the barycentric point of the triangle there plus its layer's offset along the
  triangle's normal there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.mesh.model import Mesh

if TYPE_CHECKING:
    from fibrelmp.translate.cardioproof.case import SphCase

SHELL = ("triangle", "quad")
# memory bounds (docs/cardioproof.md): the fluid lattice over the mesh's bounding box and the
# wall's fine samples are arrays of this many points at most (~100 bytes each while built)
MAX_LATTICE = 4_000_000
MAX_WALL_SAMPLES = 4_000_000
CHUNK = 262_144               # points a triangle's distance test takes at once


def shell_elements(mesh: Mesh, source: Path | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(triangles (t, 3) node indices with their element index as a 4th column, the shell
    elements' region tags (e,)) in file order; volume or line elements are an error."""
    tris, tags, element = [], [], 0
    for block in mesh.cells:
        if block.kind not in SHELL:
            raise InputError(source, None, f"the mesh has {block.kind} elements: the moving wall is a "
                             "surface mesh of triangles and quads (extract the surface first, e.g. "
                             "meshtool extract surface)")
        index = element + np.arange(len(block.nodes))
        if block.kind == "triangle":
            tris.append(np.column_stack([block.nodes, index]))
        else:
            q = block.nodes
            tris.append(np.column_stack([q[:, [0, 1, 2]], index]))
            tris.append(np.column_stack([q[:, [0, 2, 3]], index]))
        tags.append(block.tags)
        element += len(block.nodes)
    if not tris:
        raise InputError(source, None, "the mesh has no shell elements")
    tri = np.concatenate(tris).astype(np.int64)
    return tri[np.argsort(tri[:, 3], kind="stable")], np.concatenate(tags)


def open_edge(x: np.ndarray, tri: np.ndarray) -> tuple[int, int] | None:
    """(triangle row, its edge's first corner) of an edge that not exactly two triangles
    share, nodes merged by position (separate parts may touch: a piston disc in a tube);
    None when the surface is closed."""
    scale = float(np.ptp(x, axis=0).max()) or 1.0
    _, merged = np.unique(np.round(x / (scale * 1e-9)).astype(np.int64), axis=0, return_inverse=True)
    t = merged.reshape(-1)[tri]
    edges = np.concatenate([np.sort(t[:, [i, (i + 1) % 3]], axis=1) for i in range(3)])
    _, inverse, counts = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
    bad = np.flatnonzero(counts[inverse.reshape(-1)] != 2)
    if not len(bad):
        return None
    return int(bad[0] % len(tri)), int(bad[0] // len(tri))


def unit_normals(x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    n = np.cross(x[tri[:, 1]] - x[tri[:, 0]], x[tri[:, 2]] - x[tri[:, 0]])
    norm = np.linalg.norm(n, axis=1)
    return n / np.where(norm > 0, norm, 1.0)[:, None]


def crossings_below(x: np.ndarray, tri: np.ndarray, q: np.ndarray) -> np.ndarray:
    """For each query point, the number of triangles the vertical line through it crosses
    below it.  The queries are shifted by a tiny irrational amount in x and y, so that no line
    passes exactly through an edge or a vertex of a lattice-aligned mesh."""
    scale = float(np.ptp(x, axis=0).max()) or 1.0
    qx = q[:, 0] + scale * 1.4142135623730951e-9
    qy = q[:, 1] + scale * 1.7320508075688772e-9
    order = np.argsort(qx, kind="stable")
    sx = qx[order]
    hits = []
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    lo = np.minimum(np.minimum(a, b), c)
    hi = np.maximum(np.maximum(a, b), c)
    start = np.searchsorted(sx, lo[:, 0], "left")
    stop = np.searchsorted(sx, hi[:, 0], "right")
    for k in np.flatnonzero(stop > start):
        rows = order[start[k]:stop[k]]
        rows = rows[(qy[rows] >= lo[k, 1]) & (qy[rows] <= hi[k, 1])]
        if not len(rows):
            continue
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = a[k], b[k], c[k]
        det = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
        if det == 0.0:
            continue                       # parallel to the line
        px, py = qx[rows] - ax, qy[rows] - ay
        l1 = (px * (cy - ay) - (cx - ax) * py) / det
        l2 = ((bx - ax) * py - px * (by - ay)) / det
        inside = (l1 > 0) & (l2 > 0) & (l1 + l2 < 1)
        z = az + l1 * (bz - az) + l2 * (cz - az)
        below = inside & (z < q[rows, 2])
        hits.append(rows[below])
    if not hits:
        return np.zeros(len(q), np.int64)
    return np.bincount(np.concatenate(hits), minlength=len(q))


def is_inside(x: np.ndarray, tri: np.ndarray, q: np.ndarray) -> np.ndarray:
    return crossings_below(x, tri, q) % 2 == 1


def orient_outward(x: np.ndarray, tri: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """``tri`` with each triangle turned so its normal points away from the inside; which
    triangles' sides could not be told apart (kept as given)."""
    n = unit_normals(x, tri)
    centre = x[tri[:, :3]].mean(axis=1)
    area = 0.5 * np.linalg.norm(np.cross(x[tri[:, 1]] - x[tri[:, 0]], x[tri[:, 2]] - x[tri[:, 0]]), axis=1)
    eps = (0.1 * np.minimum(spacing, np.sqrt(area)))[:, None]
    front = is_inside(x, tri, centre + eps * n)
    back = is_inside(x, tri, centre - eps * n)
    flip = front & ~back
    out = tri.copy()
    out[flip, 1], out[flip, 2] = tri[flip, 2], tri[flip, 1]
    return out, front == back


def enclosed_volume(x: np.ndarray, tri: np.ndarray) -> float:
    """The volume a closed surface of outward triangles encloses (divergence theorem)."""
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def sample(x: np.ndarray, tri: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Points on the triangles, at most ``spacing`` apart: (triangle row (m,), barycentric
    coordinates (m, 3))."""
    parts = np.maximum(np.ceil(edge_lengths(x, tri) / spacing), 1)
    # (n + 1)(n + 2) / 2 samples per triangle, counted in floating point before anything is made
    count = float(((parts + 1) * (parts + 2) / 2).sum())
    if not count <= MAX_WALL_SAMPLES:
        raise InputError(None, None, f"the wall triangles at fluid.spacing / 3 would be {count:.3g} "
                         f"samples (at most {MAX_WALL_SAMPLES:,}): a coarser fluid.spacing")
    parts = parts.astype(np.int64)
    rows, bary = [], []
    for n in np.unique(parts):
        which = np.flatnonzero(parts == n)
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = i + j <= n
        lam = np.column_stack([n - i[keep] - j[keep], i[keep], j[keep]]) / n
        rows.append(np.repeat(which, len(lam)))
        bary.append(np.tile(lam, (len(which), 1)))
    return np.concatenate(rows), np.concatenate(bary)


def at(x: np.ndarray, tri: np.ndarray, rows: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """The barycentric points ``bary`` of triangles ``tri[rows]`` with nodes at ``x``."""
    t = tri[rows]
    return (bary[:, 0:1] * x[t[:, 0]] + bary[:, 1:2] * x[t[:, 1]] + bary[:, 2:3] * x[t[:, 2]])


@dataclass
class WallParticles:
    rows: np.ndarray               # (w,) row into the wall triangles
    bary: np.ndarray               # (w, 3)
    layer: np.ndarray              # (w,) 0 .. layers-1

    def positions(self, x: np.ndarray, tri: np.ndarray, spacing: float) -> np.ndarray:
        """Where they are when the mesh nodes are at ``x`` (m)."""
        n = unit_normals(x, tri)[self.rows]
        return at(x, tri, self.rows, self.bary) + ((self.layer + 0.5) * spacing)[:, None] * n


def edge_lengths(x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(t,) the longest edge of each triangle."""
    return np.max([np.linalg.norm(x[tri[:, i]] - x[tri[:, (i + 1) % 3]], axis=1) for i in range(3)], axis=0)


STRETCHED = 1.3     # wall triangles stretched more: their particles may let fluid through


def wall_particles(x: np.ndarray, tri: np.ndarray, spacing: float, layers: int,
                   lo: np.ndarray) -> WallParticles:
    """``layers`` sheets behind the wall triangles ``tri`` (outward normals), one particle per
    ``spacing`` cube of each sheet (the sample nearest the cube's centre)."""
    rows, bary = sample(x, tri, spacing / 3)
    n = unit_normals(x, tri)[rows]
    base = at(x, tri, rows, bary)
    keep_rows, keep_bary, keep_layer = [], [], []
    for layer in range(layers):
        p = base + (layer + 0.5) * spacing * n
        cell = np.floor((p - lo) / spacing).astype(np.int64)
        off = np.linalg.norm(p - (lo + (cell + 0.5) * spacing), axis=1)
        key = np.ravel_multi_index((cell - cell.min(axis=0)).T, tuple(np.ptp(cell, axis=0) + 1))
        order = np.lexsort((off, key))
        first = order[np.r_[True, key[order][1:] != key[order][:-1]]]
        first.sort()
        keep_rows.append(rows[first])
        keep_bary.append(bary[first])
        keep_layer.append(np.full(len(first), layer))
    return WallParticles(np.concatenate(keep_rows), np.concatenate(keep_bary), np.concatenate(keep_layer))


def lattice_counts(x: np.ndarray, spacing: float) -> np.ndarray:
    """(3,) lattice cells along each side of the bounding box of ``x``; at most MAX_LATTICE
    in all (checked before anything of that size is made)."""
    cells = np.maximum(np.floor(np.ptp(x, axis=0) / spacing), 1)
    total = math.prod(cells.tolist())          # Python floats: inf rather than a numpy warning
    if not total <= MAX_LATTICE:
        raise InputError(None, None, f"fluid.spacing {spacing:g} m cuts the mesh's bounding box into "
                         f"{total:.3g} lattice cells (at most {MAX_LATTICE:,}): a coarser spacing")
    return cells.astype(np.int64)


def segment_distance(p: np.ndarray, s: np.ndarray, e: np.ndarray) -> np.ndarray:
    """(m,) distance of the points ``p`` to the segment from ``s`` to ``e``."""
    d = e - s
    t = np.clip(((p - s) @ d) / float(d @ d), 0.0, 1.0)
    return np.linalg.norm(p - (s + t[:, None] * d), axis=1)


def triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(m,) distance of the points ``p`` to the triangle ``a b c`` (to its plane when the
    projection falls inside it, else to the nearest edge)."""
    ab, ac, ap = b - a, c - a, p - a
    n = np.cross(ab, ac)
    n = n / np.linalg.norm(n)
    d00, d01, d11 = ab @ ab, ab @ ac, ac @ ac
    d20, d21 = ap @ ab, ap @ ac
    den = d00 * d11 - d01 * d01
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    inside = (v >= 0) & (w >= 0) & (v + w <= 1)
    edges = np.minimum(np.minimum(segment_distance(p, a, b), segment_distance(p, b, c)), segment_distance(p, c, a))
    return np.where(inside, np.abs(ap @ n), edges)


def nearest_within(x: np.ndarray, tri: np.ndarray, q: np.ndarray, limit: float) -> np.ndarray:
    """(m,) each point's distance to the nearest of the triangles ``tri`` (nodes ``x``), inf
    beyond ``limit``: each triangle tests only the points in its bounding box enlarged by
    ``limit`` (sorted by x, as in crossings_below)."""
    order = np.argsort(q[:, 0], kind="stable")
    sx = q[order, 0]
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    lo = np.minimum(np.minimum(a, b), c) - limit
    hi = np.maximum(np.maximum(a, b), c) + limit
    start = np.searchsorted(sx, lo[:, 0], "left")
    stop = np.searchsorted(sx, hi[:, 0], "right")
    nearest = np.full(len(q), np.inf)
    for k in np.flatnonzero(stop > start):
        # in chunks: a large slanted triangle's box can hold the whole lattice
        for first in range(start[k], stop[k], CHUNK):
            rows = order[first:min(first + CHUNK, stop[k])]
            rows = rows[np.all((q[rows, 1:] >= lo[k, 1:]) & (q[rows, 1:] <= hi[k, 1:]), axis=1)]
            if len(rows):
                nearest[rows] = np.minimum(nearest[rows], triangle_distance(q[rows], a[k], b[k], c[k]))
    nearest[nearest >= limit] = np.inf
    return nearest


# fluid starts at least a quarter spacing from a wall, so at least 3/4 spacing from the first
# wall sheet (the lattice came to 0.035 dx of the tube's wall and the flow pushed such particles
# through it); half a spacing, the spacing rule's ideal, leaves curved walls a gap of dx/2 on
# average and the outflow estimates 8 % high (docs/cardioproof.md); the tolerance keeps points
# exactly at the clearance
CLEARANCE = 0.25 * (1 - 1e-6)


def fluid_points(x: np.ndarray, tri: np.ndarray, spacing: float, walls: np.ndarray | None = None) -> np.ndarray:
    """Cell centres of a cubic lattice over the bounding box that are inside the closed
    surface ``tri`` and (given the ``walls`` triangles) at least CLEARANCE spacings from
    every wall."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    counts = lattice_counts(x, spacing)
    # the lattice is centred in the box, so a box-aligned wall is half a spacing from the
    # nearest points on both sides
    start = lo + 0.5 * ((hi - lo) - counts * spacing)
    axes = [start[a] + (np.arange(counts[a]) + 0.5) * spacing for a in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    fluid = grid[is_inside(x, tri, grid)]
    if walls is not None and len(walls):
        fluid = fluid[~(nearest_within(x, walls, fluid, CLEARANCE * spacing) < CLEARANCE * spacing)]
    return fluid


def motion_frames(case: "SphCase") -> Iterator[np.ndarray]:
    """The mesh's node positions (m) at each motion frame (the mesh itself when static)."""
    if case.motion is None:
        yield case.mesh.points_m
        return
    if case.motion.kind == "dynpt":
        from fibrelmp.mesh.opencarp.dynpt import DynptReader

        for frame in DynptReader(case.motion.files[0]):
            yield frame.points * case.mesh.unit
        return
    from fibrelmp.translate.cardioproof.case import read_mesh

    for path in case.motion.files:
        mesh = read_mesh(path, case.mesh.unit)
        if len(mesh.points) != len(case.mesh.points):
            raise InputError(path, None, f"{len(mesh.points)} nodes, the case's mesh has "
                             f"{len(case.mesh.points)}")
        yield mesh.points_m
