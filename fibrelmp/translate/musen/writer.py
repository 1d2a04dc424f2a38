"""Write GranularFrames as a MUSEN text result (what cmusen's EXPORT_TO_TEXT writes).

Layout (``ExportAsText.cpp``): one line per object in ascending id with ALL saved time points
on it, then the scene lines 22/28/29/30, geometries 25/26/27, 38, materials 32/33/34 and
generators 39/40/41.  Time-point values get ``precision`` significant digits like a C++
ostream (``%g``); activity intervals and scene lines always get 6, sphere radii 16 and bond
diameters/lengths 25, as in MUSEN.  The lines are formatted by ``text_writer`` (shared with
the ``.mdem`` text export); this module supplies the values from the frames and the model.

Memory stays bounded: ``add`` appends each frame's per-type value block to one raw float64
file per object type in a temporary folder beside the output (laid out saves x objects x
columns); ``close`` reads back chunks of objects for all saves and formats them (one C-level
``%`` per chunk and object type), a chunk holding about a million numbers whatever the number
of saves, writes a temp file and renames it (formatbase.Writer).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from fibrelmp.formatbase import Writer
from fibrelmp.granmodel import GranularFrame, GranularModel
from fibrelmp.granular_run.stress import principal_stresses
from fibrelmp.textio import temp_name, write_failure
from fibrelmp.translate.musen.scene import (ACTIVE_INTERACTIONS, ACTIVE_PROPERTIES, DEFAULT_ACTIVITY_END,
                               PROPERTY_DEFAULTS)
from fibrelmp.translate.musen.liquid_bonds import LiquidBondActivity
from fibrelmp.translate.musen.scene_record import scene_record
from fibrelmp.translate.musen.text_writer import (bulk_format, export_selectors, gather_spool, long_lines,
                                                  object_headers, scene_line, time_point_lines,
                                                  write_long_line)

# per type: (flag, tag, width) in the exporter's order, and the spooled column block.
# Spheres: principal stresses (42) and the stress tensor (36) when the job computes them
# (granular_run.stress; else left out: the warning musen-no-stress says why); temperature (37)
# is 0, as MUSEN writes without a thermal model (the frame's, when a heat model runs).
_SPHERE_STRESS = (("angVel", 16, 3), ("coord", 12, 3), ("force", 20, 3), ("forceAmpl", 18, 1),
                  ("orient", 31, 4), ("princStress", 42, 3), ("stressTensor", 36, 9),
                  ("temperature", 37, 1), ("velocity", 15, 3))
_SPHERE = tuple(f for f in _SPHERE_STRESS if f[0] not in ("princStress", "stressTensor"))
_BOND = (("coord", 12, 3), ("force", 20, 3), ("forceAmpl", 18, 1), ("tangOverlap", 45, 3),
         ("temperature", 37, 1), ("totTorque", 43, 1), ("velocity", 15, 3))
_WALL = (("coord", 44, 9), ("force", 20, 3), ("forceAmpl", 18, 1), ("velocity", 15, 3))
_CHUNK = 4096
_VALUES_PER_CHUNK = 1_000_000         # ~8 MB of floats (+ their text) per formatting chunk


def _width(spec) -> int:
    """Spool columns of one object's time point: the fields' values, in the spec's order."""
    return sum(w for _, _, w in spec)


def _property(mat, pid: int) -> float:
    """A material property as simulated: the Material fields win over ``props``."""
    fields = {0: mat.density, 7: mat.youngs, 8: mat.normal_strength, 9: mat.shear_strength,
              10: mat.poisson}
    if pid in fields and fields[pid] == fields[pid]:          # not nan
        return fields[pid]
    return mat.props.get(pid, PROPERTY_DEFAULTS[pid])


def _g(x: float) -> str:
    return "%g" % (DEFAULT_ACTIVITY_END if x == np.inf else x)


def _g_all(x: np.ndarray) -> list[str]:
    """``_g`` of every value, with one ``%``."""
    return bulk_format("%g", np.where(x == np.inf, DEFAULT_ACTIVITY_END, x))


class MusenResultWriter(Writer):
    """``add`` every frame, then ``close`` (or ``abort`` on failure)."""

    format = "musen"

    def __init__(self, model: GranularModel, path: str | os.PathLike, precision: int = 6,
                 time_interval: tuple[float, float] | None = None,
                 selectors: dict[str, dict[str, bool]] | None = None, *, force: bool = True):
        super().__init__(path, force=force)
        self.model = model
        self.path = self.target
        self.precision = int(precision)
        self.time_interval = time_interval
        self.sel = export_selectors(selectors)
        self.times: list[float] = []
        self.sphere_spec = _SPHERE          # _SPHERE_STRESS once a frame brings the stress tensor
        sp = model.spheres
        self.sphere_end = sp.active_end.copy()
        self.bond_end = model.bonds.active_end.copy() if model.bonds is not None else None
        self.liquid = LiquidBondActivity(model)
        self.removed = np.zeros(sp.count, bool)      # spheres removed during the run so far
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.spool = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.spool.",
                                               dir=self.path.parent))
        except OSError as exc:
            raise write_failure(self.path, exc) from None

    @property
    def tmp(self) -> Path:
        """The temp file the result is written to until it is complete."""
        return temp_name(self.path)

    # ------------------------------------------------------------------ frames
    def track_activity(self, frame: GranularFrame) -> bool:
        """Note removed spheres and broken bonds (activity ends); whether the frame is in
        the exported time interval."""
        sp = self.model.spheres
        t = float(frame.time)
        rows = np.asarray(frame.sphere_rows, np.int64)
        present = np.zeros(sp.count, bool)
        present[rows] = True
        # a sphere active by its interval but missing from the frame was removed at this save
        gone = ~present & (sp.active_start <= t) & (self.sphere_end > t)
        self.sphere_end[gone] = t
        # only a sphere leaving the domain ends its liquid bonds (CPUSimulator), not one whose
        # activity interval ended
        self.removed |= gone
        self.liquid.save(t, ~self.removed)
        if self.bond_end is not None and frame.bond_alive is not None:
            dead = ~np.asarray(frame.bond_alive, bool)
            if self.model.plan.inlet_layout is not None:
                # a generated agglomerate's bond not made yet is not dead (activity start inf)
                dead &= np.isfinite(self.model.bonds.active_start)
            when = (np.asarray(frame.bond_end_time, np.float64) if frame.bond_end_time is not None
                    else np.full(len(dead), t))
            when = np.where(np.isfinite(when), when, t)
            self.bond_end[dead] = np.minimum(self.bond_end[dead], when[dead])
        return self.time_interval is None or self.time_interval[0] <= t <= self.time_interval[1]

    def write(self, frame: GranularFrame) -> None:
        m = self.model
        t = float(frame.time)
        rows = np.asarray(frame.sphere_rows, np.int64)
        if not self.track_activity(frame):
            return
        if not self.times and frame.stress_tensor is not None:
            self.sphere_spec = _SPHERE_STRESS
        blocks = {"s": self._sphere_block(frame, rows)}
        if m.bonds is not None:
            blocks["b"] = self._bond_block(frame, blocks["s"])
        if m.triangles is not None:
            blocks["w"] = self._wall_block(frame)
        for name, block in blocks.items():        # one growing (T, n, K) file per type
            with open(self.spool / f"{name}.bin", "ab") as fh:    # (a failure names the output)
                fh.write(np.ascontiguousarray(block, np.float64).tobytes())
        self.times.append(t)

    def _sphere_block(self, f: GranularFrame, rows: np.ndarray) -> np.ndarray:
        # spheres not in the frame are written as zeros, as MUSEN stores nothing for them
        n = self.model.spheres.count
        stress = self.sphere_spec is _SPHERE_STRESS
        b = np.zeros((n, _width(self.sphere_spec)))
        # MUSEN saves the previous evaluation's force (docs/musen.md, saved time points)
        force = f.sphere_force_as_saved()
        b[rows, 0:3] = f.omega
        b[rows, 3:6] = f.position
        b[rows, 6:9] = force
        b[rows, 9] = np.linalg.norm(force, axis=1)
        b[rows, 10:14] = f.quaternion
        at = 14
        if stress:                            # 42 principal stresses, 36 the tensor
            tensor = np.asarray(f.stress_tensor, np.float64).reshape(-1, 9)
            b[rows, 14:17] = principal_stresses(tensor)
            b[rows, 17:26] = tensor
            at = 26
        if f.temperature is not None:        # temperature (0 without a heat model)
            b[rows, at] = f.temperature
        b[rows, at + 1:at + 4] = f.velocity
        return b

    def _bond_block(self, f: GranularFrame, s: np.ndarray) -> np.ndarray:
        bonds = self.model.bonds
        pair = bonds.pair
        b = np.zeros((bonds.count, _width(_BOND)))
        # midpoint / mean velocity of the two spheres as the frame has them (0 when absent)
        v = _width(self.sphere_spec) - 3        # the velocity is the last field
        b[:, 0:3] = 0.5 * (s[pair[:, 0], 3:6] + s[pair[:, 1], 3:6])
        b[:, 12:15] = 0.5 * (s[pair[:, 0], v:v + 3] + s[pair[:, 1], v:v + 3])
        held = f.bonds_as_saved(bonds.count)
        if f.bond_force is not None:
            force = np.where(held[:, None], np.asarray(f.bond_force, np.float64), 0.0)
            b[:, 3:6] = force
            b[:, 6] = np.linalg.norm(force, axis=1)
        if f.bond_tangential_overlap is not None:
            b[:, 7:10] = np.where(held[:, None], f.bond_tangential_overlap, 0.0)
        if f.bond_torque is not None:                 # column 10: temperature 0
            b[:, 11] = np.where(held, f.bond_torque, 0.0)
        return b

    def _wall_block(self, f: GranularFrame) -> np.ndarray:
        tri = self.model.triangles
        b = np.zeros((tri.count, _width(_WALL)))
        vert = tri.vertices if f.triangle_vertices is None else f.triangle_vertices
        b[:, 0:9] = np.asarray(vert, np.float64).reshape(-1, 9)
        force = f.triangle_force_as_saved()
        if force is not None:
            b[:, 9:12] = force
            b[:, 12] = np.linalg.norm(np.asarray(force, np.float64), axis=1)
        b[:, 13:16] = tri.velocity if f.triangle_velocity is None else f.triangle_velocity
        return b

    # ------------------------------------------------------------------ output
    def finish(self) -> None:
        out = self.open(self.path, "w", newline="\n")
        self._write_objects(out)
        out.write(self._scene_text())

    def discard(self) -> None:
        shutil.rmtree(self.spool, ignore_errors=True)

    def _objects(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(ids, type, row) of every object to write, ascending id."""
        m = self.model
        parts = [(m.spheres.ids, 1)]
        if m.bonds is not None:
            parts.append((m.bonds.ids, 9))
        if m.triangles is not None:
            parts.append((m.triangles.ids, 14))
        liquid = m.liquid_bonds
        if liquid:
            parts.append((np.array([lb.id for lb in liquid], np.int64), 13))
        ids = np.concatenate([np.asarray(p[0], np.int64) for p in parts])
        types = np.concatenate([np.full(len(p[0]), p[1]) for p in parts])
        rows = np.concatenate([np.arange(len(p[0])) for p in parts])
        keep = self._filter(types, rows)
        # rows reserved for generated spheres that were never made (translate/granular/inlets.py)
        keep &= ~((types == 1) & ~np.isfinite(np.r_[m.spheres.active_start, np.zeros(len(rows))][
            np.where(types == 1, rows, len(m.spheres.active_start))]))
        if m.bonds is not None and m.plan.inlet_layout is not None:     # and their bonds
            starts = np.r_[m.bonds.active_start, 0.0]
            keep &= ~((types == 9) & ~np.isfinite(starts[np.where(types == 9, rows, len(starts) - 1)]))
        order = np.argsort(ids[keep], kind="stable")
        return ids[keep][order], types[keep][order], rows[keep][order]

    def _filter(self, types: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """CExportAsText::FilterObjects: only when some selector is off."""
        if all(all(g.values()) for g in self.sel.values()):
            return np.ones(len(types), bool)
        ot = self.sel["objectTypes"]
        keep = (((types == 1) & ot["particles"]) | ((types == 9) & ot["bonds"])
                | ((types == 14) & ot["walls"]))
        if self.times and any(any(self.sel[g].values())
                              for g in ("tdPropsPart", "tdPropsBond", "tdPropsWall")):
            start, end = self._activity(types, rows)
            keep &= ~((self.times[-1] < start) | (self.times[0] > end))
        return keep

    def _activity(self, types, rows) -> tuple[np.ndarray, np.ndarray]:
        m = self.model
        start = np.zeros(len(types))
        end = np.zeros(len(types))
        for t, s, e in ((1, m.spheres.active_start, self.sphere_end),
                        (9, None if m.bonds is None else m.bonds.active_start, self.bond_end),
                        (14, None if m.triangles is None else m.triangles.active_start,
                         None if m.triangles is None else m.triangles.active_end)):
            sel = types == t
            if sel.any():
                start[sel], end[sel] = s[rows[sel]], e[rows[sel]]
        sel = types == 13
        if sel.any():
            liquid = m.liquid_bonds
            start[sel] = [liquid[r].active_start for r in rows[sel]]
            end[sel] = self.liquid.end[rows[sel]]
        return start, end

    def _write_objects(self, out) -> None:
        ids, types, rows = self._objects()
        # cmusen's result holds a liquid bond inactive at the run's start as an object of
        # type 0, which its text export leaves out (LiquidBondActivity.untyped)
        keep = ~((types == 13) & self.liquid.untyped[np.where(types == 13, rows, 0)]) \
            if len(self.liquid.untyped) else np.ones(len(ids), bool)
        ids, types, rows = ids[keep], types[keep], rows[keep]
        nt = len(self.times)
        maps = {}
        m = self.model
        for name, count, width in (("s", m.spheres.count, _width(self.sphere_spec)),
                                   ("b", 0 if m.bonds is None else m.bonds.count, _width(_BOND)),
                                   ("w", 0 if m.triangles is None else m.triangles.count, _width(_WALL))):
            if nt and count:
                maps[name] = (self.spool / f"{name}.bin", count, width)
        most = 1 + max(_width(spec) for spec in (self.sphere_spec, _BOND, _WALL))
        piece = long_lines(nt, most, _VALUES_PER_CHUNK)
        if piece is not None:               # many saves: one line at a time, in pieces
            for i in range(len(ids)):
                self._long_line(out, int(types[i]), ids[i:i + 1], rows[i:i + 1], maps, piece)
            return
        # objects per chunk: about _VALUES_PER_CHUNK numbers in memory whatever the saves
        chunk = max(16, min(_CHUNK, _VALUES_PER_CHUNK // max(1, nt * most)))
        for lo in range(0, len(ids), chunk):
            cid, ctype, crow = ids[lo:lo + chunk], types[lo:lo + chunk], rows[lo:lo + chunk]
            lines = np.empty(len(cid), dtype=object)
            for t in (1, 9, 13, 14):
                sel = np.flatnonzero(ctype == t)
                if len(sel):
                    lines[sel] = self._lines(t, cid[sel], crow[sel], maps)
            out.write("".join(lines.tolist()))

    def _lines(self, otype: int, ids: np.ndarray, rows: np.ndarray, maps) -> list[str]:
        spec, group, name = {1: (self.sphere_spec, "tdPropsPart", "s"), 9: (_BOND, "tdPropsBond", "b"),
                             14: (_WALL, "tdPropsWall", "w"), 13: ((), "", "")}[otype]
        nt = len(self.times)

        def values_of(cols: list[int]) -> np.ndarray:
            path, count, width = maps[name]
            with open(path, "rb") as fh:
                return gather_spool(fh, count, width, nt, rows)[:, :, cols]

        return time_point_lines(self._headers(otype, ids, rows), spec, self.sel.get(group, {}),
                                self.times, self.precision, values_of)

    def _long_line(self, out, otype: int, ids: np.ndarray, rows: np.ndarray, maps, piece: int) -> None:
        spec, group, name = {1: (self.sphere_spec, "tdPropsPart", "s"), 9: (_BOND, "tdPropsBond", "b"),
                             14: (_WALL, "tdPropsWall", "w"), 13: ((), "", "")}[otype]

        def values_of(cols: list[int], steps: slice) -> np.ndarray:
            path, count, width = maps[name]
            with open(path, "rb") as fh:
                return gather_spool(fh, count, width, len(self.times), rows, steps)[0][:, cols]

        write_long_line(out, self._headers(otype, ids, rows)[0], spec, self.sel.get(group, {}),
                        self.times, self.precision, piece, values_of)

    def _headers(self, otype: int, ids: np.ndarray, rows: np.ndarray) -> list[str]:
        """Every object's constant part (``object_headers``: formatted in bulk)."""
        m = self.model
        if otype == 1:
            obj = m.spheres
            geom = bulk_format("%.16g %.16g", obj.radius[rows], obj.contact_radius[rows])
        elif otype == 9:
            obj = m.bonds
            sid = m.spheres.ids
            geom = bulk_format("%d %d %.25g %.25g", sid[obj.pair[rows, 0]], sid[obj.pair[rows, 1]],
                               obj.diameter[rows], obj.length0[rows])
        elif otype == 14:
            obj = m.triangles
            geom = [""] * len(rows)
        else:
            obj = None
            liquid = m.liquid_bonds
            geom = ["%d %d %.25g %.25g" % (liquid[r].left, liquid[r].right,
                                          liquid[r].diameter, liquid[r].length0)
                    for r in rows]
        start, end = self._activity(np.full(len(rows), otype), rows)
        const = self.sel["constProps"]
        keys = [self._key(obj, otype, r) for r in rows] if const["material"] else [""] * len(rows)
        return object_headers(const, [str(i) for i in ids.tolist()], otype, geom, keys,
                              _g_all(start), _g_all(end))

    def _key(self, obj, otype: int, r: int) -> str:
        if otype == 13:
            key = self.model.liquid_bonds[r].key
        elif obj.compound_key is not None:
            key = obj.compound_key[r]
        else:
            key = self.model.materials[int(obj.material[r])].key
        return key or "Undefined"

    def _scene_text(self) -> str:
        m = self.model
        record = scene_record(m)
        raw = record.raw
        lines: list[str] = []

        def line(tag: int, *values) -> None:
            lines.append(scene_line(tag, *values))

        sc = self.sel["sceneInfo"]
        if sc["domain"] and m.plan.domain is not None:
            line(22, *[_g(v) for v in np.concatenate(m.plan.domain)])
        if sc["pbc"]:
            flags, box = record.pbc
            periodic = tuple(bool(x) for x in m.plan.periodic)
            if periodic != tuple(flags[0] and f for f in flags[1:]):
                flags = [any(periodic), *periodic]
            if m.plan.periodic_box is not None:
                box = list(np.concatenate(m.plan.periodic_box))
            line(28, *[int(f) for f in flags], *[_g(v) for v in box])
        if sc["anisotropy"]:
            line(29, int(bool(record.anisotropy)))
        if sc["contactRadius"]:
            line(30, int(bool(record.contact_radius_flag)))
        ge = self.sel["geometries"]
        tri_ids = m.triangles.ids if m.triangles is not None else np.zeros(0, np.int64)
        for g in m.geometries:
            if ge["baseInfo"]:
                line(25, g.name.replace(" ", "_"), g.key, _g(g.mass), *[int(f) for f in g.free],
                     int(bool(g.rotate_around_centre)))
            if ge["tdProperties"]:
                line(26, self._motion_text(g) + " ")
            if ge["wallsList"]:
                line(27, len(g.triangle_rows), *[int(i) for i in tri_ids[g.triangle_rows]])
        if ge["analysisVolumes"]:
            for tok in raw.get(38, []):
                line(38, *tok)
        ma = self.sel["materials"]
        if ma["compounds"]:
            for mat in m.materials:
                props = [x for p in ACTIVE_PROPERTIES for x in (p, _g(_property(mat, p)))]
                line(32, mat.key, mat.name, *props)
        if ma["interactions"]:
            inter = record.interactions
            for b in range(len(m.materials)):
                for a in range(b + 1):
                    props = inter.get((a, b))
                    law = m.contacts.get((a, b))
                    if props is None and law is None:
                        continue
                    values = (dict(props) if props is not None else {})
                    if law is not None:        # the model's contact law is what was simulated
                        values.update({200: law.restitution, 201: law.friction,
                                       202: law.rolling_friction})
                    line(33, m.materials[b].key, m.materials[a].key,
                         *[x for p in ACTIVE_INTERACTIONS for x in (p, _g(values[p]))])
        if ma["mixtures"]:
            for tok in raw.get(34, []):
                line(34, *tok)
        gen = self.sel["generators"]
        if gen["packageGenerator"]:
            for tok in raw.get(39, []):
                line(39, *tok)
            for tok in raw.get(40, [["1", "2"]])[-1:]:   # MUSEN always writes its config line
                line(40, *tok)
        if gen["bondsGenerator"]:
            for tok in raw.get(41, []):
                line(41, *tok)
        return "".join(lines)

    @staticmethod
    def _motion_text(g) -> str:
        """GeometryMotion.cpp operator<<: `type n intervals`, "0 0" for none."""
        if g.motion_type == 0:
            return "0 0"
        if g.motion_type == 1:
            parts = [f"1 {len(g.motion)}"]
            for iv in g.motion:
                parts.append(" ".join(_g(v) for v in (iv.t_begin, iv.t_end, *iv.velocity,
                                                      *iv.centre, *iv.angular_velocity)))
            return " ".join(parts)
        parts = [f"{g.motion_type} {len(g.force_motion)}"]     # force-driven motion
        for iv in g.force_motion:
            parts.append(" ".join(_g(v) for v in (iv.limit, int(iv.limit_max), *iv.velocity,
                                                  *iv.centre, *iv.angular_velocity)))
        return " ".join(parts)
