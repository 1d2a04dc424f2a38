"""MUSEN text -> ``.mdem``, as MUSEN's ``IMPORT_FROM_TEXT`` (``ImportFromText.cpp``) makes it.

Objects keep their ids (``particles[id]``), types, compound keys and activity intervals (0..0
when a line has no ``24``, as MUSEN imports it); every time point of the file becomes a saved
time point, and each object's values at it are MUSEN's ``InterpolatedValue`` of the object's
own records (linear, extrapolated at the ends).  A record without a tag takes MUSEN's defaults
(zeros; orientation 0 1 0 0).  Scene lines fill the scene message: domain, periodic
boundaries, flags, geometries (25/26/27), analysis volumes (38), materials (32/33/34: every
compound with MUSEN's 16 default properties, then the values given; interactions added for
every compound pair as MUSEN's database adds them) and generators (39/40/41).
"""

from __future__ import annotations

import datetime
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.translate.musen.mdem import timepoints as tp
from fibrelmp.translate.musen.mdem.messages import new
from fibrelmp.translate.musen.mdem.objects import (LIQUID_BOND, SOLID_BOND, SPHERE, WALL,
                                                   encode_bond, encode_sphere)
from fibrelmp.translate.musen.mdem.text_export import PROPERTY_DEFAULTS

MOLAR_MASS, MOLAR_MASS_DEFAULT = 100, 0.018
COMPOUND_PROPERTIES = tuple(range(16))
INTERACTION_PROPERTIES = (200, 201, 202, 203, 204)
T_RANGE, P_RANGE = (0.0, 500.0), (0.0, 1e6)

# per type: the fields MUSEN's importer sets (SetAllTDdataIntoSystemStructure)
_SET = {SPHERE: tp.bit("coord", "vel", "angle_vel", "force", "quaternion", "stress_tensor",
                       "temperature"),
        SOLID_BOND: tp.bit("force", "angle_vel", "total_torque", "temperature"),
        LIQUID_BOND: tp.bit("force"),
        WALL: tp.bit("force", "vel", "coord", "quaternion", "angle_vel")}
# text tag -> (field, first value used, count); 44 = wall vertices (coord, quaternion, angle_vel)
_TAGS = {12: ("coord", 0, 3), 15: ("vel", 0, 3), 16: ("angle_vel", 0, 3), 20: ("force", 0, 3),
         31: ("quaternion", 0, 4), 36: ("stress_tensor", 0, 9), 37: ("temperature", 0, 1),
         43: ("total_torque", 0, 1), 45: ("angle_vel", 0, 3)}


def import_text(path: str | Path) -> tuple[Any, Iterator[tuple[float, np.ndarray, np.ndarray]]]:
    """(scene message, time points) of a MUSEN text file."""
    from fibrelmp.translate.musen.text import check_duplicate_ids, scan_text, time_points_of

    path = Path(path)
    scan = scan_text(path)
    ids = np.array(scan.ids, np.int64)
    check_duplicate_ids(scan, ids, path)
    storage = new("ProtoSimulationStorage")
    info = storage.info
    info.version = 1
    _objects(info, scan, ids)
    _scene(storage, scan, path)
    points = time_points_of(scan)
    return storage, _time_points(points, int(ids.max()) + 1 if len(ids) else 0)


def _objects(info: Any, scan, ids: np.ndarray) -> None:
    n = int(ids.max()) + 1 if len(ids) else 0
    if n > 2 ** 31 - 1 or n > 16 * len(ids) + (1 << 20):
        # MUSEN's objects are particles[id]: ids far beyond the object count mean an array
        # of mostly empty entries (MUSEN itself stores ids as int32)
        raise InputError(scan.path, scan.lines[int(np.argmax(ids))], f"object id {n - 1} is far "
                         f"beyond the {len(ids)} objects of the file (.mdem files index objects "
                         "by id); renumber the objects")
    for _ in range(n):
        info.particles.add()
    for r, oid in enumerate(ids.tolist()):
        p = info.particles[oid]
        p.id = oid
        kind = scan.types[r]
        p.type = kind
        geom = scan.geoms[r]
        if kind == SPHERE:
            p.encoded_properties = encode_sphere(geom[0], geom[1])
        elif kind in (SOLID_BOND, LIQUID_BOND):
            p.encoded_properties = encode_bond(int(geom[0]), int(geom[1]), geom[2], geom[3])
        if scan.keys[r] is not None:
            p.compound = scan.keys[r]
        if scan.acts[r] is not None:
            p.activity_start, p.activity_end = scan.acts[r]


def _interp(times: np.ndarray, y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """MUSEN's InterpolatedValue for every time in ``t`` (linear; the end intervals
    extended; one record: constant; none: zeros)."""
    if len(times) == 0:
        return np.zeros((len(t),) + y.shape[1:])
    if len(times) == 1:
        return np.broadcast_to(y[0], (len(t),) + y.shape[1:]).copy()
    ir = np.clip(np.searchsorted(times, t, side="right"), 1, len(times) - 1)
    il = ir - 1
    same = times[ir] == times[il]
    dt = np.where(same, 1.0, times[ir] - times[il])
    out = y[il] + (t - times[il])[:, None] * (y[ir] - y[il]) / dt[:, None]
    out[same] = y[ir][same]
    return out


def _time_points(points, n: int) -> Iterator[tuple[float, np.ndarray, np.ndarray]]:
    times, present = points.times, points.present
    m = len(points.ids)
    # values of each object at each of its own records (defaults where a tag is missing)
    own = np.zeros((len(times), m, tp.NCOLS))
    own[:, :, tp.FIELDS["quaternion"][1] + 1] = 1.0              # CQuaternion(0, 1, 0, 0)
    for tag, (field, _, k) in _TAGS.items():
        values = points.fields.get(tag)
        if values is None:
            continue
        first = tp.FIELDS[field][1]
        have = ~np.isnan(values[:, :, 0])
        own[:, :, first:first + k][have] = values[have]
    walls = points.fields.get(44)
    if walls is not None:
        have = ~np.isnan(walls[:, :, 0])
        q = tp.FIELDS["quaternion"][1]
        own[:, :, 0:3][have] = walls[have][:, 0:3]
        own[:, :, q:q + 3][have] = walls[have][:, 3:6]
        own[:, :, q + 3][have] = 0.0
        own[:, :, 9:12][have] = walls[have][:, 6:9]
    # objects lacking some time of the file: interpolated from their own records
    for j in np.flatnonzero(~present.all(axis=0)):
        mine = present[:, j]
        own[:, j] = _interp(times[mine], own[mine, j], times)
    masks = np.zeros(n, np.uint32)
    rows = points.ids
    for kind, mask in _SET.items():
        masks[rows[points.types == kind]] = mask
    for k, time in enumerate(times.tolist()):
        values = np.zeros((n, tp.NCOLS))
        values[rows] = own[k]
        for kind, mask in _SET.items():             # only the fields MUSEN sets
            sel = rows[points.types == kind]
            values[sel] *= _column_mask(mask)
        yield time, values, masks


def _column_mask(mask: int) -> np.ndarray:
    out = np.zeros(tp.NCOLS)
    for name, (number, first, k) in tp.FIELDS.items():
        if mask >> number & 1:
            out[first:first + k] = 1.0
    return out


# ------------------------------------------------------------------------ scene
def set_vector(msg: Any, values) -> None:
    """A ``ProtoVector`` set (present even if all zero, as after MUSEN's ``mutable_...``)."""
    msg.SetInParent()
    msg.x, msg.y, msg.z = (float(v) for v in values)


def _floats(tok: list[str], path: Path, ln: int, what: str) -> list[float]:
    try:
        return [float(t) for t in tok]
    except ValueError:
        raise InputError(path, ln, f"`{what}`: expected numbers, got {' '.join(tok)!r}") from None


def _scene(storage: Any, scan, path: Path) -> None:
    info, mods = storage.info, storage.modules_data
    set_vector(info.simulation_volume_min, (-5e-3,) * 3)            # ClearAllData's domain
    set_vector(info.simulation_volume_max, (5e-3,) * 3)
    set_vector(info.periodic_conditions_min, (-5e-3,) * 3)
    set_vector(info.periodic_conditions_max, (5e-3,) * 3)
    set_vector(info.periodic_conditions_vel, (0.0,) * 3)
    db = mods.materials_database
    db.SetInParent()
    mods.bonds_generator.SetInParent()              # the generators' SaveConfiguration after import
    mods.package_generator.simulator_type = 1       # CPU, MUSEN's default
    mods.package_generator.verlet_coeff = 2.0
    geometry = None
    for ln, tag, tok in scan.scene:
        try:
            geometry = _scene_line(info, mods, db, geometry, ln, tag, tok, path)
        except (IndexError, ValueError, OverflowError, TypeError) as exc:
            raise InputError(path, ln, f"`{tag}` line cannot be imported: "
                             f"{'too few values' if isinstance(exc, IndexError) else exc}") from None


def _scene_line(info, mods, db, geometry, ln: int, tag: int, tok: list[str], path: Path):
    """One scene line into the scene message; the geometry lines 26/27 belong to."""
    if tag == 22:
        v = _floats(tok, path, ln, "22")
        set_vector(info.simulation_volume_min, v[:3])
        set_vector(info.simulation_volume_max, v[3:6])
    elif tag == 28:
        v = _floats(tok, path, ln, "28")
        info.periodic_conditions_enabled, info.periodic_conditions_x, \
            info.periodic_conditions_y, info.periodic_conditions_z = (bool(x) for x in v[:4])
        set_vector(info.periodic_conditions_min, v[4:7])
        set_vector(info.periodic_conditions_max, v[7:10])
    elif tag == 29:
        info.anisotripy = bool(float(tok[0]))
    elif tag == 30:
        info.contact_radius = bool(float(tok[0]))
    elif tag == 25:
        geometry = _geometry(info.real_geometry.add(), tok, path, ln)
    elif tag == 26:
        if geometry is None:
            raise InputError(path, ln, "`26` (geometry motion) before any `25` geometry")
        _motion(geometry.base_geometry.motion, tok, path, ln)
    elif tag == 27:
        if geometry is None:
            raise InputError(path, ln, "`27` (geometry walls) before any `25` geometry")
        geometry.planes.extend(int(float(t)) for t in tok[1:])
    elif tag == 38:
        _volume(info.analysis_volume.add(), tok, path, ln)
    elif tag == 32:
        _compound(db, tok, path, ln)
    elif tag == 33:
        _interaction(db, tok, path, ln)
    elif tag == 34:
        _mixture(db, tok, path, ln)
    elif tag == 39:
        _package(mods.package_generator.generators.add(), tok, path, ln)
    elif tag == 40:
        v = _floats(tok[:2], path, ln, "40")
        mods.package_generator.simulator_type = int(v[0])
        mods.package_generator.verlet_coeff = v[1]
    elif tag == 41:
        _bonds_generator(mods.bonds_generator.generators.add(), tok, path, ln)
    return geometry


def _base(base: Any, name: str, key: str) -> None:
    base.name = name
    base.key = key
    base.shape = 5                                  # STL
    base.color.SetInParent()
    base.color.r, base.color.g, base.color.b, base.color.a = 0.5, 0.5, 1.0, 1.0
    base.rotation.SetInParent()
    set_vector(base.rotation.v1, (1, 0, 0))
    set_vector(base.rotation.v2, (0, 1, 0))
    set_vector(base.rotation.v3, (0, 0, 1))
    base.motion.SetInParent()
    base.scaling = 1.0


def _geometry(geo: Any, tok: list[str], path: Path, ln: int) -> Any:
    _base(geo.base_geometry, tok[0], tok[1])
    v = _floats(tok[2:], path, ln, "25")
    geo.mass = v[0]
    set_vector(geo.free_motion, [1.0 if x else 0.0 for x in v[1:4]])
    geo.rotate_around_center = bool(v[4]) if len(v) > 4 else False
    return geo


def _motion(motion: Any, tok: list[str], path: Path, ln: int) -> None:
    """A geometry motion from text: type, count, then per interval two limits and velocity,
    rotation centre, rotation velocity (``operator<<(CGeometryMotion)``)."""
    v = _floats(tok, path, ln, "26")
    kind, count = int(v[0]), int(v[1]) if len(v) > 1 else 0
    intervals = []
    for i in range(count if kind else 0):
        a, b, *rest = v[2 + 11 * i: 13 + 11 * i]
        intervals.append((a, b, rest[0:3], rest[3:6], rest[6:9]))
    set_motion(motion, kind, intervals)


def set_motion(motion: Any, kind: int, intervals: list[tuple]) -> None:
    """``ProtoGeometryMotion`` of a type and its intervals (limit1, limit2 or limit type,
    velocity, rotation centre, rotation velocity), as ``CGeometryMotion::SaveToProto``."""
    motion.SetInParent()
    motion.type = kind
    for a, b, vel, centre, rot in intervals:
        iv = motion.intervals.add()
        set_vector(iv.velocity, vel)
        set_vector(iv.rot_center, centre)
        set_vector(iv.rot_velocity, rot)
        iv.limit1 = a
        if kind == 1:
            iv.limit2 = b
        else:
            iv.limit_type = int(b)


def relevant_sizes(shape: int, sizes: list[float]) -> list[float]:
    """``CGeometrySizes::RelevantSizes``: of width, depth, height, radius, inner radius,
    those a shape stores."""
    w, d, h, r, ri = sizes
    return {0: [r], 1: [w, d, h], 2: [r, h], 3: [r, ri]}.get(shape, [])


def _volume(vol: Any, tok: list[str], path: Path, ln: int) -> None:
    base = vol.base_geometry
    _base(base, tok[0], tok[1])
    # shape, colour (4), sizes (5), scaling, rotation (9): 20 numbers (operator<< of
    # CAnalysisVolume), then the motion
    v = _floats(tok[2:22], path, ln, "38")
    base.shape = int(v[0])
    base.color.r, base.color.g, base.color.b, base.color.a = v[1:5]
    del base.sizes[:]
    base.sizes.extend(relevant_sizes(base.shape, v[5:10]))
    base.scaling = v[10]
    for row, msg in zip(range(3), (base.rotation.v1, base.rotation.v2, base.rotation.v3)):
        set_vector(msg, v[11 + 3 * row: 14 + 3 * row])
    rest = tok[22:]
    kind = int(float(rest[0]))
    count = int(float(rest[1])) if kind else 0
    _motion(base.motion, rest[:2 + 11 * count], path, ln)
    mesh = rest[2 + 11 * count if kind else 2:]
    ntri = int(float(mesh[1]))
    values = _floats(mesh[2:2 + 9 * ntri], path, ln, "38")
    for i in range(ntri):
        t = vol.triangles.add()
        set_vector(t.vert1, values[9 * i:9 * i + 3])
        set_vector(t.vert2, values[9 * i + 3:9 * i + 6])
        set_vector(t.vert3, values[9 * i + 6:9 * i + 9])


def set_constant(prop: Any, pid: int, value: float) -> None:
    """``SetPropertyValue``: one constant correlation over MUSEN's default T and p range."""
    prop.propertyType = pid
    del prop.correlation[:]
    cor = prop.correlation.add()
    cor.t1, cor.t2 = T_RANGE
    cor.p1, cor.p2 = P_RANGE
    cor.corType = 0
    cor.parameter.append(value)


def _pairs(tok: list[str], path: Path, ln: int, what: str) -> dict[int, float]:
    v = _floats(tok, path, ln, what)
    if len(v) % 2:
        raise InputError(path, ln, f"`{what}`: property ids and values must come in pairs")
    return {int(v[i]): v[i + 1] for i in range(0, len(v), 2)}


def _compound(db: Any, tok: list[str], path: Path, ln: int) -> None:
    c = db.compound.add()
    c.uniqueKey, c.compoundName = tok[0], tok[1]
    c.authorName = "Unspecified"
    today = datetime.date.today()                   # MUSEN stamps a new compound's creation date
    c.creationDate.year, c.creationDate.month, c.creationDate.day = today.year, today.month, today.day
    c.color.SetInParent()
    c.color.b, c.color.a = 1.0, 1.0
    c.phase = 2                                      # solid
    const = c.constProperty.add()
    const.propertyType, const.value = MOLAR_MASS, MOLAR_MASS_DEFAULT
    given = _pairs(tok[2:], path, ln, "32")
    for pid in COMPOUND_PROPERTIES:
        set_constant(c.property.add(), pid, given.get(pid, PROPERTY_DEFAULTS[pid]))
    for other in db.compound:                        # ConformInteractionsAdd
        i = db.interaction.add()
        i.compoundKey1, i.compoundKey2 = c.uniqueKey, other.uniqueKey
        for pid in INTERACTION_PROPERTIES:
            set_constant(i.property.add(), pid, PROPERTY_DEFAULTS[pid])


def _interaction(db: Any, tok: list[str], path: Path, ln: int) -> None:
    a, b = tok[0], tok[1]
    for i in db.interaction:
        if {i.compoundKey1, i.compoundKey2} == {a, b}:
            for pid, value in _pairs(tok[2:], path, ln, "33").items():
                for prop in i.property:
                    if prop.propertyType == pid:
                        set_constant(prop, pid, value)
            return
    raise InputError(path, ln, f"`33`: no compounds {a} and {b} (their `32` lines come first)")


def _mixture(db: Any, tok: list[str], path: Path, ln: int) -> None:
    m = db.mixture.add()
    m.uniqueKey, m.mixtureName = tok[0], tok[1]
    rest = tok[2:]
    for i in range(0, len(rest) - 4, 5):
        f = m.fraction.add()
        f.fractionName = f"Fraction {int(float(rest[i]))}"
        f.compoundKey = rest[i + 1]
        f.diameter, f.contact_diameter, f.fraction = _floats(rest[i + 2:i + 5], path, ln, "34")


def _package(gen: Any, tok: list[str], path: Path, ln: int) -> None:
    gen.volume_name = tok[0]
    gen.volume_active = bool(float(tok[1]))
    gen.volume_key, gen.mixture_key = tok[2], tok[3]
    v = _floats(tok[4:11], path, ln, "39")
    gen.porosity, gen.max_overlap, gen.max_iterations = v[0], v[1], int(v[2])
    set_vector(gen.init_velocity, v[3:6])
    gen.inside_geometry = bool(v[6])


def _bonds_generator(gen: Any, tok: list[str], path: Path, ln: int) -> None:
    gen.name = tok[0]
    gen.activity = bool(float(tok[1]))
    gen.material_key = tok[2]
    v = _floats(tok[3:8], path, ln, "41")
    gen.min_length, gen.max_length, gen.property1 = v[0:3]
    gen.allow_overlap, gen.compound_specific = bool(v[3]), bool(v[4])
    lists = " ".join(tok[8:]).split("/")
    if len(lists) >= 3:
        gen.partner_compounds1.extend(lists[1].split())
        gen.partner_compounds2.extend(lists[2].split())
