"""Rigid-motion kinematics of granular walls.

Used by ``granular.walls`` / ``granular.mesh`` (LAMMPS script) and the frames (wall positions).
Numpy only; nothing writes files.

Motion (MUSEN geometry motion type 1): in [t_begin, t_end) the geometry translates with v and
rotates with angular velocity w about a fixed centre c (or about its own moving centroid when
``rotate_around_centre``: the area-weighted centroid of its triangles, as MUSEN's
CPUSimulator::MoveWalls computes it), i.e. dx/dt = v + w x (x - c).  The exact solution of
each interval is x(t) = R(t) x0 + b(t) with every entry of R and b of the form
k0 + k1 tau + k2 cos(|w| tau) + k3 sin(|w| tau)  (tau = t - interval start), which is what
the LAMMPS variables and fix musen/wall/mesh evaluate and what the frames report.

The wall *velocity* MUSEN reports and its contact law uses is not always the motion's: when no
interval moves a geometry any more (after the last one ends, or in a gap or a zero interval),
MUSEN's MoveWalls skips it and its walls keep the velocity, rotation velocity and rotation
centre they last had (``Kinematics.wall_state``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fibrelmp.granmodel import Geometry
from fibrelmp.translate.granular.geometry import area_centroid


def _rot_parts(n: np.ndarray, u: np.ndarray):
    """R_n(phi) u = A + B cos(phi) + C sin(phi) (Rodrigues), for u (3,) or (3,k)."""
    if u.ndim == 1:
        a = n * float(n @ u)
    else:
        a = np.outer(n, n @ u)
    return a, u - a, np.cross(n, u, axis=0) if u.ndim > 1 else np.cross(n, u)


@dataclass
class Segment:
    """x(t) = R(tau) x0 + b(tau) for t in [t0, t1), tau = t - t0.  Each entry of R (3,3) and
    b (3,) is  k0 + k1 tau + k2 cos(w tau) + k3 sin(w tau);  coefficients (4,3,3) / (4,3)."""

    t0: float
    t1: float
    w: float                  # |omega| (0: translation only)
    axis: np.ndarray          # unit rotation axis (zeros if w == 0)
    kr: np.ndarray            # (4,3,3)
    kb: np.ndarray            # (4,3)
    velocity: np.ndarray      # MUSEN's reported wall velocity (translation velocity)

    def basis(self, tau: float) -> np.ndarray:
        if self.w == 0:
            return np.array([1.0, tau, 1.0, 0.0])
        return np.array([1.0, tau, math.cos(self.w * tau), math.sin(self.w * tau)])

    def dbasis(self, tau: float) -> np.ndarray:
        if self.w == 0:
            return np.array([0.0, 1.0, 0.0, 0.0])
        return np.array([0.0, 1.0, -self.w * math.sin(self.w * tau), self.w * math.cos(self.w * tau)])

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        e = self.basis(t - self.t0)
        return np.tensordot(e, self.kr, 1), np.tensordot(e, self.kb, 1)

    def rate(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        e = self.dbasis(t - self.t0)
        return np.tensordot(e, self.kr, 1), np.tensordot(e, self.kb, 1)


@dataclass
class WallMotion:
    """One MUSEN time interval as its contact law sees it (closed: t_begin <= t <= t_end)."""

    t_begin: float
    t_end: float
    velocity: np.ndarray
    centre: np.ndarray
    omega: np.ndarray

    @property
    def moves(self) -> bool:
        return bool(self.velocity.any() or self.omega.any())


@dataclass
class Kinematics:
    """Rigid motion of one geometry from t_start on (identity before the first interval)."""

    segments: list[Segment] = field(default_factory=list)
    intervals: list[tuple[float, float, np.ndarray]] = field(default_factory=list)
    moving: bool = False
    rotating: bool = False
    single_axis: np.ndarray | None = None     # common rotation axis if all rotations share it
    motions: list[WallMotion] = field(default_factory=list)   # sorted by t_begin, not ended at t_start
    around_centre: bool = False

    def segment(self, t: float) -> Segment | None:
        for s in self.segments:
            if s.t0 <= t < s.t1:
                return s
        return self.segments[-1] if self.segments and t >= self.segments[-1].t1 else None

    def transform(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        if not self.segments or t < self.segments[0].t0:
            return np.eye(3), np.zeros(3)
        return self.segment(t).at(t)

    def wall_state(self, t: float) -> tuple[WallMotion | None, bool]:
        """(the interval whose velocity, rotation velocity and centre MUSEN's walls carry at
        time t or None (never moved: all zero), whether the geometry moves at t).

        MUSEN (CGeometryMotion::UpdateMotionInfo) takes the interval with
        t_begin <= t <= t_end; when there is none or it does not move the geometry,
        CPUSimulator::MoveWalls skips the geometry and the walls keep the values of the last
        interval that moved them: the wall stands still while MUSEN's contact law and its
        result file still see it moving."""
        cur = next((m for m in self.motions if m.t_begin <= t <= m.t_end), None)
        if cur is not None and cur.moves:
            return cur, True
        last = None
        for m in self.motions:
            if m.t_begin <= t and m.moves:
                last = m
        return last, False

    def velocity(self, t: float) -> np.ndarray:
        """The translation velocity MUSEN reports for the walls at time t: that of the motion
        interval holding t, kept after the motion stops (``wall_state``)."""
        m, _ = self.wall_state(t)
        return m.velocity.copy() if m is not None else np.zeros(3)

    def kept_velocity(self, t0: float, t1: float) -> tuple[float, np.ndarray, np.ndarray] | None:
        """The first time in [t0, t1) from which the geometry stands still while MUSEN keeps a
        non-zero wall velocity or rotation velocity (time, velocity, rotation velocity), or
        None: the quirk ``wall_state`` describes, which fibrelmp reproduces and warns about."""
        bounds = sorted({t0, t1} | {m.t_begin for m in self.motions if t0 < m.t_begin < t1}
                        | {m.t_end for m in self.motions if t0 <= m.t_end < t1})
        for a, b in zip(bounds, bounds[1:]):
            m, moving = self.wall_state(0.5 * (a + b))
            if m is not None and not moving:
                return a, m.velocity.copy(), m.omega.copy()
        return None

    def angle(self, t: float) -> float:
        """Rotation angle about ``single_axis`` (only when rotations share one axis)."""
        th = 0.0
        for s in self.segments:
            if t <= s.t0:
                break
            th += float(s.axis @ self.single_axis) * s.w * (min(t, s.t1) - s.t0) if s.w else 0.0
        return th


def geometry_kinematics(geom: Geometry, vertices0: np.ndarray, t_start: float,
                        t_end: float) -> Kinematics:
    """Segments of time-dependent motion (motion_type 1) from t_start to t_end.

    ``vertices0``: the geometry's triangles (k,3,3) at t_start (for the centroid when it
    rotates about its own centre: their area-weighted centroid, as MUSEN computes it).
    """
    kin = Kinematics()
    if geom.motion_type != 1 or not geom.motion:
        return kin
    kin.around_centre = bool(geom.rotate_around_centre)
    # a simulation starts with still walls (MUSEN's InitializeGeometricalObjects): intervals
    # that ended before t_start leave no kept velocity
    kin.motions = [WallMotion(float(iv.t_begin), float(iv.t_end), np.asarray(iv.velocity, float).copy(),
                              np.asarray(iv.centre, float).copy(), np.asarray(iv.angular_velocity, float).copy())
                   for iv in sorted(geom.motion, key=lambda m: m.t_begin) if iv.t_end >= t_start]
    g0 = area_centroid(vertices0)
    rk, bk = np.eye(3), np.zeros(3)
    t = t_start
    axes = []
    for iv in sorted(geom.motion, key=lambda m: m.t_begin):
        kin.intervals.append((float(iv.t_begin), float(iv.t_end), np.asarray(iv.velocity, float).copy()))
        t0, t1 = max(iv.t_begin, t_start), min(iv.t_end, t_end)
        if t1 <= t0:
            continue
        v = np.asarray(iv.velocity, float)
        om = np.asarray(iv.angular_velocity, float)
        w = float(np.linalg.norm(om))
        if not v.any() and w == 0:
            continue
        if t0 > t:      # a gap: no motion
            kin.segments.append(_static_segment(t, t0, rk, bk))
        kr, kb = np.zeros((4, 3, 3)), np.zeros((4, 3))
        if w == 0:
            kr[0] = rk
            kb[0], kb[1] = bk, v
            n = np.zeros(3)
        else:
            n = om / w
            axes.append(n)
            kin.rotating = True
            a, b_, c = _rot_parts(n, rk)
            kr[0], kr[2], kr[3] = a, b_, c
            centre = (rk @ g0 + bk) if geom.rotate_around_centre else np.asarray(iv.centre, float)
            a, b_, c = _rot_parts(n, bk - centre)
            kb[0] = centre + a
            kb[2], kb[3] = b_, c
            if geom.rotate_around_centre:
                kb[1] += v
            else:       # integral of R(w u) v du over [0, tau]
                av, bv, cv = _rot_parts(n, v)
                kb[0] += cv / w
                kb[1] += av
                kb[2] -= cv / w
                kb[3] += bv / w
        seg = Segment(t0, t1, w, n, kr, kb, v.copy())
        kin.segments.append(seg)
        rk, bk = seg.at(t1)
        t = t1
        kin.moving = True
    if kin.segments:
        kin.segments.append(_static_segment(t, math.inf, rk, bk))
    if axes:
        ref = axes[0]
        if all(abs(abs(float(ax @ ref)) - 1) < 1e-12 for ax in axes):
            kin.single_axis = ref
    else:
        kin.single_axis = np.array([0.0, 0.0, 1.0])
    return kin


def _static_segment(t0: float, t1: float, rk: np.ndarray, bk: np.ndarray) -> Segment:
    kr, kb = np.zeros((4, 3, 3)), np.zeros((4, 3))
    kr[0], kb[0] = rk, bk
    return Segment(t0, t1, 0.0, np.zeros(3), kr, kb, np.zeros(3))


def _num(x: float) -> str:
    return repr(float(x))


def piecewise_expression(kin: Kinematics, coeff, derivative: bool = False) -> str:
    """LAMMPS equal-style expression of one R/b entry over all segments (uses ``time``).

    ``coeff(segment) -> (4,)`` picks the entry's coefficients."""
    terms = []
    for s in kin.segments:
        k = np.asarray(coeff(s), float)
        tau = f"(time-{_num(s.t0)})"
        if derivative:
            parts = [(k[1], "")]
            if s.w:
                parts += [(-k[2] * s.w, f"*sin({_num(s.w)}*{tau})"), (k[3] * s.w, f"*cos({_num(s.w)}*{tau})")]
        else:
            parts = [(k[0] + (k[2] if not s.w else 0.0), ""), (k[1], f"*{tau}")]
            if s.w:
                parts += [(k[2], f"*cos({_num(s.w)}*{tau})"), (k[3], f"*sin({_num(s.w)}*{tau})")]
        body = "+".join(f"{_num(c)}{f}" for c, f in parts if c != 0) or "0"
        cond = f"(time>={_num(s.t0)})" + (f"*(time<{_num(s.t1)})" if math.isfinite(s.t1) else "")
        terms.append(f"{cond}*({body})")
    if not terms:
        return "0"
    first = kin.segments[0].t0
    identity = coeff(_static_segment(0.0, 0.0, np.eye(3), np.zeros(3)))[0]
    if identity != 0 and not derivative:
        terms.append(f"(time<{_num(first)})*{_num(identity)}")
    return "+".join(terms)
