"""Which spheres a granular job simulates (active at the start, inside the domain), when
activity ends delete them, and their LAMMPS types (one per sphere material)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.translate.granular.contacts import rolling_spring
from fibrelmp.translate.granular.inlets import inlet_spheres
from fibrelmp.translate.granular.schedule import RunTime


@dataclass
class SimulatedSpheres:
    keep: np.ndarray                 # (count,) bool: simulated
    rows: np.ndarray                 # rows simulated (LAMMPS id = row + 1)
    outside_rows: np.ndarray         # active at t_start but outside the domain: dropped
    late_rows: np.ndarray            # active only after t_start: not simulated
    deletions: list[tuple[int, np.ndarray]]   # (step, sphere rows) removed at activity end
    x: np.ndarray                    # positions of all spheres
    crad: np.ndarray                 # contact radius of all spheres (the LAMMPS radius)
    smat: np.ndarray                 # material of each simulated sphere
    mats: list[int]                  # sphere materials; LAMMPS type of mats[i] is i + 1
    type_of_mat: dict[int, int]
    mass: np.ndarray                 # mass of each simulated sphere
    m_min: dict[int, float]          # lightest sphere per material
    r_mean: dict[int, float]         # mean contact radius per material
    r_min: float                     # smallest / largest contact radius (1.0 without spheres)
    r_max: float

    def material_groups(self) -> list[tuple[int, int]]:
        """(LAMMPS type, material) of every sphere type: groups m<type> in the script."""
        return [(self.type_of_mat[m], m) for m in self.mats]


def select_spheres(model: GranularModel, run: RunTime, periodic: np.ndarray, dom_lo, dom_hi,
                   warnings: list[tuple[str, str]]) -> SimulatedSpheres:
    """Spheres active at the start and inside the domain (``dom_lo``/``dom_hi`` or None) on the
    non-periodic axes; the others are named in ``warnings``."""
    sp = model.spheres
    dim, dt, t_start, t_end = run.dim, run.dt, run.t_start, run.t_end
    eps = 0.5 * dt
    active_now = (sp.active_start <= t_start + eps) & (sp.active_end > t_start + eps)
    late = sp.active_start > t_start + eps
    if model.plan.inlet_rows is not None:          # reserved for generated spheres (inlets.py)
        late[model.plan.inlet_rows:] = False
    x = np.asarray(sp.position, float)
    inside = np.ones(sp.count, bool)
    if dom_lo is not None:
        for a in range(dim):
            if not periodic[a]:
                inside &= (x[:, a] >= dom_lo[a]) & (x[:, a] <= dom_hi[a])
    keep = active_now & inside
    outside_rows = np.flatnonzero(active_now & ~inside)
    late_rows = np.flatnonzero(late & ~active_now)
    if len(late_rows):
        warnings.append(("late spheres", f"{len(late_rows)} sphere(s) become active only after the "
                         "start time; fibrelmp does not insert particles during a run, so they are "
                         "left out"))
    if len(outside_rows):
        warnings.append(("outside domain", f"{len(outside_rows)} sphere(s) lie outside the "
                         "simulation domain at the start and are left out"))
    rows = np.flatnonzero(keep)
    if (sp.radius[rows] <= 0).any() or (sp.mass[rows] <= 0).any():
        raise InputError(model.source, None, "every sphere needs a radius > 0 and a mass > 0")
    crad = np.where(sp.contact_radius > 0, sp.contact_radius, sp.radius)
    if (np.abs(crad[rows] - sp.radius[rows]) > 1e-12 * sp.radius[rows]).any():
        warnings.append(("contact radius", "spheres with contact radius != radius: LAMMPS has one "
                         "radius and uses the contact radius (moments of inertia 2/5 m Rc^2)"))
    # finite activity ends inside the run: delete at that step
    deletions: list[tuple[int, np.ndarray]] = []
    ends = sp.active_end[rows]
    fin = np.isfinite(ends) & (ends < t_end)
    if fin.any():
        dsteps = np.ceil((ends[fin] - t_start) / dt - 1e-9).astype(np.int64)
        for s in np.unique(dsteps):
            deletions.append((int(max(s, 1)), rows[fin][dsteps == s]))

    # LAMMPS types: one per sphere material (wall-tile materials follow, see tiles.py)
    smat = sp.material[rows].astype(np.int64)
    # and the materials of the spheres MUSEN's generators will insert (inlets.py)
    made = inlet_spheres(model)
    mats = sorted({int(m) for m in smat} | {m for m, _, _ in made})
    type_of_mat = {m: i + 1 for i, m in enumerate(mats)}
    mass = sp.mass[rows]
    m_min = {m: min([float(x) for x in mass[smat == m]] + [w for k, _, w in made if k == m])
             for m in mats}
    r_mean = {m: float(np.mean([*crad[rows][smat == m], *(r for k, r, _ in made if k == m)]))
              for m in mats}
    radii = [*crad[rows], *(r for _, r, _ in made)]
    r_min = float(min(radii)) if radii else 1.0
    r_max = float(max(radii)) if radii else 1.0
    if m_min:                       # the rolling spring of the heaviest sphere is the stiffest
        rolling_spring(max(m_min.values()), dt, model.source)
    return SimulatedSpheres(keep, rows, outside_rows, late_rows, deletions, x, crad, smat, mats,
                            type_of_mat, mass, m_min, r_mean, r_min, r_max)


def check_distinct_positions(model: GranularModel) -> None:
    """Refuse two spheres alive at the start at exactly one position: their contact has no
    normal (MUSEN's law divides by the zero distance and gives nan; LAMMPS's pair styles skip
    the pair, so the two would overlap for ever with no force)."""
    sp = model.spheres
    if sp is None or sp.count < 2:
        return
    t = model.plan.t_start
    rows = np.flatnonzero((sp.active_start <= t) & (sp.active_end > t))
    if len(rows) < 2:
        return
    pos = np.ascontiguousarray(np.asarray(sp.position, float)[rows])
    order = np.lexsort(pos.T[::-1])
    same = np.flatnonzero((pos[order[1:]] == pos[order[:-1]]).all(axis=1))
    if not len(same):
        return
    a, b = (int(sp.ids[rows[order[k]]]) for k in (same[0], same[0] + 1))
    more = f" (and {len(same) - 1} more pair(s))" if len(same) > 1 else ""
    x = ", ".join(f"{v:.17g}" for v in pos[order[same[0]]])
    raise InputError(model.source, None, f"spheres {min(a, b)} and {max(a, b)} are at the same "
                     f"position ({x}){more}: their contact has no direction (MUSEN gives nan, "
                     "LAMMPS no force); move one sphere")
