"""Triangle walls for fibrelmp's ``fix musen/wall/mesh`` (MUSEN's particle-wall contact): the
file the fix reads (``walls.mesh`` next to ``data.lammps``; format in the fix's header,
``fibrelmp/lammps_styles/src/fix_musen_wall_mesh.h``).

Every triangle of every geometry is written as it is, in MUSEN's wall order (geometries in
scene order, each in its ``27`` list order: the order MUSEN breaks ties between touched
triangles in), with its own wall material; each geometry with the coefficients of its exact
rigid motion (the same ``kinematics.Kinematics`` the frames report wall positions with) and its
MUSEN motion intervals (the wall velocity the contact law sees)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.granmodel import GranularModel
from fibrelmp.textio import atomic_write
from fibrelmp.translate.granular.contacts import check_law

MESH_NAME = "walls.mesh"              # the fix's input, next to data.lammps
MESH_FORCES_NAME = "wall_forces.dump" # per-triangle forces, one frame per saved step
MESH_FIX = "fl_walls"


def _num(x: float) -> str:
    x = float(x)
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(x)


def _words(name: str) -> str:
    """A name as one plain ASCII word (letters, digits, _ . -): the file is read by LAMMPS
    ranks and user text must not reach it as anything but a label."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", str(name))[:64] or "_"


@dataclass
class MeshWalls:
    """What the job needs of the mesh: which model triangle each fix triangle is."""

    rows: np.ndarray        # (T,) model triangle row of fix triangle i (its dump id is i + 1)

    @property
    def count(self) -> int:
        return len(self.rows)


def mesh_plans(wall_plans) -> list:
    return [wp for wp in wall_plans if wp.kind == "mesh"]


def mesh_rows(wall_plans) -> np.ndarray:
    plans = mesh_plans(wall_plans)
    if not plans:
        return np.zeros(0, np.int64)
    return np.concatenate([np.asarray(wp.triangle_rows, np.int64) for wp in plans])


def mesh_text(model: GranularModel, wall_plans, spheres) -> str:
    """The fix's input file: laws per (LAMMPS sphere type, wall material), geometries with
    their motion, triangles."""
    plans = mesh_plans(wall_plans)
    tris = model.triangles
    rows = mesh_rows(wall_plans)
    wall_mats = sorted({int(m) for m in tris.material[rows]}) if len(rows) else []
    out = ["# fibrelmp: triangle walls of fix musen/wall/mesh (MUSEN's particle-wall contact)",
           "musen/wall/mesh 1"]
    laws = []
    for t, m in spheres.material_groups():
        for wm in wall_mats:
            law = check_law(model, m, wm)
            laws.append(f"{t} {wm} {_num(law.youngs_eff)} {_num(law.shear_eff)} "
                        f"{_num(law.restitution)} {_num(law.friction)} {_num(law.rolling_friction)}"
                        f"   # {_words(model.materials[m].name)} - {_words(model.materials[wm].name)}")
    out.append("# per LAMMPS sphere type and wall material: E* G* e mu mu_r")
    out.append(f"laws {len(laws)}")
    out += laws
    out.append(f"geometries {len(plans)}")
    for wp in plans:
        if wp.stepped is not None:
            out += _stepped_lines(wp, tris)
            continue
        kin = wp.kinematics
        out.append(f"geometry {_words(wp.name)} {int(kin.around_centre)} {len(kin.segments)} "
                   f"{len(kin.motions)}")
        for s in kin.segments:
            vals = [s.t0, s.t1, s.w, *np.asarray(s.axis, float).ravel(),
                    *np.asarray(s.kr, float).ravel(), *np.asarray(s.kb, float).ravel()]
            out.append("seg " + " ".join(_num(v) for v in vals))
        for m in kin.motions:
            vals = [m.t_begin, m.t_end, *m.velocity, *m.centre, *m.omega]
            out.append("int " + " ".join(_num(v) for v in vals))
    if any(wp.stepped is not None for wp in plans):
        out.append("gravity " + " ".join(_num(g) for g in model.plan.gravity))
    out.append(f"triangles {len(rows)}")
    for gi, wp in enumerate(plans):
        for r in np.asarray(wp.triangle_rows, np.int64):
            v = np.asarray(tris.vertices[r], float).ravel()
            out.append(f"{gi} {int(tris.material[r])} " + " ".join(_num(c) for c in v))
    return "\n".join(out) + "\n"


def _stepped_lines(wp, tris) -> list[str]:
    """A geometry the fix moves step by step: MUSEN's intervals as they are (time intervals
    in MUSEN's order, force intervals), its free axes and mass."""
    g = wp.stepped
    around = bool(g.rotate_around_centre)
    times = g.motion if g.motion_type == 1 else []
    out = [f"geometry {_words(wp.name)} {int(around)} 0 {len(times)}"]
    for m in times:
        vals = [m.t_begin, m.t_end, *m.velocity, *m.centre, *m.angular_velocity]
        out.append("int " + " ".join(_num(v) for v in vals))
    if g.motion_type in (1, 2, 3):
        forces = g.force_motion if g.motion_type in (2, 3) else []
        out.append(f"force {g.motion_type} {len(forces)}")
        for f in forces:
            vals = [*f.velocity, *f.centre, *f.angular_velocity]
            out.append(f"fint {_num(f.limit)} {int(f.limit_max)} " + " ".join(_num(v) for v in vals))
    if any(g.free) and g.mass != 0:
        out.append("free " + " ".join(str(int(bool(x))) for x in g.free) + f" {_num(g.mass)}")
    rows = np.asarray(wp.triangle_rows, np.int64)
    if len(rows) and np.any(tris.velocity[rows[0]] != 0):    # one velocity (walls.py checks)
        out.append("velocity " + " ".join(_num(v) for v in tris.velocity[rows[0]]))
    return out


def write_mesh(model: GranularModel, wall_plans, spheres, path: Path) -> MeshWalls:
    atomic_write(Path(path), mesh_text(model, wall_plans, spheres))
    return MeshWalls(mesh_rows(wall_plans))
