"""MUSEN's contact-list update schedule for ``fix musen/verlet`` (docs/musen.md, *Broken
bonds and MUSEN's contact list*).

cmusen lets a broken bond's spheres into its contact list only at its next list update
(``CVerletList::UpdateList`` → ``RemoveSBContacts``), which its Verlet distance decides: the
fix needs that distance (``CVerletList::SetSceneInfo``: coefficient × the smallest contact
radius), the auto-adjustment flag, and the wall speed MUSEN's check adds every step
(``CCPUSimulator::UpdateVerletLists``: ``GetMaxWallVelocity``, recomputed only while the
time is 0 or a geometry moves freely, so frozen at its t = 0 value otherwise)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fibrelmp.granmodel import Geometry, GranularModel


@dataclass(frozen=True)
class VerletSchedule:
    distance: float          # MUSEN's initial Verlet distance (m)
    auto: bool               # its auto-adjustment
    wall_speed: float        # the wall speed its check adds per step (m/s)
    pbc_speed: float         # the largest face speed of a moving periodic box (m/s)
    approximate: str | None  # why the wall term is not MUSEN's exactly (None: it is)


def musen_verlet(model: GranularModel) -> VerletSchedule:
    """The settings of ``fix musen/verlet`` for a MUSEN model."""
    plan, s = model.plan, model.spheres
    active = (s.active_start <= plan.t_start) & (plan.t_start < s.active_end)
    radii = s.contact_radius[active] if active.any() else s.contact_radius
    # GetMinParticleContactRadius: the first sphere counts whether active or not
    smallest = float(min(radii.min(initial=np.inf), s.contact_radius[0])) if s.count else 0.0
    speed, approximate = 0.0, None
    for geom in model.geometries:
        if not len(geom.triangle_rows):
            continue
        value, why = _geometry_speed(model, geom)
        speed = max(speed, value)
        approximate = approximate or why
    pbc = 0.0
    if plan.periodic_velocity is not None and any(plan.periodic):
        pbc = float(np.abs(np.asarray(plan.periodic_velocity)[list(plan.periodic)]).max())
    return VerletSchedule(plan.verlet_coeff * smallest, bool(plan.verlet_auto), speed, pbc, approximate)


def _geometry_speed(model: GranularModel, geom: Geometry) -> tuple[float, str | None]:
    """MUSEN's GetMaxWallVelocity term of one geometry as its walls move after t = 0:
    |v| + |ω| × the largest vertex distance from the rotation centre."""
    vertices = model.triangles.vertices[geom.triangle_rows].reshape(-1, 3)
    t0 = model.plan.t_start
    if geom.motion_type in (2, 3):
        intervals = geom.force_motion
        why = f"geometry {geom.name!r} moves by force: its largest interval speed is used"
    else:
        intervals = [m for m in geom.motion if m.t_begin <= t0 <= m.t_end]
        why = None
    if any(geom.free) and geom.mass != 0:
        why = (f"geometry {geom.name!r} moves freely: MUSEN re-evaluates its speed every step, "
               "fibrelmp uses its interval speeds")
    if not intervals:           # MUSEN keeps the walls' stored velocity
        v = model.triangles.velocity[geom.triangle_rows]
        return float(np.linalg.norm(v, axis=1).max(initial=0.0)), why
    best = 0.0
    for m in intervals:
        reach = np.linalg.norm(vertices - np.asarray(m.centre), axis=1).max(initial=0.0)
        best = max(best, float(np.linalg.norm(m.velocity)) + float(np.linalg.norm(m.angular_velocity)) * reach)
    return best, why
