"""The CardioProof case file: a JSON document whose first key is ``"cardioproof"``.

::

    {"cardioproof": 1,
     "mesh":    {"file": "tube.pts", "unit": 1e-6},          # openCARP (µm) or VTK (m); a string works
     "motion":  {"file": "tube.dynpt", "frame_interval": 1e-3},   # or {"meshes": [...]}; optional
     "fluid":   {"spacing": 1e-4, "density": 1000, "artificial_viscosity": 0.1, "sound_speed": 5.0},
     "wall":    {"layers": 3},
     "openings": [{"name": "outlet", "tags": [3], "pressure": [[0, 0], [0.01, 50]],
                   "search_distance": 2e-4}],
     "run":     {"end_time": 0.01},
     "output":  {"interval": 1e-3, "series_interval": 1e-4}}

Everything in SI units except the mesh coordinates, which keep their file's unit (``unit``:
metres per coordinate unit; openCARP files default to µm, VTK files to m).  Paths are relative
to the case file.  docs/cardioproof.md describes every key and its default.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.lammps_text import lammps_word
from fibrelmp.mesh.model import Mesh
from fibrelmp.particles import ModelCounts, ParticleModel, ParticleView
from fibrelmp.translate.json_doc import JsonDoc, load_json

VERSION = 1
ARTIFICIAL_VISCOSITY = 0.1   # Monaghan's alpha when the case gives no viscosity
SMOOTHING_RATIO = 2.6          # kernel cutoff h / particle spacing (LAMMPS's SPH examples)
CFL = 0.1                      # dt <= CFL h / c0 (LAMMPS's SPH examples)
# the weakly compressible model needs c0 >= 10x the fastest flow; above this (70x water's real
# 1480 m/s) the Tait pressure's B = c0^2 rho0 / 7 and the step count only grow
MAX_SOUND_SPEED = 1e5          # m/s
DENSITY_RANGE = (1e-3, 1e5)    # kg/m^3: thin gas .. 7x mercury (a tiny one gave NaN positions)
MAX_ARTIFICIAL_VISCOSITY = 10.0   # Monaghan's alpha: LAMMPS's examples use 0.1 .. 1
EXTENT_RANGE = (1e-9, 1e3)     # m: the mesh's largest extent (catches a wrong mesh.unit)
KEYS = {"cardioproof", "mesh", "motion", "fluid", "wall", "openings", "run", "output", "comment"}
# the keys of each object (a misspelt key must not silently give a default)
OBJECT_KEYS = {
    "mesh": {"file", "unit"},
    "motion": {"file", "meshes", "frame_interval"},
    "fluid": {"spacing", "density", "viscosity", "artificial_viscosity", "sound_speed", "smoothing_ratio"},
    "wall": {"layers"},
    "openings": {"name", "tags", "elements", "pressure", "search_distance"},
    "run": {"end_time", "time_step", "cfl"},
    "output": {"interval", "series_interval", "name"},
}


def _file(j: JsonDoc, value: Any, where: str, folder: Path) -> Path:
    """A file the case names, as an absolute path (relative names: to the case's folder)."""
    name = j.string(value, where)
    if not name.strip():
        j.fail(where, "an empty file name")
    if "\0" in name:
        j.fail(where, "a file name cannot contain a NUL character")
    return folder / name


def _known(j: JsonDoc, obj: dict, kind: str, where: str) -> dict:
    unknown = sorted(set(obj) - OBJECT_KEYS[kind])
    if unknown:
        j.fail(f"{where}.{unknown[0]}", f"unknown key (known: {', '.join(sorted(OBJECT_KEYS[kind]))})")
    return obj


@dataclass
class Opening:
    name: str                      # a LAMMPS word (IDs of its regions, fixes, variables)
    elements: np.ndarray           # indices into the mesh's shell elements (file order)
    pressure: np.ndarray           # (k, 2) time [s], pressure [Pa]; linear, held beyond the ends
    search_distance: float         # m


@dataclass
class Motion:
    kind: str                      # "dynpt" | "meshes"
    files: list[Path]
    frame_interval: float          # s between frames
    count: int                     # frames


@dataclass
class SphCase(ParticleModel):
    """SPH water in a moving finite-element wall (CardioProof).  Its particles are made when
    the job is planned (``cardioproof.job.plan_job``: the fluid lattice inside the wall)."""

    mesh: Mesh
    mesh_file: Path
    motion: Motion | None
    spacing: float                 # m, particle spacing dx
    density: float                 # kg/m^3
    viscosity: float | None        # Pa s (dynamic; Morris's laminar viscosity) or None
    artificial_viscosity: float | None   # Monaghan's alpha (sph/taitwater) or None
    sound_speed: float | None      # m/s (None: from the motion, see job.sound_speed)
    smoothing_ratio: float
    layers: int
    openings: list[Opening]
    end_time: float
    time_step: float | None
    cfl: float
    save_interval: float
    series_interval: float | None
    name: str
    kind: str = "cardioproof"
    plan: dict | None = field(default=None, repr=False)       # cardioproof.job.plan_job's, once

    particle_noun: ClassVar[str] = "SPH particles"

    def particles_view(self) -> ParticleView:
        """The fluid particles at rest on their lattice (none before the job is planned; the
        wall particles follow the mesh and are the job's)."""
        if self.plan is None:
            return ParticleView.empty()
        fluid = np.asarray(self.plan["fluid"], float).reshape(-1, 3)
        n = len(fluid)
        return ParticleView(np.arange(1, n + 1), fluid, np.zeros((n, 3)),
                            np.full(n, 0.5 * self.spacing),
                            np.full(n, self.density * self.plan["particle_volume"]),
                            np.zeros(n, np.int64))

    def counts(self) -> ModelCounts:
        """The wall: the mesh's cells; one fluid."""
        return ModelCounts(walls=self.mesh.cell_count, materials=1)

    def given_time_step(self) -> float | None:
        """run.time_step (None: the job takes the CFL limit, cardioproof.job.time_step)."""
        return self.time_step

    def unstable_hint(self) -> str:
        return ("the SPH run became unstable; a higher fluid.sound_speed (with its smaller step), "
                "more artificial_viscosity or a finer spacing usually help")

    @property
    def smoothing(self) -> float:
        """h: the kernel's cutoff (m)."""
        return self.smoothing_ratio * self.spacing


def read_case(path: str | Path) -> SphCase:
    """The case file at ``path`` and the mesh (and motion header) it names."""
    path = Path(path)
    doc = load_json(path, "CardioProof case file")
    j = JsonDoc(path)
    doc = j.obj(doc, "")
    unknown = sorted(set(doc) - KEYS)
    if unknown:
        j.fail(unknown[0], f"unknown key (known: {', '.join(sorted(KEYS))})")
    version = j.integer(doc.get("cardioproof"), "cardioproof")
    if version != VERSION:
        j.fail("cardioproof", f"case file version {version}: this fibrelmp reads version {VERSION}")
    # every file the case names is resolved now: the run changes directory before the motion
    # frames are read
    folder = path.absolute().parent

    mesh_spec = doc.get("mesh")
    if isinstance(mesh_spec, str):
        mesh_spec = {"file": mesh_spec}
    mesh_spec = _known(j, j.obj(mesh_spec, "mesh"), "mesh", "mesh")
    mesh_file = _file(j, mesh_spec.get("file"), "mesh.file", folder)
    unit = mesh_spec.get("unit")
    mesh = read_mesh(mesh_file, None if unit is None else j.number(unit, "mesh.unit", positive=True))
    extent = float(np.ptp(mesh.points_m, axis=0).max()) if len(mesh.points) else 0.0
    if not EXTENT_RANGE[0] <= extent <= EXTENT_RANGE[1]:
        j.fail("mesh.unit" if unit is not None else "mesh.file", f"the mesh spans {extent:g} m: expected "
               f"{EXTENT_RANGE[0]:g} to {EXTENT_RANGE[1]:g} m (is mesh.unit, metres per coordinate unit, right?)")

    fluid = _known(j, j.obj(doc.get("fluid"), "fluid"), "fluid", "fluid")
    dx = j.number(fluid.get("spacing"), "fluid.spacing", positive=True)
    density = j.number(fluid.get("density", 1000.0), "fluid.density", positive=True)
    if not DENSITY_RANGE[0] <= density <= DENSITY_RANGE[1]:
        j.fail("fluid.density", f"{density:g} kg/m^3: expected {DENSITY_RANGE[0]:g} to {DENSITY_RANGE[1]:g}")
    if "viscosity" in fluid and "artificial_viscosity" in fluid:
        j.fail("fluid", "give either viscosity (laminar, Morris) or artificial_viscosity (Monaghan's "
               "alpha): LAMMPS's Tait-water styles take one of them")
    viscosity = None
    alpha = ARTIFICIAL_VISCOSITY
    if "viscosity" in fluid:
        viscosity = j.number(fluid["viscosity"], "fluid.viscosity", positive=True)
        alpha = None
    elif "artificial_viscosity" in fluid:
        alpha = j.number(fluid["artificial_viscosity"], "fluid.artificial_viscosity", minimum=0.0)
        if alpha > MAX_ARTIFICIAL_VISCOSITY:
            j.fail("fluid.artificial_viscosity", f"{alpha:g}: at most {MAX_ARTIFICIAL_VISCOSITY:g} "
                   "(Monaghan's alpha is usually 0.01 to 1)")
    c0 = fluid.get("sound_speed")
    c0 = None if c0 is None else j.number(c0, "fluid.sound_speed", positive=True)
    if c0 is not None and c0 > MAX_SOUND_SPEED:
        j.fail("fluid.sound_speed", f"{c0:g} m/s: at most {MAX_SOUND_SPEED:g} m/s (the model needs 10x the "
               "fastest flow; water's real sound speed is 1480 m/s)")
    ratio = j.number(fluid.get("smoothing_ratio", SMOOTHING_RATIO), "fluid.smoothing_ratio", positive=True)
    if not 1.5 <= ratio <= 4.0:
        j.fail("fluid.smoothing_ratio", f"{ratio:g}: the kernel cutoff must be 1.5 to 4 spacings")
    wall = _known(j, j.obj(doc.get("wall", {}), "wall"), "wall", "wall")
    layers = j.integer(wall.get("layers", math.ceil(ratio)), "wall.layers", minimum=1)
    if layers > 8:
        j.fail("wall.layers", f"{layers}: at most 8 layers")

    motion = _motion(j, doc.get("motion"), folder, mesh)
    run = _known(j, j.obj(doc.get("run"), "run"), "run", "run")
    end_time = j.number(run.get("end_time"), "run.end_time", positive=True)
    dt = run.get("time_step")
    dt = None if dt is None else j.number(dt, "run.time_step", positive=True)
    cfl = j.number(run.get("cfl", CFL), "run.cfl", positive=True)
    if motion is not None and end_time > (motion.count - 1) * motion.frame_interval * (1 + 1e-12):
        j.fail("run.end_time", f"{end_time:g} s is beyond the last motion frame "
               f"({(motion.count - 1) * motion.frame_interval:g} s)")
    output = _known(j, j.obj(doc.get("output", {}), "output"), "output", "output")
    save = j.number(output.get("interval", end_time / 10), "output.interval", positive=True)
    series = output.get("series_interval")
    series = None if series is None else j.number(series, "output.series_interval", positive=True)
    name = lammps_word(j.string(output.get("name", path.stem), "output.name"), path, None, "output.name")

    openings = _openings(j, doc.get("openings", []), mesh, dx, mesh_file)
    return SphCase(path, mesh, mesh_file, motion, dx, density, viscosity, alpha, c0, ratio, layers,
                   openings, end_time, dt, cfl, save, series, str(name))


def read_mesh(path: Path, unit: float | None) -> Mesh:
    """A mesh file of any registered mesh format (by extension); ``unit``: metres per
    coordinate unit (None: the format's own)."""
    from fibrelmp import registry

    suffix = path.suffix.lower()
    for fmt in registry.formats(registry.MESH):
        if suffix in fmt.extensions:
            hook = fmt.load(registry.MESH)
            if fmt.name == "opencarp":
                mesh = hook.reader(path).read()
                if unit is not None:
                    mesh.unit = unit
            else:
                mesh = hook.reader(path, unit=1.0 if unit is None else unit).read()
            return mesh
    exts = ", ".join(e for f in registry.formats(registry.MESH) for e in f.extensions)
    raise InputError(path, None, f"not a mesh file fibrelmp reads (extensions: {exts})")


def _motion(j: JsonDoc, spec: Any, folder: Path, mesh: Mesh) -> Motion | None:
    if spec is None:
        return None
    spec = _known(j, j.obj(spec, "motion"), "motion", "motion")
    if "file" in spec and "meshes" in spec:
        j.fail("motion", "give either 'file' (a .dynpt) or 'meshes', not both")
    interval = spec.get("frame_interval")
    if "file" in spec:
        from fibrelmp.mesh.opencarp.dynpt import DynptReader

        file = _file(j, spec["file"], "motion.file", folder)
        reader = DynptReader(file)
        if reader.nodes != len(mesh.points):
            raise InputError(file, None, f"{reader.nodes} nodes per frame, the mesh has {len(mesh.points)}")
        if interval is None:
            # openCARP's time unit is the millisecond (unites_t says otherwise)
            scale = 1.0 if reader.header.get("unites_t", "ms") == "s" else 1e-3
            interval = reader.inc_t * scale
            if not interval > 0:
                raise InputError(file, None, f"inc_t:{reader.inc_t:g}: the time between frames must be "
                                 "positive (or give motion.frame_interval)")
        count, files, kind = reader.count, [file], "dynpt"
    elif "meshes" in spec:
        items = j.array(spec["meshes"], "motion.meshes")
        files = [_file(j, f, f"motion.meshes[{k}]", folder) for k, f in enumerate(items)]
        count, kind = len(files), "meshes"
        if interval is None:
            j.fail("motion.frame_interval", "needed with a mesh series")
    else:
        j.fail("motion", "give 'file' (a .dynpt) or 'meshes' (one mesh file per frame)")
    interval = j.number(interval, "motion.frame_interval", positive=True)
    if count < 2:
        j.fail("motion", f"{count} frame(s): a motion needs at least two")
    return Motion(kind, files, interval, count)


def _openings(j: JsonDoc, spec: Any, mesh: Mesh, dx: float, mesh_file: Path) -> list[Opening]:
    from fibrelmp.translate.cardioproof.geometry import shell_elements

    items = j.array(spec, "openings")
    _, tags = shell_elements(mesh, mesh_file)
    out, taken, names = [], np.zeros(len(tags), bool), set()
    extent = float(np.ptp(mesh.points_m, axis=0).max())
    for k, item in enumerate(items):
        where = f"openings[{k}]"
        item = _known(j, j.obj(item, where), "openings", where)
        name = str(lammps_word(j.string(item.get("name", f"opening{k + 1}"), f"{where}.name"),
                               j.path, None, f"{where}.name"))
        if name in names:
            j.fail(f"{where}.name", f"{name!r} is used twice")
        names.add(name)
        chosen = np.zeros(len(tags), bool)
        for t in j.array(item.get("tags", []), f"{where}.tags"):
            chosen |= tags == j.integer(t, f"{where}.tags")
        for e in j.array(item.get("elements", []), f"{where}.elements"):
            e = j.integer(e, f"{where}.elements", minimum=0)
            if e >= len(tags):
                j.fail(f"{where}.elements", f"element {e}: the mesh has {len(tags)} shell elements")
            chosen[e] = True
        if not chosen.any():
            j.fail(where, "selects no shell element (give 'tags' or 'elements')")
        if (chosen & taken).any():
            j.fail(where, "shares elements with an earlier opening")
        taken |= chosen
        pressure = item.get("pressure", 0.0)
        if isinstance(pressure, list):
            rows = [j.vector(r, 2, f"{where}.pressure[{i}]", "[time, pressure]")
                    for i, r in enumerate(pressure)]
            table = np.array(rows, float).reshape(-1, 2)
            if not len(table):
                j.fail(f"{where}.pressure", "an empty table")
            if np.any(np.diff(table[:, 0]) <= 0):
                j.fail(f"{where}.pressure", "times must increase")
        else:
            table = np.array([[0.0, j.number(pressure, f"{where}.pressure")]])
        d = j.number(item.get("search_distance", 2.0 * dx), f"{where}.search_distance", positive=True)
        if not dx <= d <= extent:
            # below dx no lattice layer is within reach (the force would go to nobody); beyond the
            # mesh's size every particle is near and the box (enlarged by 3d) loses all scale
            j.fail(f"{where}.search_distance", f"{d:g} m: must be from fluid.spacing ({dx:g} m) to the "
                   f"mesh's largest extent ({extent:g} m)")
        out.append(Opening(name, np.flatnonzero(chosen), table, d))
    if taken.all():
        j.fail("openings", "every shell element is an opening: there is no wall")
    return out
