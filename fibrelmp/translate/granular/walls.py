"""Walls of a granular job: how each geometry (triangle group) or plane is represented in
LAMMPS (``plan_walls``) and the region, fix and variable commands of the regions, planes and
moving wall particles (``wall_commands``).

With fibrelmp's LAMMPS styles (``lammps_styles.plugin()``), every geometry of a MUSEN scene is
its exact triangles in ``fix musen/wall/mesh`` (kind ``mesh``: MUSEN's particle-wall law and
contact resolution; see ``mesh.py``).  Without them (and for DEMDF planes, whose law is not
MUSEN's) stock LAMMPS walls stand in: a region box / cylinder, wall particles ("tiles"), or a
wall/gran plane, and MUSEN geometries are named in an "approximate MUSEN physics" warning."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fibrelmp import lammps_styles
from fibrelmp.errors import InputError
from fibrelmp.granmodel import Geometry, GranularModel
from fibrelmp.lammps_text import LammpsText, comment_text
from fibrelmp.translate.granular.contacts import check_law, law_args, rolling_spring
from fibrelmp.translate.granular.geometry import (BoxShape, CylinderShape, closest_points, detect_cylinder,
                                                  detect_oriented_box, geometry_triangle_rows)
from fibrelmp.translate.granular.kinematics import Kinematics, geometry_kinematics, piecewise_expression
from fibrelmp.translate.granular import models as physics
from fibrelmp.translate.granular.mesh import MESH_FIX, MESH_NAME
from fibrelmp.translate.lammps_format import float_text


@dataclass
class WallPlan:
    """How one geometry (group of triangles) or plane is represented."""

    name: str
    kind: str                        # mesh | box | cylinder | tiles | plane | ignored
    description: str
    triangle_rows: np.ndarray        # rows into model.triangles (empty for planes)
    kinematics: Kinematics
    material: int
    shape: BoxShape | CylinderShape | None = None
    region: str | None = None        # LAMMPS region id
    fixes: list[str] = field(default_factory=list)
    contact_vars: list[str] = field(default_factory=list)   # 6 dump columns (fx fy fz cx cy cz)
    tile_ids: np.ndarray | None = None       # LAMMPS ids of its wall tiles
    tile_owner: np.ndarray | None = None     # triangle row of each tile
    plane_index: int | None = None           # index into model.planes
    stepped: Geometry | None = None          # moved step by step by fix musen/wall/mesh (force-
                                             # dependent or free motion): the geometry it follows


def use_mesh(model: GranularModel) -> bool:
    """MUSEN's triangle walls become ``fix musen/wall/mesh`` triangles: with fibrelmp's styles
    (DEMDF's planes keep stock walls: their law is fibrelmp's soft-sphere stand-in for BOS's
    hard spheres, not MUSEN's)."""
    return model.kind == "musen" and lammps_styles.plugin().available


def plan_walls(model: GranularModel, dt: float, t_end: float, mesh: bool | None = None) -> list[WallPlan]:
    """Representation of every geometry / plane (no files, used by ``fibrelmp check`` too).
    ``mesh``: exact triangles in fix musen/wall/mesh (default: ``use_mesh``)."""
    if mesh is None:
        mesh = use_mesh(model)
    plans: list[WallPlan] = []
    tris = model.triangles
    t0 = model.plan.t_start
    for name, geom, rows in geometry_triangle_rows(model):
        v = tris.vertices[rows]
        stepped = geom is not None and (is_stepped(geom) or (mesh and steps_by_time(geom, tris.velocity[rows])))
        if geom is not None:
            _check_motion(model, geom, mesh, rows)
            kin = (stepped_kinematics(geom) if is_stepped(geom)
                   else geometry_kinematics(geom, v, t0, t_end))
        else:
            kin = Kinematics()
        mats, counts = np.unique(tris.material[rows], return_counts=True)
        material = int(mats[np.argmax(counts)])
        if mesh:
            if geom is None:
                plans.append(WallPlan(name, "ignored", "in no geometry: not simulated (MUSEN's "
                                      "simulator only uses the walls of geometries)", rows, kin, material))
                continue
            desc = (f"{len(rows)} exact triangles -> fix musen/wall/mesh (MUSEN's particle-wall "
                    "contact, face/edge/vertex)")
            if stepped:
                kind = ("force-dependent" if geom.motion_type in (2, 3) else
                        "free" if is_stepped(geom) else "time-dependent")
                desc += f", moving step by step as MUSEN moves it ({kind} motion)"
            elif kin.moving:
                desc += ", moving (time-dependent motion)"
            plans.append(WallPlan(name, "mesh", desc, rows, kin, material,
                                  stepped=geom if stepped else None))
            continue
        shape = detect_oriented_box(v) or detect_cylinder(v) if len(rows) else None
        if shape is not None and kin.rotating and not _region_can_rotate(shape, kin):
            shape = None        # a region rotates about one fixed axis direction only
        if isinstance(shape, BoxShape):
            kind = "box"
        elif isinstance(shape, CylinderShape):
            kind = "cylinder"
        else:
            kind = "tiles"
        desc = shape.describe() if shape is not None else "tiled with frozen wall particles"
        if kin.moving:
            desc += ", moving (time-dependent motion)"
        if len(mats) > 1:
            desc += f"; mixed wall materials, uses '{model.materials[material].name}' for all"
        plans.append(WallPlan(name, kind, desc, rows, kin, material, shape))
    for k, pl in enumerate(model.planes):
        n = np.asarray(pl.normal, float)
        n = n / np.linalg.norm(n)
        axis = int(np.argmax(np.abs(n)))
        aligned = abs(abs(n[axis]) - 1) < 1e-12
        if aligned:
            ax = "xyz"[axis]
            sign = "+" if n[axis] > 0 else "-"
            desc = f"plane {ax} = {pl.point[axis]:.6g} (normal {sign}{ax}) -> fix wall/gran {ax}plane"
        else:
            desc = "plane through " + ", ".join(f"{c:.6g}" for c in pl.point) + " -> LAMMPS region plane"
        plans.append(WallPlan(f"plane {k + 1}", "plane", desc, np.zeros(0, np.int64), Kinematics(),
                              int(pl.material), plane_index=k))
    return plans


def _region_can_rotate(shape, kin: Kinematics) -> bool:
    if kin.single_axis is None:
        return False
    if isinstance(shape, BoxShape) and shape.frame is not None:
        ax, th = shape.rotation()
        return th == 0.0 or abs(abs(float(ax @ kin.single_axis)) - 1) < 1e-9
    return True


def is_stepped(geom: Geometry) -> bool:
    """The geometry's motion depends on the forces on it: force-dependent intervals (types 2
    and 3) or free axes with a mass (CPUSimulator::MoveWalls solves Newton's law then)."""
    return geom.motion_type in (2, 3) or (any(geom.free) and geom.mass != 0)


def steps_by_time(geom: Geometry, wall_velocities: np.ndarray) -> bool:
    """A time-dependent motion that fix musen/wall/mesh moves step by step as
    CPUSimulator::MoveWalls does: v(t) dt per step, and once more in MUSEN's prediction
    iteration at t = 0, so MUSEN's walls (in its contacts and its result file) are one step
    ahead of the exact motion x0 + v t (docs/musen.md, "Walls one step ahead").  Walls that
    start with different stored velocities keep the exact motion (the fix starts a geometry
    from one velocity); ``wall_warnings`` names them."""
    if geom.motion_type != 1 or not any(np.any(np.asarray(iv.velocity, float) != 0)
                                        or np.any(np.asarray(iv.angular_velocity, float) != 0)
                                        for iv in geom.motion):
        return False
    vel = np.asarray(wall_velocities, float)
    return not len(vel) or bool(np.all(vel == vel[:1]))


def stepped_kinematics(geom: Geometry) -> Kinematics:
    """What the job knows in advance of a stepped geometry: only its interval velocities
    (pacing); fix musen/wall/mesh moves it and reports where it is."""
    vels = [iv.velocity for iv in geom.force_motion] + [iv.velocity for iv in geom.motion]
    return Kinematics(intervals=[(-math.inf, math.inf, np.asarray(v, float)) for v in vels])


def _check_motion(model: GranularModel, geom: Geometry, mesh: bool, rows: np.ndarray) -> None:
    if geom.motion_type not in (0, 1, 2, 3):
        raise InputError(model.source, None, f"geometry '{geom.name}': unknown motion type "
                         f"{geom.motion_type}")
    if not is_stepped(geom):
        return
    what = "force-dependent" if geom.motion_type in (2, 3) else "free (force-driven)"
    if not mesh:
        raise InputError(model.source, None, f"geometry '{geom.name}': {what} geometry motion "
                         "needs fibrelmp's LAMMPS styles (fix musen/wall/mesh)")
    if geom.motion_type in (2, 3) and not geom.force_motion:
        raise InputError(model.source, None, f"geometry '{geom.name}': force-dependent motion "
                         "without intervals (MUSEN refuses it too)")
    vel = model.triangles.velocity[np.asarray(rows, np.int64)]
    if len(vel) and np.any(vel != vel[:1]):
        # MUSEN starts each wall from its own stored velocity; fibrelmp's geometry has one
        raise InputError(model.source, None, f"geometry '{geom.name}': its walls start with "
                         f"different velocities; {what} motion needs one velocity per geometry")


def describe_walls(model: GranularModel) -> list[str]:
    """One line per geometry / plane: how LAMMPS represents it."""
    plan = model.plan
    out = []
    for wp in plan_walls(model, plan.dt, plan.t_end):
        counted = len(wp.triangle_rows) and wp.kind != "mesh"
        out.append(f"{wp.name}: {wp.description}" + (f" ({len(wp.triangle_rows)} triangles)"
                                                     if counted else ""))
    return out


def spheres_behind(v: np.ndarray, x: np.ndarray, r: np.ndarray) -> int:
    """How many of the triangles v (k,3,3) have a sphere (centres x, radii r) touching their
    face from behind: the centre projects inside the triangle at a signed distance in
    (-r, 0] along the normal (V2 - V1) x (V3 - V1)."""
    if not len(v) or not len(x):
        return 0
    order = np.argsort(x[:, 0], kind="stable")
    xs, rs = x[order], r[order]
    reach = float(rs.max())
    e1, e2 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n, axis=1)[:, None]
    lo, hi = v.min(axis=1) - reach, v.max(axis=1) + reach
    a = np.searchsorted(xs[:, 0], lo[:, 0], "left")
    b = np.searchsorted(xs[:, 0], hi[:, 0], "right")
    count = 0
    for k in np.flatnonzero(b > a):
        p, rr = xs[a[k]:b[k]], rs[a[k]:b[k]]
        near = ((p >= lo[k]) & (p <= hi[k])).all(axis=1)
        p, rr = p[near], rr[near]
        d = (p - v[k, 0]) @ n[k]
        q = p - d[:, None] * n[k] - v[k, 0]
        d00, d01, d11 = e1[k] @ e1[k], e1[k] @ e2[k], e2[k] @ e2[k]
        d20, d21 = q @ e1[k], q @ e2[k]
        den = d00 * d11 - d01 * d01
        g, bt = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
        inside = (g >= 0) & (bt >= 0) & (g + bt <= 1)
        if (inside & (d <= 0) & (d > -rr)).any():
            count += 1
    return count


def spheres_on_triangles(v: np.ndarray, x: np.ndarray, r: np.ndarray) -> int:
    """How many spheres (centres x, radii r) have their centre on one of the triangles v
    (k,3,3): closer than 1e-12 radii (fix musen/wall/mesh then takes the face normal as the
    contact direction, where MUSEN divides by the zero distance)."""
    if not len(v) or not len(x):
        return 0
    lo, hi = v.min(axis=(0, 1)), v.max(axis=(0, 1))
    near = np.flatnonzero(((x >= lo - r[:, None]) & (x <= hi + r[:, None])).all(axis=1))
    count = 0
    step = max(1, 2_000_000 // len(v))            # bounded memory: (chunk, k) distances
    for s in range(0, len(near), step):
        rows = near[s:s + step]
        d2 = closest_points(x[rows], v).min(axis=1)
        count += int((d2 <= (1e-12 * r[rows]) ** 2).sum())
    return count


def wall_warnings(model: GranularModel, wall_plans: list[WallPlan], t_start: float,
                  t_end: float, spheres=None) -> list[tuple[str, str]]:
    """What the job's wall representation does not reproduce (stock walls standing in for
    MUSEN's), walls MUSEN does not simulate, MUSEN's kept wall velocity, and spheres behind
    the faces of exact triangles (``spheres``: a ``SimulatedSpheres``)."""
    out: list[tuple[str, str]] = []
    if model.kind != "musen":
        return out
    for wp in wall_plans:
        if wp.kind == "mesh" and spheres is not None and len(spheres.rows):
            behind = spheres_behind(model.triangles.vertices[wp.triangle_rows], spheres.x[spheres.rows],
                                    spheres.crad[spheres.rows])
            if behind:
                out.append(("spheres behind walls", f"geometry '{wp.name}': {behind} triangle(s) have a "
                            "sphere touching them from behind (the side their normal (V2-V1)x(V3-V1) "
                            "points away from): MUSEN's particle-wall law pushes spheres along the "
                            "normal, so it pushes these through the wall; check the orientation of "
                            "the triangles"))
        if wp.kind == "mesh" and spheres is not None and len(spheres.rows):
            on = spheres_on_triangles(model.triangles.vertices[wp.triangle_rows],
                                      spheres.x[spheres.rows], spheres.crad[spheres.rows])
            if on:
                out.append(("sphere centre on a wall", f"geometry '{wp.name}': {on} sphere(s) have "
                            "their centre on one of its triangles (closer than 1e-12 radii): "
                            "MUSEN's contact direction (centre minus contact point) is undefined "
                            "there and its results turn to nan; fibrelmp uses the triangle's "
                            "normal (docs/granular.md)"))
        if wp.kind in ("box", "cylinder", "tiles"):
            out.append(("approximate MUSEN physics", f"wall geometry '{wp.name}' represented as "
                        f"{wp.description}: LAMMPS's granular wall law stands in for MUSEN's "
                        "particle-wall contact (docs/granular.md, Walls)"))
        elif wp.kind == "mesh" and wp.stepped is None and wp.kinematics.moving:
            # steps_by_time refused it: its walls start with different stored velocities
            out.append(("approximate MUSEN physics", f"geometry '{wp.name}': its walls start with "
                        "different velocities, so it follows its exact motion x0 + v t; MUSEN's "
                        "walls are one step ahead of that (docs/musen.md, Walls one step ahead)"))
        elif wp.kind == "ignored":
            out.append(("walls in no geometry", f"{len(wp.triangle_rows)} triangular wall(s) belong "
                        "to no geometry: MUSEN's simulator does not use them, so they are not "
                        "simulated either"))
        kept = wp.kinematics.kept_velocity(t_start, t_end) if wp.kind != "ignored" else None
        if kept is not None:
            t, v, w = kept
            what = ("reproduced: the contact law sees the wall moving" if wp.kind == "mesh" else
                    "NOT reproduced by the stock representation (its walls stop)")
            out.append(("MUSEN kept wall velocity", f"geometry '{wp.name}' stops moving at t = "
                        f"{t:.6g} but MUSEN keeps its last wall velocity ({', '.join(f'{c:.6g}' for c in v)}) "
                        f"and rotation velocity ({', '.join(f'{c:.6g}' for c in w)}) in its contact law "
                        f"and result file; {what}"))
    return out


def wall_commands(model: GranularModel, wall_plans: list[WallPlan], spheres, dt: float):
    """(region/fix commands, variable commands, extra frame columns) of every wall: regions and
    planes get wall/gran fixes per sphere type, moving wall particles a fix move.  Each plan
    gets the tag w1, w2, ... in its order; ``spheres`` is a ``SimulatedSpheres``."""
    wall_cmds: list[str] = []
    var_cmds: list[str] = []
    frame_columns: list[str] = []
    mat_groups = spheres.material_groups()
    xs = spheres.x[spheres.rows]
    if any(wp.kind == "mesh" for wp in wall_plans):
        wall_cmds.append(LammpsText("# " + comment_text(f"the exact triangles of every wall geometry "
                                                         f"({MESH_NAME}), MUSEN's particle-wall contact")))
        wall_cmds.append(f"fix             {MESH_FIX} spheres musen/wall/mesh {MESH_NAME}"
                         f"{physics.mesh_law_args(model)}")
    for gi, wp in enumerate(wall_plans):
        tag = f"w{gi + 1}"
        if wp.kind == "mesh":
            wp.fixes.append(MESH_FIX)
        elif wp.kind in ("box", "cylinder"):
            _region_wall(model, wp, tag, mat_groups, xs, spheres.smat, spheres.m_min, dt, wall_cmds,
                         var_cmds, frame_columns)
        elif wp.kind == "plane":
            _plane_wall(model, model.planes[wp.plane_index], wp, tag, mat_groups, spheres.m_min, dt,
                        wall_cmds, frame_columns)
        elif wp.kind == "tiles" and wp.kinematics.moving:
            _tile_motion(wp, tag, var_cmds, wall_cmds)
    return wall_cmds, var_cmds, frame_columns


def _region_motion(wp: WallPlan, tag: str, var_cmds) -> str:
    """The move/rotate keywords of a region following its geometry (variables into
    ``var_cmds``), "" for a static axis-aligned one.  LAMMPS places a dynamic region at
    P + R_n(theta) (x_region - P) + d: with the geometry's motion x = R(t) x0 + b(t) and a
    region frame E (x0 = P + E (x_region - P)), R_n(theta) = R(t) E and d = R(t) P + b - P."""
    sh = wp.shape
    kin = wp.kinematics
    frame = isinstance(sh, BoxShape) and sh.frame is not None
    P = sh.pivot if frame else np.zeros(3)
    dyn = ""
    if kin.moving:
        for i, ax in enumerate("xyz"):
            def coeff(s, i=i):
                k = np.einsum("kij,j->ki", s.kr, P)[:, i] + s.kb[:, i]
                k[0] -= P[i]
                return k
            var_cmds.append(f"variable        {tag}_b{ax} equal \"{piecewise_expression(kin, coeff)}\"")
        dyn = f" move v_{tag}_bx v_{tag}_by v_{tag}_bz"
    if kin.rotating or frame:
        ax0, th0 = sh.rotation() if frame else (np.array([0.0, 0.0, 1.0]), 0.0)
        n = kin.single_axis if kin.rotating else ax0
        th0 = th0 * (1.0 if float(ax0 @ n) >= 0 else -1.0)
        expr = _angle_expression(kin, th0) if kin.rotating else float_text(th0)
        var_cmds.append(f"variable        {tag}_th equal \"{expr}\"")
        dyn += (f" rotate v_{tag}_th {float_text(P[0])} {float_text(P[1])} {float_text(P[2])} "
                f"{float_text(n[0])} {float_text(n[1])} {float_text(n[2])}")
    if dyn:
        dyn += " units box"
    return dyn


def _region_wall(model, wp: WallPlan, tag: str, mat_groups, xs, smat, m_min, dt, wall_cmds,
                 var_cmds, frame_columns) -> None:
    """Region (+ wall/gran/region fixes per sphere type; spheres on both sides of a closed
    region get one region each, side in and side out, found with a static probe region)."""
    sh = wp.shape
    frame = isinstance(sh, BoxShape) and sh.frame is not None
    P = sh.pivot if frame else np.zeros(3)
    dyn = _region_motion(wp, tag, var_cmds)
    if isinstance(sh, BoxShape):
        geo = "block " + " ".join(f"{float_text(sh.lo[a])} {float_text(sh.hi[a])}" for a in range(3))
        opened = " ".join(f"open {f}" for f in sh.open_faces)
        if sh.flat_axis is not None:
            inside = np.zeros(len(xs), bool)
        else:
            xl = sh.to_local(xs)
            inside = ((xl > sh.lo) & (xl < sh.hi)).all(1)
    else:
        ax = "xyz"[sh.axis]
        geo = (f"cylinder {ax} {float_text(sh.c1)} {float_text(sh.c2)} {float_text(sh.radius)} "
               f"{float_text(sh.lo)} {float_text(sh.hi)}")
        opened = " ".join(f"open {f}" for f in sh.open_faces)
        b, c = [k for k in range(3) if k != sh.axis]
        rho = np.hypot(xs[:, b] - sh.c1, xs[:, c] - sh.c2)
        inside = (rho < sh.radius) & (xs[:, sh.axis] > sh.lo) & (xs[:, sh.axis] < sh.hi)
    sides = []
    if inside.any():
        sides.append("in")
    if (~inside).any() or not len(xs):
        sides.append("out")
    fx, cx = [[] for _ in range(3)], [[] for _ in range(3)]
    for side in sides:
        rid = f"{tag}{side}"
        wall_cmds.append(f"region          {rid} {geo} side {side} {opened}{dyn}".rstrip())
        grp = "spheres"
        if len(sides) == 2:
            static = ""
            if frame:
                ax0, th0 = sh.rotation()
                wall_cmds.append(f"variable        {rid}_th0 equal {float_text(th0)}")
                static = (f" rotate v_{rid}_th0 {float_text(P[0])} {float_text(P[1])} {float_text(P[2])} "
                          f"{float_text(ax0[0])} {float_text(ax0[1])} {float_text(ax0[2])} units box")
            wall_cmds.append(f"region          {rid}_probe {geo} side {side} {opened}{static}".rstrip())
            wall_cmds.append(f"group           {rid} region {rid}_probe")
            grp = rid
        for t, m in mat_groups:
            if not ((smat == m) & (inside if side == "in" else ~inside)).any():
                continue
            law = check_law(model, m, wp.material)
            k, g = rolling_spring(m_min[m], dt)
            fid = f"{rid}_m{t}"
            g_use = f"m{t}" if grp == "spheres" else f"{rid}_m{t}"
            if grp != "spheres":
                wall_cmds.append(f"group           {rid}_m{t} intersect {rid} m{t}")
            wall_cmds.append(f"fix             {fid} {g_use} wall/gran/region granular "
                             f"{law_args(law, law.rolling_friction, k, g)} region {rid} contacts")
            wp.fixes.append(fid)
            for i in range(3):
                fx[i].append(f"f_{fid}[{2 + i}]")
                cx[i].append(f"f_{fid}[{5 + i}]")
        wp.region = rid
    if wp.fixes:
        for i, ax in enumerate("xyz"):
            wall_cmds.append(f"variable        {tag}_f{ax} atom \"{'+'.join(fx[i])}\"")
        for i, ax in enumerate("xyz"):
            wall_cmds.append(f"variable        {tag}_c{ax} atom \"{'+'.join(cx[i])}\"")
        wp.contact_vars = [f"v_{tag}_f{a}" for a in "xyz"] + [f"v_{tag}_c{a}" for a in "xyz"]
        frame_columns.extend(wp.contact_vars)


def _angle_expression(kin: Kinematics, th0: float = 0.0) -> str:
    """th0 + rotation angle theta(t) about kin.single_axis (all segments share the axis)."""
    n = kin.single_axis

    def coeff(s):
        ws = float(s.axis @ n) * s.w if s.w else 0.0
        return np.array([th0 + kin.angle(s.t0), ws, 0.0, 0.0])
    return piecewise_expression(kin, coeff)


def _plane_wall(model, pl, wp: WallPlan, tag: str, mat_groups, m_min, dt, wall_cmds, frame_columns) -> None:
    """wall/gran fixes per sphere type (wall/gran/region for a plane not along an axis), with
    ``contacts``: each sphere's force from the plane and contact point go to the frames
    (``v_<tag>_fx`` .. ``v_<tag>_cz``, as for region walls; post --to mercury's wall rows)."""
    n = np.asarray(pl.normal, float)
    n = n / np.linalg.norm(n)
    axis = int(np.argmax(np.abs(n)))
    aligned = abs(abs(n[axis]) - 1) < 1e-12
    if not aligned:
        p = pl.point
        wall_cmds.append(f"region          {tag} plane {float_text(p[0])} {float_text(p[1])} {float_text(p[2])} "
                         f"{float_text(n[0])} {float_text(n[1])} {float_text(n[2])} side in units box")
    for t, m in mat_groups:
        law = check_law(model, m, wp.material)
        k, g = rolling_spring(m_min[m], dt)
        fid = f"{tag}_m{t}"
        if aligned:
            pos = float_text(pl.point[axis])
            lohi = f"{pos} NULL" if n[axis] > 0 else f"NULL {pos}"
            where = f"{'xyz'[axis]}plane {lohi}"
            wall_cmds.append(f"fix             {fid} m{t} wall/gran granular "
                             f"{law_args(law, law.rolling_friction, k, g)} {where} contacts")
        else:
            wall_cmds.append(f"fix             {fid} m{t} wall/gran/region granular "
                             f"{law_args(law, law.rolling_friction, k, g)} region {tag} contacts")
        wp.fixes.append(fid)
    if wp.fixes:
        for name, first in (("f", 2), ("c", 5)):
            for i, ax in enumerate("xyz"):
                wall_cmds.append(f"variable        {tag}_{name}{ax} atom \""
                                 + "+".join(f"f_{fid}[{first + i}]" for fid in wp.fixes) + "\"")
        wp.contact_vars = [f"v_{tag}_f{a}" for a in "xyz"] + [f"v_{tag}_c{a}" for a in "xyz"]
        frame_columns.extend(wp.contact_vars)


def _tile_motion(wp: WallPlan, tag: str, var_cmds, wall_cmds) -> None:
    """fix move variable: x = R(t) x0 + b(t) for every tile (x0 kept in d_x0 d_y0 d_z0)."""
    if wp.tile_ids is None or not len(wp.tile_ids):
        return
    kin = wp.kinematics

    def var(name: str, pick, rate: bool = False) -> None:
        var_cmds.append(f"variable        {tag}_{name} equal \"{piecewise_expression(kin, pick, rate)}\"")

    for i, ax in enumerate("xyz"):
        var(f"b{ax}", lambda s, i=i: s.kb[:, i])
        var(f"vb{ax}", lambda s, i=i: s.kb[:, i], True)
    move = f"fix             {tag}_move {tag}_tiles move variable "
    if not kin.rotating:
        wall_cmds.append(move + " ".join(f"v_{tag}_b{a}" for a in "xyz") + " "
                         + " ".join(f"v_{tag}_vb{a}" for a in "xyz"))
        return
    for i in range(3):
        for j in range(3):
            var(f"R{i}{j}", lambda s, i=i, j=j: s.kr[:, i, j])
            var(f"dR{i}{j}", lambda s, i=i, j=j: s.kr[:, i, j], True)
    x0 = ["d_x0", "d_y0", "d_z0"]
    for i, ax in enumerate("xyz"):
        disp = "+".join(f"(v_{tag}_R{i}{j}{'-1' if i == j else ''})*{x0[j]}" for j in range(3))
        vel = "+".join(f"v_{tag}_dR{i}{j}*{x0[j]}" for j in range(3))
        var_cmds.append(f"variable        {tag}_dx{ax} atom \"{disp}+v_{tag}_b{ax}\"")
        var_cmds.append(f"variable        {tag}_vx{ax} atom \"{vel}+v_{tag}_vb{ax}\"")
    wall_cmds.append(move + " ".join(f"v_{tag}_dx{a}" for a in "xyz") + " "
                     + " ".join(f"v_{tag}_vx{a}" for a in "xyz"))
