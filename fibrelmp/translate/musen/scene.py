"""Read MUSEN text scenes and results into the neutral GranularModel.

Semantics follow MUSEN's code (github.com/msolids/musen e0ff360: ``ImportFromText.cpp``,
``ExportAsText.cpp``, ``DefinesMDB.h``), not its PDF, where the two disagree.  docs/musen.md
lists every deviation.  One object per line: ``0 ID 1 TYPE 5 GEOM [23 KEY] [24 T0 T1]`` then
any number of time points ``2 T <tag values>...``; the LAST time point is the start state.
Tokenising lives in ``text.py`` (``scan_text``); this module turns the tokens into the model.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.units import SI
from fibrelmp.granmodel import (ContactLaw, ForceInterval, Geometry, GranularModel, GranularPlan, LiquidBond,
                         Material, MotionInterval, SolidBonds, Spheres, Triangles, hertz_effective)
from fibrelmp.translate.musen.scene_record import MusenSceneRecord
from fibrelmp.translate.musen.text import (LIQUID_BOND, SOLID_BOND, SPHERE, TD_SIZE, TYPE_NAMES, WALL,  # noqa: F401
                         TimePoints, _bool, check_duplicate_ids, _fill, _int, _num, scan_text, TextScan,
                         _state, read_time_points)

DEFAULT_ACTIVITY_END = 1e300            # MUSENDefinitions.h; read as inf, written back as 1e+300
DEFAULT_DOMAIN = (-5e-3, 5e-3)          # CSystemStructure::ClearAllData
# DefinesMDB.h: TP properties 0..15 and the constant property 100 (molar mass)
PROPERTY_DEFAULTS = {0: 1000.0, 1: 1000.0, 2: 0.1, 3: 0.5, 4: 0.0, 5: 1000.0, 6: 2260000.0,
                     7: 1e9, 8: 1e7, 9: 1e7, 10: 0.2, 11: 1.0, 12: 2e-5, 13: 0.7, 14: 1.7e-5,
                     15: 20e9, 100: 0.018}
ACTIVE_PROPERTIES = (0, 1, 2, 3, 7, 8, 9, 10, 11, 12, 13, 14, 15)   # what the exporter writes
INTERACTION_DEFAULTS = {200: 0.6, 201: 0.45, 202: 0.05, 203: 45.0, 204: 2e-9}
ACTIVE_INTERACTIONS = (200, 201, 202)
NOT_USED_TAGS = {38: "analysis volume", 39: "package generator", 41: "bonds generator"}


# --------------------------------------------------------------------------- model

def read(path: str | Path) -> GranularModel:
    """Read a MUSEN text scene (or text result: its last time point is the start state)."""
    path = Path(path)
    scan = scan_text(path)
    model_warn: list[tuple[str, str]] = []
    ids = np.array(scan.ids, np.int64)
    types = np.array(scan.types, np.int64)
    check_duplicate_ids(scan, ids, path)
    all_times = [scan.vals[r][lay.time_idx] for r, lay in enumerate(scan.layouts) if lay]
    t_start = float(max(float(t.max()) for t in all_times)) if all_times else 0.0

    materials, key_index = _materials(scan, path, model_warn)
    rows = {t: np.flatnonzero(types == t) for t in (SPHERE, SOLID_BOND, LIQUID_BOND, WALL)}
    late: list[str] = []
    spheres = _spheres(scan, rows[SPHERE], key_index, materials, t_start, late, path, model_warn)
    bonds = _bonds(scan, rows[SOLID_BOND], ids, types, rows[SPHERE], key_index, t_start,
                   late, path)
    triangles = _walls(scan, rows[WALL], key_index, t_start, late, path)
    if late:
        model_warn.append(("musen-time-mismatch", f"{len(late)} object(s) (first ids "
                           f"{', '.join(late[:5])}) have no time point at t = {t_start:g}, "
                           "the last one in the file: their start state is inter/extrapolated "
                           "linearly as MUSEN's importer does"))
    no_act = sum(1 for r in range(len(ids)) if scan.acts[r] is None)
    if no_act:
        model_warn.append(("musen-no-activity", f"{no_act} object(s) have no activity interval "
                           "`24`: fibrelmp makes them active from 0 for ever, while MUSEN imports "
                           "them as never active (interval 0..0)"))

    liquid_bonds = _liquid_bonds(scan, rows[LIQUID_BOND], ids, types, path)
    record = MusenSceneRecord()
    if liquid_bonds:
        model_warn.append(("musen-liquid-bonds", f"{len(liquid_bonds)} liquid "
                           "bond(s) (type 13): they exert no force and never break, as in cmusen 1.74.2 "
                           "(MUSEN e0ff360's ModelLBCapilarViscous is a no-op); the results "
                           "hold their activity as cmusen writes it (translate/musen/liquid_bonds.py), "
                           "except that a sphere leaving the domain ends its liquid bonds at "
                           "the next save's time, where cmusen writes its removal step's"))
    plan = GranularPlan(dt=float("nan"), t_start=t_start, t_end=float("nan"))
    geometries = _scene(scan, plan, record, triangles, ids, types, rows[WALL], path,
                        model_warn)
    contacts = _contacts(scan, materials, key_index, path, model_warn, record)
    model = GranularModel(source=path, kind="musen", materials=materials, contacts=contacts,
                          spheres=spheres, plan=plan, bonds=bonds, triangles=triangles,
                          geometries=geometries, origin=record, liquid_bonds=liquid_bonds,
                          units=SI.name)
    model.warnings.extend(model_warn)
    domain_warning(model)
    return model


def _materials(scan: TextScan, path: Path, warn: list) -> tuple[list[Material], dict[str, int]]:
    materials: list[Material] = []
    key_index: dict[str, int] = {}
    for ln, tag, tok in scan.scene:
        if tag != 32:
            continue
        if len(tok) < 2:
            raise InputError(path, ln, "`32` needs a material key and a name")
        key, name = tok[0], tok[1]
        rest = tok[2:]
        if len(rest) % 2:
            raise InputError(path, ln, f"material {key}: property {rest[-1]!r} has no value (or the "
                             "name contains a space, which the text format cannot hold)")
        props = dict(PROPERTY_DEFAULTS)
        for j in range(0, len(rest), 2):
            pid = _int(rest, j, path, ln, f"material {key}: property id")
            value = _num(rest, j + 1, path, ln, f"material {key}: property {pid}")
            if pid not in PROPERTY_DEFAULTS:
                warn.append(("musen-unknown-property", f"{path}:{ln}: material {key}: property "
                             f"id {pid} is not a MUSEN property; ignored as MUSEN does"))
                continue
            props[pid] = value
        if key in key_index:
            warn.append(("musen-duplicate-material", f"{path}:{ln}: material key {key} is "
                         "defined twice; MUSEN gives the second one a new random key, so "
                         "objects and interactions keep using the first; the second is dropped"))
            continue
        _check_material(key, name, props, path, ln)
        key_index[key] = len(materials)
        materials.append(Material(key=key, name=name, density=props[0], youngs=props[7],
                                  poisson=props[10], normal_strength=props[8],
                                  shear_strength=props[9], props=props))
    return materials, key_index


def _check_material(key: str, name: str, props: dict, path: Path | None, ln: int | None) -> None:
    """CMaterialsDatabase::IsDataCorrect: MUSEN refuses to simulate with these values."""
    for bad, text in ((props[0] < 0, "negative density"),
                      (props[3] == 0, "zero thermal conductivity (MUSEN refuses it)"),
                      (props[7] <= 0, "Young's modulus must be positive"),
                      (not 0.0 <= props[10] <= 0.5, "Poisson ratio outside [0, 0.5]"),
                      (props[13] < 0, "negative surface tension")):
        if bad:
            raise InputError(path, ln, f"material {key} ({name}): {text}")


def _keys(scan: TextScan, rows: np.ndarray, key_index: dict[str, int], path: Path,
          what: str) -> np.ndarray:
    out = np.empty(len(rows), np.int64)
    for j, r in enumerate(rows):
        key = scan.keys[r]
        if key not in key_index:
            why = "has no `23` material key" if key is None else f"uses material {key!r}"
            raise InputError(path, scan.lines[r], f"{what} {scan.ids[r]} {why}, which no `32` "
                             f"line defines (known: {', '.join(key_index) or 'none'}); MUSEN "
                             "refuses to simulate: 'Materials not for all objects are defined'")
        out[j] = key_index[key]
    return out


def _activity(scan: TextScan, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    act = np.array([scan.acts[r] or (0.0, math.inf) for r in rows], np.float64).reshape(-1, 2)
    end = act[:, 1].copy()
    end[end >= DEFAULT_ACTIVITY_END] = np.inf
    return act[:, 0].copy(), end


def _require_time_point(scan: TextScan, rows: np.ndarray, what: str, path: Path) -> None:
    for r in rows:
        if scan.layouts[r] is None:
            raise InputError(path, scan.lines[r], f"{what} {scan.ids[r]} has no time point "
                             "`2 T ...`: its position is undefined")


def _spheres(scan, rows, key_index, materials, t, late, path, warn) -> Spheres:
    _require_time_point(scan, rows, "sphere", path)
    mat = _keys(scan, rows, key_index, path, "sphere")
    geom = np.array([scan.geoms[r] for r in rows], np.float64).reshape(-1, 2)
    radius, contact = geom[:, 0].copy(), geom[:, 1].copy()
    if (radius <= 0).any():
        r = rows[int(np.flatnonzero(radius <= 0)[0])]
        raise InputError(path, scan.lines[r], f"sphere {scan.ids[r]}: radius must be positive")
    contact[contact == 0] = radius[contact == 0]     # Sphere.cpp: contact radius 0 -> radius
    density = np.array([m.density for m in materials])[mat] if len(mat) else np.zeros(0)
    st = _state(scan, rows, (12, 15, 16, 31, 37), t, late)
    no_xyz = np.isnan(st[12]).any(axis=1)
    if no_xyz.any():
        r = rows[int(np.flatnonzero(no_xyz)[0])]
        warn.append(("musen-missing-field", f"{path}:{scan.lines[r]}: {int(no_xyz.sum())} "
                     f"sphere(s) (first id {scan.ids[r]}) have no coordinates `12` at t = {t:g}: "
                     "MUSEN puts them at the origin"))
    start, end = _activity(scan, rows)
    return Spheres(ids=np.array([scan.ids[r] for r in rows], np.int64), material=mat,
                   radius=radius, contact_radius=contact,
                   mass=density * 4.0 / 3.0 * np.pi * radius ** 3,
                   position=_fill(st[12], 0.0), velocity=_fill(st[15], 0.0),
                   omega=_fill(st[16], 0.0), quaternion=_fill(st[31], (0.0, 1.0, 0.0, 0.0)),
                   active_start=start, active_end=end,
                   compound_key=[scan.keys[r] for r in rows],
                   temperature=_fill(st[37], 0.0)[:, 0])


def _bond_ends(scan, rows, ids, types, sphere_rows, path, what):
    ends = np.array([scan.geoms[r][:2] for r in rows], np.float64).reshape(-1, 2)
    bad = (ends != np.round(ends)) | (ends < 0) | (ends >= 2 ** 53)
    if bad.any():
        j = int(np.flatnonzero(bad.any(axis=1))[0])
        raise InputError(path, scan.lines[rows[j]], f"{what} {scan.ids[rows[j]]}: particle ids "
                         "must be non-negative integers")
    ends = ends.astype(np.int64)
    sphere_ids = ids[sphere_rows]
    order = np.argsort(sphere_ids)
    k = np.minimum(np.searchsorted(sphere_ids[order], ends), max(len(order) - 1, 0))
    found = (sphere_ids[order][k] == ends) if len(order) else np.zeros(ends.shape, bool)
    if not found.all():
        j, side = (int(x) for x in np.argwhere(~found)[0])
        other = np.flatnonzero(ids == ends[j, side])
        kind = f"a {TYPE_NAMES[int(types[other[0]])]}" if len(other) else "no object in this file"
        raise InputError(path, scan.lines[rows[j]], f"{what} {scan.ids[rows[j]]} connects particle "
                         f"{ends[j, side]}, which is {kind}; bonds join two spheres")
    pair = order[k]                       # index into the spheres (built in sphere_rows order)
    same = np.flatnonzero(pair[:, 0] == pair[:, 1])
    if len(same):
        r = rows[same[0]]
        raise InputError(path, scan.lines[r], f"{what} {scan.ids[r]} joins sphere "
                         f"{ends[same[0], 0]} to itself")
    return pair


def _bonds(scan, rows, ids, types, sphere_rows, key_index, t, late, path) -> SolidBonds | None:
    if not len(rows):
        return None
    pair = _bond_ends(scan, rows, ids, types, sphere_rows, path, "solid bond")
    mat = _keys(scan, rows, key_index, path, "solid bond")
    geom = np.array([scan.geoms[r] for r in rows], np.float64)
    for col, name in ((2, "diameter"), (3, "initial length")):
        bad = np.flatnonzero(geom[:, col] <= 0)
        if len(bad):
            r = rows[bad[0]]
            raise InputError(path, scan.lines[r], f"solid bond {scan.ids[r]}: {name} must be "
                             "positive")
    start, end = _activity(scan, rows)
    st = _state(scan, rows, (20, 45, 16), t, late)
    overlap = np.where(np.isnan(st[45]), st[16], st[45])    # old files: `16` = overlap
    force, overlap = _fill(st[20], 0.0), _fill(overlap, 0.0)
    return SolidBonds(ids=np.array([scan.ids[r] for r in rows], np.int64), pair=pair,
                      material=mat, diameter=geom[:, 2].copy(), length0=geom[:, 3].copy(),
                      active_start=start, active_end=end,
                      compound_key=[scan.keys[r] for r in rows],
                      force=force if force.any() else None,
                      tangential_overlap=overlap if overlap.any() else None,
                      source_line=np.array([scan.lines[r] for r in rows], np.int64))


def _walls(scan, rows, key_index, t, late, path) -> Triangles | None:
    if not len(rows):
        return None
    _require_time_point(scan, rows, "triangular wall", path)
    mat = _keys(scan, rows, key_index, path, "triangular wall")
    st = _state(scan, rows, (44, 12, 31, 16, 15), t, late)
    new = ~np.isnan(st[44]).any(axis=1)
    old = ~(np.isnan(st[12]).any(axis=1) | np.isnan(st[31][:, :3]).any(axis=1)
            | np.isnan(st[16]).any(axis=1))
    if not (new | old).all():
        r = rows[int(np.flatnonzero(~(new | old))[0])]
        raise InputError(path, scan.lines[r], f"triangular wall {scan.ids[r]}: its last time point "
                         "has no vertices: give `44 V1 V2 V3` (or the old `12 V1 16 V3 31 V2 0`)")
    vert = np.empty((len(rows), 3, 3))
    vert[new] = st[44][new].reshape(-1, 3, 3)
    only_old = old & ~new
    # old encoding (TriangularWall.h): V1 in coordinates, V2 in quaternion q0..q2, V3 in omega
    vert[only_old, 0] = st[12][only_old]
    vert[only_old, 1] = st[31][only_old, :3]
    vert[only_old, 2] = st[16][only_old]
    area = np.linalg.norm(np.cross(vert[:, 1] - vert[:, 0], vert[:, 2] - vert[:, 0]), axis=1)
    if (area == 0).any():
        r = rows[int(np.flatnonzero(area == 0)[0])]
        raise InputError(path, scan.lines[r], f"triangular wall {scan.ids[r]}: its three vertices "
                         "are on one line (zero area)")
    start, end = _activity(scan, rows)
    return Triangles(ids=np.array([scan.ids[r] for r in rows], np.int64), material=mat,
                     vertices=vert, velocity=_fill(st[15], 0.0), active_start=start,
                     active_end=end, compound_key=[scan.keys[r] for r in rows])


def _liquid_bonds(scan, rows, ids, types, path) -> list[LiquidBond]:
    if not len(rows):
        return []
    sphere_rows = np.flatnonzero(types == SPHERE)
    _bond_ends(scan, rows, ids, types, sphere_rows, path, "liquid bond")
    start, end = _activity(scan, rows)
    out = []
    for j, r in enumerate(rows):
        g = scan.geoms[r]
        out.append(LiquidBond(id=int(scan.ids[r]), left=int(g[0]), right=int(g[1]),
                              diameter=g[2], length0=g[3], key=scan.keys[r],
                              active_start=float(start[j]), active_end=float(end[j])))
    return out


def _scene(scan, plan, record, triangles, ids, types, wall_rows, path, warn) -> list[Geometry]:
    raw = record.raw
    geometries: list[Geometry] = []
    domain = None
    pbc = None
    for ln, tag, tok in scan.scene:
        if tag == 22:
            v = [_num(tok, j, path, ln, f"domain (`22`) value {j + 1}") for j in range(6)]
            if not all(math.isfinite(x) for x in v) or any(v[j] >= v[j + 3] for j in range(3)):
                raise InputError(path, ln, "domain (`22`): need xmin ymin zmin xmax ymax zmax "
                                 "with each min < max")
            domain = (np.array(v[:3]), np.array(v[3:]))
        elif tag == 28:
            flags = [_bool(tok, j, path, ln, f"periodic boundaries (`28`) flag {j + 1}")
                     for j in range(4)]
            box = [_num(tok, 4 + j, path, ln, f"periodic boundaries (`28`) value {j + 5}")
                   for j in range(6)]
            pbc = (flags, box)
        elif tag in (29, 30):
            flag = _bool(tok, 0, path, ln, f"flag `{tag}`")
            if tag == 29:
                record.anisotropy = flag
            else:
                record.contact_radius_flag = flag
            if tag == 29 and flag:
                warn.append(("musen-anisotropy", f"{path}:{ln}: anisotropy (`29 1`) is on; "
                             "fibrelmp's spheres are isotropic, orientations are only carried"))
        elif tag == 25:
            geometries.append(_geometry(tok, path, ln))
        elif tag in (26, 27):
            if not geometries:
                raise InputError(path, ln, f"`{tag}` before any geometry line `25` (it belongs to "
                                 "the last `25` above it)")
            g = geometries[-1]
            g.raw_lines.append(" ".join([str(tag)] + tok))
            if tag == 26:
                _motion(g, tok, path, ln, warn)
            else:
                g.triangle_rows = _wall_list(tok, ids, types, wall_rows, path, ln)
        elif tag in (34, 38, 39, 40, 41):
            raw.setdefault(tag, []).append(tok)
            if tag in NOT_USED_TAGS:
                warn.append(("musen-not-used", f"{path}:{ln}: {NOT_USED_TAGS[tag]} (`{tag}`) "
                             "parsed, not used (kept for the result file)"))
    if domain is None:
        domain = (np.full(3, DEFAULT_DOMAIN[0]), np.full(3, DEFAULT_DOMAIN[1]))
        warn.append(("musen-default-domain", f"{path}: no simulation domain (`22`): MUSEN's "
                     "default, a 1 cm cube centred on the origin, is used"))
    plan.domain = domain
    flags, box = pbc if pbc else ([False] * 4, [-5e-3] * 3 + [5e-3] * 3)
    record.pbc = (flags, box)
    plan.periodic = tuple(flags[0] and f for f in flags[1:])
    plan.periodic_box = (np.array(box[:3]), np.array(box[3:]))
    return geometries


def _geometry(tok, path, ln) -> Geometry:
    if len(tok) < 6:
        raise InputError(path, ln, "`25` needs NAME KEY MASS freeX freeY freeZ [ROTATE_AROUND_CENTRE]")
    mass = _num(tok, 2, path, ln, "geometry mass")
    free = tuple(_bool(tok, 3 + j, path, ln, f"geometry free-motion flag {j + 1}") for j in range(3))
    rot = _bool(tok, 6, path, ln, "rotate-around-centre flag") if len(tok) > 6 else None
    return Geometry(name=tok[0], key=tok[1], mass=mass, free=free, rotate_around_centre=rot,
                    motion_type=0, motion=[], triangle_rows=np.zeros(0, np.int64),
                    raw_lines=[" ".join(["25"] + tok)])


def _motion(g: Geometry, tok, path, ln, warn) -> None:
    mtype = _int(tok, 0, path, ln, "geometry motion type (`26`)")
    if mtype not in (0, 1, 2, 3):
        raise InputError(path, ln, f"geometry motion type {mtype}: MUSEN knows 0 none, 1 time, "
                         "2 force, 3 constant force")
    g.motion_type = mtype
    if mtype == 0:
        return
    n = _int(tok, 1, path, ln, "number of motion intervals")
    v = [_num(tok, 2 + j, path, ln, f"motion interval value {j + 1}") for j in range(11 * n)]
    if mtype == 1:
        for j in range(n):
            a = v[11 * j: 11 * j + 11]      # tBeg tEnd | velocity | centre | angular velocity
            g.motion.append(MotionInterval(a[0], a[1], np.array(a[2:5]), np.array(a[5:8]),
                                           np.array(a[8:11])))
    else:
        for j in range(n):
            a = v[11 * j: 11 * j + 11]      # Flimit limitType(0 MIN, 1 MAX) | velocity | centre | angular velocity
            if a[1] not in (0.0, 1.0):
                raise InputError(path, ln, f"force motion interval {j + 1}: limit type {a[1]:g}: "
                                 "MUSEN knows 0 (MIN) and 1 (MAX)")
            g.force_motion.append(ForceInterval(a[0], a[1] == 1.0, np.array(a[2:5]), np.array(a[5:8]),
                                                np.array(a[8:11])))


def _wall_list(tok, ids, types, wall_rows, path, ln) -> np.ndarray:
    n = _int(tok, 0, path, ln, "`27` number of walls")
    wall_ids = [_int(tok, 1 + j, path, ln, f"`27` wall id {j + 1}") for j in range(n)]
    index = {int(ids[r]): j for j, r in enumerate(wall_rows)}
    out = []
    for w in wall_ids:
        if w not in index:
            found = np.flatnonzero(ids == w)
            kind = f"a {TYPE_NAMES[int(types[found[0]])]}" if len(found) else "not in this file"
            raise InputError(path, ln, f"geometry wall list (`27`): object {w} is {kind}, "
                             "not a triangular wall")
        out.append(index[w])
    return np.array(out, np.int64)


def _contacts(scan, materials, key_index, path, warn, record) -> dict:
    given: dict[tuple[int, int], dict[int, float]] = {}
    for ln, tag, tok in scan.scene:
        if tag != 33:
            continue
        if len(tok) < 2:
            raise InputError(path, ln, "`33` needs two material keys")
        rest = tok[2:]
        if len(rest) % 2:
            raise InputError(path, ln, f"interaction property {rest[-1]!r} has no value")
        if tok[0] not in key_index or tok[1] not in key_index:
            bad = tok[0] if tok[0] not in key_index else tok[1]
            warn.append(("musen-unknown-interaction", f"{path}:{ln}: interaction names material "
                         f"{bad!r}, which no `32` line above defines; ignored as MUSEN does"))
            continue
        a, b = sorted((key_index[tok[0]], key_index[tok[1]]))
        props = given.setdefault((a, b), {})
        for j in range(0, len(rest), 2):
            pid = _int(rest, j, path, ln, "interaction property id")
            value = _num(rest, j + 1, path, ln, f"interaction property {pid}")
            if pid not in INTERACTION_DEFAULTS:
                warn.append(("musen-unknown-property", f"{path}:{ln}: interaction property id "
                             f"{pid} is not a MUSEN property; ignored as MUSEN does"))
                continue
            props[pid] = value
    record.interactions = {}
    contacts = {}
    defaulted = []
    for b in range(len(materials)):
        for a in range(b + 1):
            props = dict(INTERACTION_DEFAULTS)
            if (a, b) in given:
                props.update(given[(a, b)])
            else:
                defaulted.append(f"{materials[b].name}-{materials[a].name}")
            record.interactions[(a, b)] = props
            contacts[(a, b)] = contact_law(materials[a], materials[b], props)
    if defaulted:
        warn.append(("musen-default-interaction", f"{path}: no `33` line for {', '.join(defaulted)}: "
                     "MUSEN's defaults restitution 0.6, sliding 0.45, rolling friction 0.05"))
    return contacts


def contact_law(m1: Material, m2: Material, props: dict[int, float]) -> ContactLaw:
    e_star, g_star = hertz_effective(m1, m2)
    return ContactLaw(youngs_eff=e_star, shear_eff=g_star, restitution=props[200],
                      friction=props[201], rolling_friction=props[202])


def domain_warning(model: GranularModel) -> None:
    lo, hi = model.plan.domain
    sp = model.spheres
    active = (sp.active_start <= model.plan.t_start) & (sp.active_end > model.plan.t_start)
    outside = active & ((sp.position < lo) | (sp.position > hi)).any(axis=1)
    if outside.any():
        model.warn("musen-outside-domain", f"{int(outside.sum())} of {int(active.sum())} active "
                   f"spheres lie outside the simulation domain {lo.tolist()}..{hi.tolist()}: "
                   "MUSEN removes them (and their bonds) at the first step; set the domain with "
                   "SIMULATION_DOMAIN in a cmusen script")


def check_simulable(model: GranularModel) -> None:
    """Raise if the model holds what fibrelmp cannot simulate.  Liquid bonds are simulated
    as cmusen 1.74.2 does: they exert no force (the scene reader warns)."""




# --------------------------------------------------------------------------- fibrelmp check
def _first_material_key(path: str | Path) -> str | None:
    from fibrelmp.textio import read_text

    try:
        text = read_text(path, "MUSEN text file")
    except InputError:
        return None
    for raw in text.splitlines():
        tok = raw.split()
        if len(tok) >= 3 and tok[0] == "32":
            return tok[1]
    return None


def check_patch(err: InputError, line: str | None, attempt: int) -> str | None:
    """What ``textio.collect_errors`` puts in place of a failing scene line while ``fibrelmp
    check`` looks for further errors.  Bonds and wall lists name objects by id and objects
    name materials by key, so a failing sphere or wall line becomes a plain object with the
    same id and a failing material line a material with MUSEN's defaults under the same key
    (removing them would make every line that refers to them fail too); other lines are
    blanked."""
    if line is None:
        return None
    tok = line.split()
    candidates: list[str] = []
    if len(tok) > 1 and tok[0] == "0" and tok[1].isdigit() and int(tok[1]) < 2 ** 53:
        key = _first_material_key(err.path) if err.path else None
        otype = tok[3] if len(tok) > 3 else "1"
        if key is not None and otype == str(WALL):
            candidates.append(f"0 {tok[1]} 1 14 5 23 {key} 24 0 1e+300 2 0 44 0 0 0 1 0 0 0 1 0")
        elif key is not None and otype not in (str(SOLID_BOND), str(LIQUID_BOND)):
            # at a position its id makes unique (two stand-ins at one point would be a bond's
            # "same position" error that the file does not have)
            candidates.append(f"0 {tok[1]} 1 1 5 1 1 23 {key} 24 0 1e+300 2 0 12 {tok[1]}e-100 0 0")
    elif len(tok) >= 3 and tok[0] == "32":
        candidates.append(f"32 {tok[1]} {tok[2]}")
    candidates.append("")
    return candidates[attempt] if attempt < len(candidates) else None
