"""Wall particles: geometries no region can represent are tiled with frozen spheres (one
LAMMPS type per wall material, after the sphere types).  Geometries needing very many are
tiled only within reach of the spheres (``reach.Travel``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.translate.granular.geometry import (particle_side, tile_triangles, tile_triangles_within,
                                                  triangle_normals)

TILE_SPACING_FACTOR = 0.5   # wall tiles: spacing = 0.5 * smallest sphere contact radius
TILE_RADIUS_FACTOR = 0.6    # wall tile radius = 0.6 * spacing
TILE_MASS_FACTOR = 1e20     # wall tiles weigh 1e20 x the heaviest sphere (m* = m_p)
TILE_CLIP_MIN = 100_000     # geometries needing more wall particles are tiled within reach only
MANY_TILES = 2_000_000      # more wall particles than this: "the run will be slow"


@dataclass
class WallTiles:
    """The wall particles of every tiled geometry, concatenated in plan order."""

    spacing: float
    radius: float
    materials: list[int]             # wall materials of tiled geometries, one LAMMPS type each
    type_of_mat: dict[int, int]
    x: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    types: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    v: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    ids: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    reach: float = math.inf          # placed only within this distance of the spheres ...
    keep_lo: np.ndarray | None = None    # ... i.e. inside this box (None: everywhere)
    keep_hi: np.ndarray | None = None
    clipped: list[str] = field(default_factory=list)    # geometries tiled within reach only

    @property
    def total(self) -> int:
        return len(self.ids)

    def largest_radius(self, r_max: float) -> float:
        """The larger of ``r_max`` (spheres) and the wall-particle radius, if there are any."""
        return max(r_max, self.radius if self.total else 0.0)


def tile_types(wall_plans, r_min: float, n_sphere_types: int) -> WallTiles:
    """Spacing, radius and LAMMPS types of the wall particles (none placed yet)."""
    spacing = TILE_SPACING_FACTOR * r_min
    materials = sorted({wp.material for wp in wall_plans if wp.kind == "tiles"})
    return WallTiles(spacing, TILE_RADIUS_FACTOR * spacing, materials,
                     {m: n_sphere_types + 1 + i for i, m in enumerate(materials)})


def place_tiles(model: GranularModel, wall_plans, tiles: WallTiles, spheres, axes, travel, t_start: float,
                warnings: list[tuple[str, str]]) -> None:
    """Place the wall particles of every tiled plan (sets its tile_ids / tile_owner and
    completes its description), behind the faces, inside the domain (``axes``, a ``BoxAxes``)
    and, for many particles of static walls, within reach of the spheres."""
    sp = model.spheres
    x, rows, r_max = spheres.x, spheres.rows, spheres.r_max
    tile_spacing, tile_radius = tiles.spacing, tiles.radius
    _keep_box(model, wall_plans, tiles, spheres, axes, travel)
    keep_lo, keep_hi = tiles.keep_lo, tiles.keep_hi
    removal_axes, dom_lo, face_hi = axes.removal_axes, axes.dom_lo, axes.face_hi
    tile_x, tile_type, tile_v, tile_ids_all = [], [], [], []
    next_id = int(sp.count) + 1
    tile_total = 0
    for wp in wall_plans:
        if wp.kind != "tiles":
            continue
        v = model.triangles.vertices[wp.triangle_rows]
        clip = (keep_lo is not None and not wp.kinematics.moving
                and tile_estimate(v, tile_spacing) > TILE_CLIP_MIN
                and not ((v >= keep_lo) & (v <= keep_hi)).all())
        if clip:
            p, owner = tile_triangles_within(v, tile_spacing, keep_lo - tile_radius, keep_hi + tile_radius)
        else:
            p, owner = tile_triangles(v, tile_spacing)
        side = particle_side(v, x[rows], 4.0 * r_max)
        nrm = triangle_normals(v)
        # offset tiles behind the face by their radius so the contact surface is the face
        p = p - (side[owner] * tile_radius)[:, None] * nrm[owner]
        if clip:
            near = ((p >= keep_lo) & (p <= keep_hi)).all(axis=1)
            p, owner = p[near], owner[near]
            tiles.clipped.append(wp.name)
        inbox = np.ones(len(p), bool)
        for a in range(3):
            if removal_axes[a]:
                inbox &= (p[:, a] >= dom_lo[a]) & (p[:, a] < face_hi[a])
        if not inbox.all():
            warnings.append(("wall tiles outside domain", f"{wp.name}: {int((~inbox).sum())} wall "
                             "particle(s) outside the simulation domain are left out"))
        p, owner = p[inbox], owner[inbox]
        _refuse_centre_on_tile(model, wp.name, x[rows], sp.ids[rows], p)
        ids = np.arange(next_id, next_id + len(p))
        next_id += len(p)
        tile_total += len(p)
        wp.tile_ids = ids
        wp.tile_owner = wp.triangle_rows[owner]
        tile_x.append(p)
        tile_type.append(np.full(len(p), tiles.type_of_mat[wp.material]))
        seg = wp.kinematics.segment(t_start) if wp.kinematics.moving else None
        if seg is not None:
            dr, db = seg.rate(t_start)
            vel = p @ dr.T + db
        else:
            vel = np.zeros_like(p)
        tile_v.append(vel)
        tile_ids_all.append(ids)
        wp.description += (f" ({len(p)} wall particles, spacing {tile_spacing:.4g}, radius "
                           f"{tile_radius:.4g}{', only within reach of the spheres' if clip else ''})")
    if tile_total > MANY_TILES:
        warnings.append(("many wall particles", f"{tile_total} wall particles tile the triangle "
                         "walls; the run will be slow"))
    if tile_x:
        tiles.x, tiles.types = np.concatenate(tile_x), np.concatenate(tile_type)
        tiles.v, tiles.ids = np.concatenate(tile_v), np.concatenate(tile_ids_all)


def _refuse_centre_on_tile(model: GranularModel, name: str, centres: np.ndarray, ids: np.ndarray,
                           tiles: np.ndarray) -> None:
    """A sphere whose centre is exactly a wall particle's (a sphere centred in a tiled wall's
    plane, where no side is known to put the particles behind): stock pair granular divides by
    their zero distance and gives nan, as MUSEN does for a centre on a wall, so the scene is
    refused (fibrelmp's fix musen/wall/mesh takes the face normal there instead)."""
    if not len(centres) or not len(tiles):
        return
    as_rows = lambda a: np.ascontiguousarray(a, float).view([("", float)] * 3).ravel()  # noqa: E731
    on = np.flatnonzero(np.isin(as_rows(centres), as_rows(tiles)))
    if len(on):
        raise InputError(model.source, None, f"sphere {int(ids[on[0]])} has its centre exactly on a "
                         f"wall particle of geometry '{name}' (the stock LAMMPS stand-in for its "
                         "triangles): the contact has no direction (LAMMPS and MUSEN give nan); "
                         "move the sphere off the wall, or use fibrelmp's styles (fix "
                         "musen/wall/mesh takes the face normal there)")


def _keep_box(model: GranularModel, wall_plans, tiles: WallTiles, spheres, axes, travel) -> None:
    """tiles.reach and the box wall particles are kept in: static walls needing more than
    TILE_CLIP_MIN particles are tiled within reach of the spheres only."""
    rows, x, r_max = spheres.rows, spheres.x, spheres.r_max
    many_tiles = any(wp.kind == "tiles" and tile_estimate(model.triangles.vertices[wp.triangle_rows],
                                                          tiles.spacing) > TILE_CLIP_MIN
                     for wp in wall_plans)
    if many_tiles and not any(wp.kinematics.moving for wp in wall_plans):
        tiles.reach = travel.reach(r_max)
    if len(rows) and math.isfinite(tiles.reach):
        pad_keep = tiles.reach + 2.0 * (r_max + tiles.radius)
        tiles.keep_lo = x[rows].min(axis=0) - pad_keep
        tiles.keep_hi = x[rows].max(axis=0) + pad_keep
        for a in range(3):
            if axes.bnd[a] == "p":
                tiles.keep_lo[a], tiles.keep_hi[a] = -math.inf, math.inf


def _tile_counts(v: np.ndarray, spacing: float) -> np.ndarray:
    """Per triangle the grid divisions ``tile_triangles`` uses."""
    e = np.max(np.stack([np.linalg.norm(v[:, 1] - v[:, 0], axis=1),
                         np.linalg.norm(v[:, 2] - v[:, 0], axis=1),
                         np.linalg.norm(v[:, 2] - v[:, 1], axis=1)]), axis=0)
    with np.errstate(all="ignore"):
        return np.maximum(1.0, np.ceil(e / spacing - 1e-9))


def tile_estimate(v: np.ndarray, spacing: float) -> float:
    """Number of grid points ``tile_triangles`` generates (before de-duplication)."""
    if not len(v):
        return 0.0
    n = _tile_counts(v, spacing)
    return float(np.sum((n + 1) * (n + 2) / 2))
