"""``fibrelmp run --also vtk``: the run's frames as files ParaView and OVITO open, written with
``post.vtk``'s writer while the frames are converted, beside the run's results.

Where: ``<base>.pvd`` and ``<base>_NNNNNN.vtp`` (with bonds also ``_bonds.vtp`` and ``.vtm``),
``<base>`` being the result's name without its suffix: FibreNet ``<folder>/<output_file>``,
a MUSEN scene's (or each cmusen SIMULATOR job's) result file, DEMDF ``<folder>/<filename>``.
They are outputs of the run like its results: checked and locked before LAMMPS starts,
staged and renamed into place when the run succeeds, replaced (all frames) only with
``--force``.

With MUSEN walls also ``<base>_walls.pvd`` and ``<base>_NNNNNN_walls.vtp`` (PolyData triangles
where they are at each frame, with their velocity and force).

What: every saved frame; ids, types, ``Radius``, ``Mass``, ``Velocity``, ``Force``,
``Angular Velocity`` and ``Orientation`` where the run has them (post/vtk/frame.py); the
time is the simulation time.

``ViewerOutput`` is the registry's ALSO hook of ``vtk`` (``fibrelmp.also``).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from fibrelmp.also import RunOutput
from fibrelmp.post.vtk.frame import ViewerFrame, box_of, from_dump, wrap
from fibrelmp.post.vtk.target import frame_pattern
from fibrelmp.post.vtk.writer import VtkWriter, check_output_name

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularFrame, GranularModel
    from fibrelmp.model import Model
    from fibrelmp.outputs import Outputs
    from fibrelmp.post.lammps_dump.reader import Frame

# FibreNet work dumps name FibreNet's velocity and force after the variables that hold them
FIBRENET_COLUMNS = {"v_fn_vx": "vx", "v_fn_vy": "vy", "v_fn_vz": "vz",
                    "v_fn_fx": "fx", "v_fn_fy": "fy", "v_fn_fz": "fz"}


def declare(outputs: "Outputs", base: Path) -> None:
    """Add the viewer files of ``base`` to a run's outputs (its ``.pvd``, and its frame files
    as a family: earlier frames need ``--force`` and go when the run succeeds).  A name the
    XML files cannot hold is an input error here, before anything is written."""
    check_output_name(base)
    outputs.files.append(base.with_name(base.name + ".pvd"))
    outputs.files.append(base.with_name(base.name + "_walls.pvd"))
    outputs.patterns.append((base.parent, frame_pattern(base)))


class ViewerWriter(VtkWriter):
    """A ``VtkWriter`` fed with a run's own frames, each turned into a ``ViewerFrame`` by
    ``convert``."""

    def __init__(self, base: Path, convert: Callable[[Any], ViewerFrame], bonded: bool):
        super().__init__(base, bonded=bonded)
        self.convert = convert

    def write(self, frame: Any) -> None:
        super().write(self.convert(frame))


# -- granular runs (MUSEN, DEMDF) ----------------------------------------------------------
def granular_writer(model: "GranularModel", base: Path) -> ViewerWriter:
    bonded = model.bonds is not None and model.bonds.count > 0
    return ViewerWriter(base, lambda frame: granular_frame(model, frame), bonded)


def granular_frame(model: "GranularModel", frame: "GranularFrame") -> ViewerFrame:
    """The spheres still in the run (ids: the input's own; type: material number, 1 = the
    first), the bonds alive at the frame (with the force on their first sphere)."""
    s, plan = model.spheres, model.plan
    rows = frame.sphere_rows
    periodic = np.array(plan.periodic, bool)
    box = plan.periodic_box if plan.periodic_box is not None else plan.domain
    if periodic.any() and box is not None:
        origin, cell, periodic = box_of(box[0], box[1], periodic)
    else:
        origin, cell, periodic = np.zeros(3), np.eye(3), np.zeros(3, bool)
    data = {"type": (np.asarray(s.material)[rows] + 1).astype(np.int32),
            "Radius": np.asarray(s.radius, float)[rows], "Mass": np.asarray(s.mass, float)[rows],
            "Velocity": frame.velocity, "Force": frame.force, "Angular Velocity": frame.omega,
            "Orientation": frame.quaternion[:, [1, 2, 3, 0]]}          # w x y z -> X Y Z W
    if frame.temperature is not None:       # a heat model's (K)
        data["temperature"] = frame.temperature
    bonds, bond_data = None, {}
    if model.bonds is not None and frame.bond_alive is not None:
        alive = np.flatnonzero(frame.bond_alive)
        bonds = np.asarray(s.ids, np.int64)[model.bonds.pair[alive]]
        if frame.bond_force is not None:
            bond_data["Force"] = frame.bond_force[alive]
    walls, wall_data = None, {}
    if model.triangles is not None and model.triangles.count:
        tri = model.triangles
        walls = tri.vertices if frame.triangle_vertices is None else frame.triangle_vertices
        wall_data["Velocity"] = tri.velocity if frame.triangle_velocity is None else frame.triangle_velocity
        if frame.triangle_force is not None:
            wall_data["Force"] = frame.triangle_force
    return ViewerFrame(frame.step, frame.time, np.asarray(s.ids, np.int64)[rows],
                       wrap(frame.position, origin, cell, periodic), origin, cell, periodic,
                       data, bonds, bond_data, walls, wall_data)


# -- FibreNet runs ---------------------------------------------------------------------------
def fibrenet_writer(model: "Model", base: Path) -> ViewerWriter:
    return ViewerWriter(base, lambda frame: fibrenet_frame(model, frame), model.bonds.count > 0)


def fibrenet_frame(model: "Model", frame: "Frame") -> ViewerFrame:
    """A frame of a FibreNet job's dump (atom id = bead row + 1): FibreNet's velocity and
    force, the bead's type (1 = the first ``type`` line), radius, mass and fibre; time =
    step x dt as FibreNet counts it (the dump's ITEM: TIME when it has one)."""
    columns = dict(frame.columns)
    for name, standard in FIBRENET_COLUMNS.items():       # FibreNet's, also beside LAMMPS's vx
        if name in columns:
            columns[standard] = columns.pop(name)
    p = model.particles
    time = frame.time if frame.time is not None else frame.step * model.dynamics.dt
    view = from_dump(replace(frame, columns=columns), np.asarray(model.bonds.atoms, np.int64) + 1, time)
    rows = view.ids - 1
    view.point_data["type"] = (np.asarray(p.types)[rows] + 1).astype(np.int32)
    view.point_data.setdefault("Radius", np.asarray(p.radii, float)[rows])
    view.point_data.setdefault("Mass", np.asarray(p.masses, float)[rows])
    view.point_data["fibre"] = np.asarray(p.molecules)[rows].astype(np.int32)
    return view


class ViewerOutput(RunOutput):
    """``run --also vtk``: the frames through ``ViewerWriter``, named after ``base``."""

    def declare(self, outputs: "Outputs", base: Path) -> None:
        declare(outputs, base)

    def granular_writer(self, model: "GranularModel", base: Path) -> ViewerWriter:
        return granular_writer(model, base)

    def fibrenet_writer(self, model: "Model", base: Path) -> ViewerWriter:
        return fibrenet_writer(model, base)
