"""A ``.mdem`` file as MUSEN text: what MUSEN's ``EXPORT_TO_TEXT`` (``ExportAsText.cpp``, all
selectors on) writes, byte for byte.

One line per object, ascending id, holding every saved time point; then the scene lines 22,
28, 29, 30, per geometry 25/26/27, analysis volumes 38, materials 32/33/34, generators
39/40/41.  Time-point values get ``precision`` significant digits (C++ ostream ``%g``), every
other number 6; sphere radii 16 digits and bond diameters/lengths 25, as MUSEN formats them.

The lines are formatted by ``translate/musen/text_writer.py`` (shared with the result writer
from frames); this module supplies the values from the ``.mdem`` file.

Memory stays bounded: time points are read one at a time and their per-type values appended
to a spool file (saves x objects x columns, as MUSEN's own exporter does with its temporary
binary file); lines are then formatted for chunks of objects at a time.
"""

from __future__ import annotations

import math
import tempfile
from array import array
from pathlib import Path
from typing import IO, Any

import numpy as np

from fibrelmp.granular_run.stress import principal_stresses
from fibrelmp.translate.musen.mdem import timepoints as tp
from fibrelmp.translate.musen.mdem.document import MdemFile
from fibrelmp.translate.musen.mdem.objects import (LIQUID_BOND, SOLID_BOND, SPHERE, WALL, Objects,
                                                   read_objects)
from fibrelmp.translate.musen.text_writer import (bulk_format, export_selectors, gather_spool, long_lines,
                                                  object_headers, scene_line, time_point_lines,
                                                  write_long_line)
from fibrelmp.translate.musen.text_writer import number_text as g

# material property ids MUSEN exports (DefinesMDB.h _MUSEN_ACTIVE_PROPERTIES/_INTERACTIONS)
# and the defaults a compound/interaction is created with
ACTIVE_PROPERTIES = (0, 1, 2, 3, 7, 8, 9, 10, 11, 12, 13, 14, 15)
ACTIVE_INTERACTIONS = (200, 201, 202)
PROPERTY_DEFAULTS = {0: 1000.0, 1: 1000.0, 2: 0.1, 3: 0.5, 4: 0.0, 5: 1000.0, 6: 2.26e6, 7: 1e9,
                     8: 1e7, 9: 1e7, 10: 0.2, 11: 1.0, 12: 2e-5, 13: 0.7, 14: 1.7e-5, 15: 20e9,
                     200: 0.6, 201: 0.45, 202: 0.05, 203: 45.0, 204: 2e-9}
NORMAL_T, NORMAL_P = 273.15, 101325.0          # where CTPProperty::GetValue() evaluates
_CHUNK_VALUES = 1_000_000

# exported values per type (the exporter's order) -> spool columns
_SPHERE_COLS = 30     # 16 angvel 3, 12 coord 3, 20 force 3, 18 |F|, 31 quat 4, 42 principal 3,
#                       36 stress 9, 37 temperature, 15 velocity 3
_BOND_COLS = 15       # 12 midpoint 3, 20 force 3, 18 |F|, 45 overlap 3, 37 T, 43 torque, 15 v 3
_WALL_COLS = 16       # 44 vertices 9, 20 force 3, 18 |F|, 15 velocity 3
# per type: (selector group, ((flag, tag, count), ...)) in the exporter's order
_TEMPLATES = {
    SPHERE: ("tdPropsPart", (("angVel", 16, 3), ("coord", 12, 3), ("force", 20, 3),
                             ("forceAmpl", 18, 1), ("orient", 31, 4), ("princStress", 42, 3),
                             ("stressTensor", 36, 9), ("temperature", 37, 1), ("velocity", 15, 3))),
    SOLID_BOND: ("tdPropsBond", (("coord", 12, 3), ("force", 20, 3), ("forceAmpl", 18, 1),
                                 ("tangOverlap", 45, 3), ("temperature", 37, 1),
                                 ("totTorque", 43, 1), ("velocity", 15, 3))),
    WALL: ("tdPropsWall", (("coord", 44, 9), ("force", 20, 3), ("forceAmpl", 18, 1),
                           ("velocity", 15, 3))),
    LIQUID_BOND: ("", ()),
}
_WIDTH = {SPHERE: _SPHERE_COLS, SOLID_BOND: _BOND_COLS, WALL: _WALL_COLS, LIQUID_BOND: 0}




def _length(v: np.ndarray) -> np.ndarray:
    """CVector3::Length: sqrt(x*x + y*y + z*z), in that order."""
    return np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])


def _rows(values: np.ndarray, n: int) -> np.ndarray:
    """The time point's values padded with empty (zero) objects to ``n`` rows."""
    if len(values) >= n:
        return values[:n]
    out = np.zeros((n, tp.NCOLS))
    out[:len(values)] = values
    return out


def td_blocks(obj: Objects, values: np.ndarray, index: dict[int, np.ndarray]) -> dict[int, np.ndarray]:
    """Per type, the exported values of one time point (rows in ``index[type]`` order)."""
    n = int(obj.ids.max()) + 1 if obj.count else 0
    v = _rows(values, n)
    col = tp.columns
    out = {}
    rows = index.get(SPHERE)
    if rows is not None and len(rows):
        ids = obj.ids[rows]
        s = v[ids]
        b = np.empty((len(ids), _SPHERE_COLS))
        b[:, 0:3] = s[:, col("angle_vel")]
        b[:, 3:6] = s[:, col("coord")]
        b[:, 6:9] = s[:, col("force")]
        b[:, 9] = _length(s[:, col("force")])
        b[:, 10:14] = s[:, col("quaternion")]
        b[:, 14:17] = principal_stresses(s[:, col("stress_tensor")])
        b[:, 17:26] = s[:, col("stress_tensor")]
        b[:, 26] = s[:, tp.FIELDS["temperature"][1]]
        b[:, 27:30] = s[:, col("vel")]
        out[SPHERE] = b
    rows = index.get(SOLID_BOND)
    if rows is not None and len(rows):
        ids = obj.ids[rows]
        bd = v[ids]
        left, right = obj.left[rows], obj.right[rows]
        ok = (left < n) & (right < n)
        lc = np.where(ok[:, None], v[np.minimum(left, n - 1)], 0.0)
        rc = np.where(ok[:, None], v[np.minimum(right, n - 1)], 0.0)
        b = np.empty((len(ids), _BOND_COLS))
        b[:, 0:3] = (lc[:, col("coord")] + rc[:, col("coord")]) / 2.0
        b[:, 3:6] = bd[:, col("force")]
        b[:, 6] = _length(bd[:, col("force")])
        b[:, 7:10] = bd[:, col("angle_vel")]
        b[:, 10] = bd[:, tp.FIELDS["temperature"][1]]
        b[:, 11] = bd[:, tp.FIELDS["total_torque"][1]]
        b[:, 12:15] = (lc[:, col("vel")] + rc[:, col("vel")]) / 2.0
        out[SOLID_BOND] = b
    rows = index.get(WALL)
    if rows is not None and len(rows):
        w = v[obj.ids[rows]]
        b = np.empty((len(rows), _WALL_COLS))
        b[:, 0:3] = w[:, col("coord")]
        b[:, 3:6] = w[:, tp.FIELDS["quaternion"][1]:tp.FIELDS["quaternion"][1] + 3]
        b[:, 6:9] = w[:, col("angle_vel")]
        b[:, 9:12] = w[:, col("force")]
        b[:, 12] = _length(w[:, col("force")])
        b[:, 13:16] = w[:, col("vel")]
        out[WALL] = b
    return out


def geometry_text(obj: Objects, rows: np.ndarray, compounds: set[str]) -> list[str]:
    """GetObjectGeometryText of each object in ``rows``."""
    out = []
    for r in rows.tolist():
        kind = int(obj.types[r])
        if kind == SPHERE:
            rc = obj.contact_radius[r]
            if rc == 0 and obj.compound[r] in compounds:      # UpdatePrecalculatedValues
                rc = obj.radius[r]
            out.append("%.16g %.16g" % (obj.radius[r], rc))
        elif kind in (SOLID_BOND, LIQUID_BOND):
            out.append("%d %d %.25g %.25g" % (obj.left[r], obj.right[r], obj.diameter[r],
                                              obj.length0[r]))
        else:
            out.append("")
    return out


def export(mdem: MdemFile, out: IO[str], precision: int = 6,
           time_interval: tuple[float, float] | None = None, spool_dir: Path | None = None,
           times_limit: int | None = None,
           selectors: dict[str, dict[str, bool]] | None = None) -> list[float]:
    """Write ``mdem`` as MUSEN text to ``out``; returns the exported times.
    ``time_interval`` (cmusen's TIME_INTERVAL) and ``times_limit`` (the first k time points)
    restrict the time points; ``selectors`` (cmusen's TEXT_EXPORT_* groups and flags, all on
    by default) what is written, as ``CExportAsText`` filters."""
    sel = export_selectors(selectors)
    obj = read_objects(mdem.info, mdem.version, mdem.path)
    compounds = {c.uniqueKey for c in mdem.scene.modules_data.materials_database.compound}
    saved = np.array(mdem.info.savedTimePoints, float)
    if saved.size == 0:
        saved = mdem.times()
    if time_interval is not None:
        saved = saved[(time_interval[0] <= saved) & (saved <= time_interval[1])]
    chosen = np.asarray(saved[:times_limit], float)
    keep = _filter(obj, sel, chosen)
    index = {t: np.flatnonzero((obj.types == t) & keep) for t in (SPHERE, SOLID_BOND, WALL, LIQUID_BOND)}
    with tempfile.TemporaryDirectory(prefix=".mdem-export.", dir=spool_dir) as tmp:
        spools = {t: open(Path(tmp) / f"{t}.bin", "w+b") for t in _WIDTH if _WIDTH[t]}
        # the chosen times, distinct and sorted, and which were written: arrays, as a
        # million saves would take ~100 MB of Python floats in sets (NaN is never found)
        wanted = np.unique(chosen)
        done = np.zeros(len(wanted), bool)
        times = array("d")
        try:
            def chosen_time(time: float) -> bool:
                at = int(np.searchsorted(wanted, time))
                return at < len(wanted) and wanted[at] == time and not done[at]

            # points outside TIME_INTERVAL are skipped undecoded
            for time, values, _ in mdem.time_points(wanted=chosen_time):
                at = int(np.searchsorted(wanted, time))
                for t, block in td_blocks(obj, values, index).items():
                    spools[t].write(np.ascontiguousarray(block).tobytes())
                times.append(time)
                done[at] = True
                if len(times) == len(wanted):
                    break
            for fh in spools.values():
                fh.flush()
            _write_objects(out, obj, index, keep, spools, times, precision, compounds, sel)
        finally:
            for fh in spools.values():
                fh.close()
    out.write("".join(scene_lines(mdem.scene, sel)))
    return times.tolist()


def _filter(obj: Objects, sel: dict, times: np.ndarray) -> np.ndarray:
    """CExportAsText::FilterObjects (type and activity; only when a selector is off)."""
    if all(all(group.values()) for group in sel.values()):
        return np.ones(obj.count, bool)
    kinds = sel["objectTypes"]
    keep = (((obj.types == SPHERE) & kinds["particles"]) | ((obj.types == SOLID_BOND) & kinds["bonds"])
            | ((obj.types == WALL) & kinds["walls"]))
    if len(times) and any(any(sel[g].values()) for g in ("tdPropsPart", "tdPropsBond", "tdPropsWall")):
        keep &= ~((times[-1] < obj.start) | (times[0] > obj.end))
    return keep


def _write_objects(out, obj: Objects, index, keep, spools, times, precision: int, compounds,
                   sel) -> None:
    nt = len(times)
    kinds = obj.types
    width_all = max(1, nt * 31)
    chunk = max(16, min(4096, _CHUNK_VALUES // width_all))
    # position of each object within its type's spool rows
    where = np.full(obj.count, -1, np.int64)
    for t, rows in index.items():
        where[rows] = np.arange(len(rows))
    kept = np.flatnonzero(keep)
    piece = long_lines(nt, 31, _CHUNK_VALUES)
    if piece is not None:                   # many saves: one line at a time, in pieces
        for r in kept.tolist():
            t = int(kinds[r])
            group, fields = _TEMPLATES[t]

            def piece_of(cols: list[int], steps: slice, t: int = t, r: int = r) -> np.ndarray:
                return gather_spool(spools[t], len(index[t]), _WIDTH[t], nt, where[[r]], steps)[0][:, cols]

            write_long_line(out, _headers(obj, np.array([r]), t, compounds, sel["constProps"])[0],
                            fields, sel.get(group, {}), times, int(precision), piece, piece_of)
        return
    for lo in range(0, len(kept), chunk):
        sl = kept[lo:lo + chunk]
        lines = np.empty(len(sl), dtype=object)
        for t in (SPHERE, SOLID_BOND, WALL, LIQUID_BOND):
            sel_rows = sl[kinds[sl] == t]
            if not len(sel_rows):
                continue
            group, fields = _TEMPLATES[t]

            def values_of(cols: list[int], t: int = t, sel_rows: np.ndarray = sel_rows) -> np.ndarray:
                return gather_spool(spools[t], len(index[t]), _WIDTH[t], nt, where[sel_rows])[:, :, cols]

            lines[np.searchsorted(sl, sel_rows)] = time_point_lines(
                _headers(obj, sel_rows, t, compounds, sel["constProps"]), fields, sel.get(group, {}),
                times, int(precision), values_of)
        out.write("".join(lines.tolist()))


def _headers(obj: Objects, rows: np.ndarray, kind: int, compounds, const: dict) -> list[str]:
    return object_headers(const, obj.ids[rows].tolist(), kind, geometry_text(obj, rows, compounds),
                          [obj.compound[r] or "Undefined" for r in rows.tolist()],
                          bulk_format("%g", obj.start[rows]), bulk_format("%g", obj.end[rows]))


# ------------------------------------------------------------------------- scene lines
def _vec(v: Any) -> str:
    return f"{g(v.x)} {g(v.y)} {g(v.z)}"


def scene_lines(storage: Any, sel: dict[str, dict[str, bool]] | None = None) -> list[str]:
    """Lines 22, 28, 29, 30, 25/26/27, 38, 32/33/34, 39/40/41 of ``storage`` (those the
    selectors ask for; all by default)."""
    sel = sel or export_selectors()
    info, mods = storage.info, storage.modules_data
    sc, ge, ma, gn = sel["sceneInfo"], sel["geometries"], sel["materials"], sel["generators"]
    lines = []
    if sc["domain"]:
        lines.append(scene_line(22, _vec(info.simulation_volume_min), _vec(info.simulation_volume_max)))
    if sc["pbc"]:
        lines.append(scene_line(28, int(info.periodic_conditions_enabled), int(info.periodic_conditions_x),
                           int(info.periodic_conditions_y), int(info.periodic_conditions_z),
                           _vec(info.periodic_conditions_min) + " " + _vec(info.periodic_conditions_max)))
    if sc["anisotropy"]:
        lines.append(scene_line(29, int(info.anisotripy)))
    if sc["contactRadius"]:
        lines.append(scene_line(30, int(info.contact_radius)))
    for geo in geometries(info):
        if ge["baseInfo"]:
            lines.append(scene_line(25, geo["name"], geo["key"], g(geo["mass"]), *geo["free"],
                               int(geo["rotate"])))
        if ge["tdProperties"]:
            lines.append(scene_line(26, motion_text(geo["motion_type"], geo["intervals"])))
        if ge["wallsList"]:
            lines.append(scene_line(27, len(geo["planes"]), " ".join(str(i) for i in geo["planes"])))
    if ge["analysisVolumes"]:
        for vol in volumes(info):
            lines.append(scene_line(38, volume_text(vol)))
    lines += material_lines(mods.materials_database, ma)
    pg = mods.package_generator
    for gen in pg.generators if gn["packageGenerator"] else ():
        lines.append(scene_line(39, f"{_single(gen.volume_name)} {int(gen.volume_active)} {gen.volume_key} "
                           f"{gen.mixture_key} {g(gen.porosity)} {g(gen.max_overlap)} "
                           f"{gen.max_iterations} {_vec(gen.init_velocity)} {int(gen.inside_geometry)}"))
    if gn["packageGenerator"]:
        lines.append(scene_line(40, f"{pg.simulator_type} {g(pg.verlet_coeff or 2.0)}"))
    for gen in mods.bonds_generator.generators if gn["bondsGenerator"] else ():
        first = "".join(f"{k} " for k in gen.partner_compounds1)
        second = "".join(f"{k} " for k in gen.partner_compounds2)
        lines.append(scene_line(41, f"{_single(gen.name)} {int(gen.activity)} {gen.material_key} "
                           f"{g(gen.min_length)} {g(gen.max_length)} {g(gen.property1)} "
                           f"{int(gen.allow_overlap)} {int(gen.compound_specific)} / {first}/ "
                           f"{second}/ "))
    return lines


def _single(text: str) -> str:
    """MakeSingleString: trimmed, whitespace to '_', never empty."""
    text = "".join("_" if ch.isspace() else ch for ch in text.strip())
    return text or "_"


def motion_text(kind: int, intervals: list[tuple]) -> str:
    """operator<<(CGeometryMotion): type, count, intervals (velocity, centre, rotation)."""
    if kind == 0:
        return "0 0 "
    parts = [f"{kind} {len(intervals)} "]
    for a, b, vel, centre, rot in intervals:
        values = [a, b] if kind == 1 else [a]
        head = " ".join(g(x) for x in values) if kind == 1 else f"{g(a)} {int(b)}"
        parts.append(f"{head} {' '.join(g(x) for x in (*vel, *centre, *rot))} ")
    return "".join(parts)


def _xyz(v: Any) -> tuple[float, float, float]:
    return (v.x, v.y, v.z)


def geometries(info: Any) -> list[dict]:
    """Real geometries as MUSEN loads them (``version`` 0: the v0 list, converted)."""
    out = []
    if info.version == 0:
        for geo in info.real_geometry_v0:
            intervals: list[tuple] = []
            kind = 0
            if len(geo.tdVal):
                kind = 2 if geo.forceDependentVel else 1
                prev = 0.0
                for k, td in enumerate(geo.tdVal):
                    motion = (_xyz(td.velocity), _xyz(td.rotCenter), _xyz(td.rotVelocity))
                    if kind == 1:
                        intervals.append((prev, td.time, *motion))
                        prev = td.time
                    else:
                        intervals.append((td.time, 1 if k % 2 == 0 else 0, *motion))
                if kind == 1 and len(intervals) == 1 and intervals[0][1] == 0:
                    intervals[0] = (intervals[0][0], 99.0, *intervals[0][2:])
            out.append({"name": geo.name.replace(" ", "_"), "key": geo.key, "mass": geo.mass,
                        "free": [int(bool(x)) for x in _xyz(geo.vFreeMotion)],
                        "rotate": geo.rotate_AroundMassCenter, "motion_type": kind,
                        "intervals": intervals, "planes": list(geo.planes)})
        return out
    for geo in info.real_geometry:
        base = geo.base_geometry
        kind = base.motion.type
        intervals = []
        for iv in base.motion.intervals:
            motion = (_xyz(iv.velocity), _xyz(iv.rot_center), _xyz(iv.rot_velocity))
            intervals.append((iv.limit1, iv.limit2 if kind == 1 else iv.limit_type, *motion))
        out.append({"name": base.name.replace(" ", "_"), "key": base.key, "mass": geo.mass,
                    "free": [int(bool(x)) for x in _xyz(geo.free_motion)],
                    "rotate": geo.rotate_around_center, "motion_type": kind,
                    "intervals": intervals, "planes": list(geo.planes)})
    return out


_DEFAULT_VOLUME_COLOUR = (0.6, 1.0, 0.6, 1.0)


def volumes(info: Any) -> list[dict]:
    """Analysis volumes as MUSEN loads them (name, key, shape, colour, 5 sizes, scaling,
    rotation, motion, triangles)."""
    out = []
    if info.version == 0:
        for vol in info.analysis_volume_v0:
            sizes = _sizes(vol.type, list(vol.vProps))
            rot = (_matrix(vol.rotation) if vol.HasField("rotation") else
                   (1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0))
            intervals, prev = [], 0.0
            for td in vol.tdVal:
                intervals.append((prev, td.time, _xyz(td.velocity), (0.0,) * 3, (0.0,) * 3))
                prev = td.time
            out.append({"name": vol.name, "key": vol.key, "shape": vol.type,
                        "colour": _colour(vol.color) if vol.HasField("color") else _DEFAULT_VOLUME_COLOUR,
                        "sizes": sizes, "scaling": 1.0, "rotation": rot,
                        "motion_type": 1 if intervals else 0, "intervals": intervals,
                        "triangles": [_triangle(t) for t in vol.triangles]})
        return out
    for vol in info.analysis_volume:
        base = vol.base_geometry
        intervals = []
        for iv in base.motion.intervals:
            motion = (_xyz(iv.velocity), _xyz(iv.rot_center), _xyz(iv.rot_velocity))
            intervals.append((iv.limit1, iv.limit2 if base.motion.type == 1 else iv.limit_type, *motion))
        out.append({"name": base.name, "key": base.key, "shape": base.shape,
                    "colour": _colour(base.color) if base.HasField("color") else _DEFAULT_VOLUME_COLOUR,
                    "sizes": _sizes(base.shape, list(base.sizes)), "scaling": base.scaling or 1.0,
                    "rotation": _matrix(base.rotation) if base.HasField("rotation")
                    else (1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0),
                    "motion_type": base.motion.type, "intervals": intervals,
                    "triangles": [_triangle(t) for t in vol.triangles]})
    return out


def _sizes(shape: int, relevant: list[float]) -> list[float]:
    """width depth height radius innerRadius from a shape's relevant sizes."""
    w = d = h = r = ri = 0.0
    if shape == 0 and len(relevant) >= 1:
        r = relevant[0]
    elif shape == 1 and len(relevant) >= 3:
        w, d, h = relevant[:3]
    elif shape == 2 and len(relevant) >= 2:
        r, h = relevant[:2]
    elif shape == 3 and len(relevant) >= 2:
        r, ri = relevant[:2]
    return [w, d, h, r, ri]


def _colour(c: Any) -> tuple[float, ...]:
    return (c.r, c.g, c.b, c.a)


def _matrix(m: Any) -> tuple[float, ...]:
    return (*_xyz(m.v1), *_xyz(m.v2), *_xyz(m.v3))


def _triangle(t: Any) -> tuple[float, ...]:
    return (*_xyz(t.vert1), *_xyz(t.vert2), *_xyz(t.vert3))


def volume_text(vol: dict) -> str:
    """operator<<(CAnalysisVolume)."""
    mesh = "".join(" ".join(g(x) for x in tri) + " " for tri in vol["triangles"])
    return (f"{_single(vol['name'])} {vol['key']} {vol['shape']} "
            f"{' '.join(g(x) for x in vol['colour'])} "
            + "".join(f"{g(x)} " for x in vol["sizes"]) + " "
            + f"{g(vol['scaling'])} {' '.join(g(x) for x in vol['rotation'])} "
            + motion_text(vol["motion_type"], vol["intervals"]) + " "
            + f"_ {len(vol['triangles'])} " + mesh)


def property_value(props: Any, pid: int, const: Any = ()) -> float:
    """CCompound::GetPropertyValue: the TP property's correlation at normal conditions, a
    constant property's value, else the default the compound was created with."""
    for prop in props:
        if prop.propertyType != pid:
            continue
        for cor in prop.correlation:
            if cor.t1 <= NORMAL_T <= cor.t2 and cor.p1 <= NORMAL_P <= cor.p2:
                return _correlation(cor.corType, list(cor.parameter))
        return math.nan
    for prop in const:
        if prop.propertyType == pid:
            return prop.value
    return PROPERTY_DEFAULTS.get(pid, math.nan)


def _correlation(kind: int, k: list[float]) -> float:
    k = k + [0.0] * (3 - len(k))
    t, p = NORMAL_T, NORMAL_P
    if kind == 0:
        return k[0]
    if kind == 1:
        return k[2] * t + k[1] * p + k[0]
    if kind == 2:
        return math.exp(k[0] + k[1] / (t + k[2]))
    if kind == 3:
        return k[0] * math.pow(t, k[1])
    return math.nan


def material_lines(db: Any, sel: dict[str, bool] | None = None) -> list[str]:
    sel = sel or {"compounds": True, "interactions": True, "mixtures": True}
    lines = []
    for c in db.compound if sel["compounds"] else ():
        values = "".join(f"{p} {g(property_value(c.property, p, c.constProperty))} "
                         for p in ACTIVE_PROPERTIES)
        lines.append(f"32 {c.uniqueKey} {c.compoundName} {values}\n")
    for i in db.interaction if sel["interactions"] else ():
        values = "".join(f"{p} {g(property_value(i.property, p))} " for p in ACTIVE_INTERACTIONS)
        lines.append(f"33 {i.compoundKey1} {i.compoundKey2} {values}\n")
    for m in db.mixture if sel["mixtures"] else ():
        parts = "".join(f"{k} {f.compoundKey} {g(f.diameter)} {g(f.contact_diameter or f.diameter)} "
                        f"{g(f.fraction)} " for k, f in enumerate(m.fraction))
        lines.append(f"34 {m.uniqueKey} {m.mixtureName} {parts}\n")
    return lines
