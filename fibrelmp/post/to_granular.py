"""LAMMPS dump frames -> the neutral GranularModel/GranularFrame, shared by the granular post
targets, which live in their homes and derive ``GranularTarget`` (``post --to musen``:
``translate.musen.target``, ``mdem``: ``translate.musen.mdem.target``, ``demdf``:
``translate.demdf.target``).

The model is built from the first frame (plus ``--data`` facts): one sphere per atom id,
one material per atom type.  A dump says nothing about materials or contact laws, so the
MUSEN result carries materials with only a density (from mass and radius when both are
known) and the DEMDF document only object types with radius and mass.

The data file of a fibrelmp work folder has the job's facts beside it
(``translate.work_facts``): with them the spheres are the run's -- MUSEN object ids, material
keys and names, orientations (the dump's LAMMPS rotation times the initial orientation, as
the run composes them), sphere radii, exact times -- and a DEMDF snapshot repeats the run's
document.  What no dump holds (walls, bonds, material properties, interactions) is still
missing from a MUSEN result (docs/post.md).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar, Mapping

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.granmodel import GranularFrame, GranularModel, GranularPlan, Material, Spheres, quat_multiply
from fibrelmp.post.lammps_dump.reader import Frame
from fibrelmp.post.target import DumpTarget
from fibrelmp.translate.work_facts import WorkFacts


def _vector(frame: Frame, names: tuple[str, str, str], n: int) -> np.ndarray:
    return frame.vector(*names) if frame.has(*names) else np.zeros((n, 3))


def _per_atom(facts: WorkFacts, name: str, ids: np.ndarray) -> np.ndarray | None:
    """The facts' per-atom array ``name`` for the atom ids of a frame (None: not given)."""
    values = getattr(facts, name)
    if values is None:
        return None
    if len(ids) and (ids.min() < 1 or ids.max() > len(values)):
        raise InputError(facts.path, None, f"atom id {int(ids.max())} of the dump is not in the "
                         f"job's facts ({len(values)} atoms): is --data from another run?")
    return values[ids - 1]


def model_from_frame(first: Frame, source: Path, names: Mapping[int, str], kind: str,
                     time: float, dt: float, keep_ids: bool = True,
                     facts: WorkFacts | None = None) -> GranularModel:
    """The scene of the first frame; ``keep_ids``: the atoms' ids become the spheres' ids
    (else 0..n-1, for formats whose particles have no ids); ``facts``: the job's facts (their
    MUSEN ids, keys, sphere radii and initial orientations)."""
    n = first.count
    if not first.has("radius"):
        raise InputError(source, first.line, f"--to {kind} needs sphere radii: the dump has no "
                         "'radius' (or 'diameter') column; add it to the dump or give --data")
    ids = first.column("id").astype(np.int64)
    types = first.column("type").astype(np.int64)
    contact = first.column("radius").astype(np.float64)
    radius = contact
    keys: dict[int, str] = {}
    object_ids = ids
    if facts is not None:
        radius = _per_atom(facts, "radius", ids)
        radius = contact if radius is None else radius
        keys = facts.material_keys or {}
        given = _per_atom(facts, "object_ids", ids)
        object_ids = ids if given is None else given
    mass = first.column("mass").astype(np.float64) if first.has("mass") else np.full(n, np.nan)
    tlist = sorted(set(types.tolist()))
    mat_of_type = {t: k for k, t in enumerate(tlist)}
    materials = []
    for t in tlist:
        rows = types == t
        vol = 4.0 / 3.0 * math.pi * radius[rows] ** 3
        rho = float(np.mean(mass[rows] / vol)) if np.isfinite(mass[rows]).all() else float("nan")
        name = names.get(t, f"type{t}")
        mat = Material(key=keys.get(t, f"LAMMPS_TYPE_{t}"), name=name.replace(" ", "_"), density=rho)
        if math.isfinite(rho):
            mat.props[0] = rho
        materials.append(mat)
    x = first.wrapped()
    spheres = Spheres(ids=object_ids if keep_ids else np.arange(n),
                      material=np.array([mat_of_type[t] for t in types]),
                      radius=radius, contact_radius=contact.copy(), mass=mass, position=x,
                      velocity=_vector(first, ("vx", "vy", "vz"), n),
                      omega=_vector(first, ("omegax", "omegay", "omegaz"), n),
                      quaternion=_orientation(first, facts),
                      active_start=np.full(n, time), active_end=np.full(n, np.inf))
    plan = GranularPlan(dt=dt, t_start=time, t_end=time,
                        domain=(first.lo.copy(), first.hi.copy()),
                        periodic=tuple(bool(p) for p in first.periodic))
    model = GranularModel(source=source, kind=kind, materials=materials, contacts={},
                          spheres=spheres, plan=plan, atom_ids=ids)
    return model


def _orientation(frame: Frame, facts: WorkFacts | None) -> np.ndarray:
    """(n, 4) orientations: the dump's quatw..quatk (identity without them), times the
    initial orientations of the job's facts (a LAMMPS sphere starts at the identity)."""
    n = frame.count
    q = (frame.vector("quatw", "quati", "quatj", "quatk") if frame.has("quatw", "quati", "quatj", "quatk")
         else np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)))
    q0 = None if facts is None else _per_atom(facts, "orientation", frame.column("id").astype(np.int64))
    return q if q0 is None else quat_multiply(q, q0)


def granular_frame(frame: Frame, time: float, model: GranularModel,
                   facts: WorkFacts | None = None) -> GranularFrame:
    """A dump frame as a GranularFrame; atoms missing from it count as removed, atoms the
    first frame did not have are an error (a model cannot grow)."""
    ids = model.atom_ids
    if model.atom_order is None:
        model.atom_order = np.argsort(ids)
    order = model.atom_order
    fid = frame.column("id").astype(np.int64)
    pos = np.searchsorted(ids, fid, sorter=order)
    pos = np.minimum(pos, len(ids) - 1)
    rows = order[pos]
    if len(fid) and not np.array_equal(ids[rows], fid):
        new = fid[ids[rows] != fid][0]
        raise InputError(frame.source, frame.line, f"atom {new} appears after the first frame: "
                         "MUSEN/DEMDF results need every object present from the start")
    n = frame.count
    out = GranularFrame(time=time, step=frame.step, sphere_rows=rows, position=frame.wrapped(),
                        velocity=_vector(frame, ("vx", "vy", "vz"), n),
                        omega=_vector(frame, ("omegax", "omegay", "omegaz"), n),
                        force=_vector(frame, ("fx", "fy", "fz"), n),
                        quaternion=_orientation(frame, facts))
    if "sfx" in frame.columns:       # fix musen/leapfrog: the force cmusen saves, as the run writes
        out.saved_force = _vector(frame, ("sfx", "sfy", "sfz"), n)
    if "d_musen_temperature" in frame.columns:    # fix musen/field heat: MUSEN's temperature
        out.temperature = np.asarray(frame.column("d_musen_temperature"), np.float64)
    return out


def spheres_only(work: Path, frame: Frame) -> str:
    """What a MUSEN result from a work folder's dump lacks against the run's own result."""
    from fibrelmp.translate.granular.mesh import MESH_NAME
    from fibrelmp.translate.granular_job import BONDS_NAME, STRESS_CONTACTS_NAME, TILES_NAME

    walls = (work / MESH_NAME).exists() or (work / TILES_NAME).exists() or \
        any(name.startswith("v_w") for name in frame.columns)
    missing = (["its walls (triangles, geometries)"] if walls else []) + \
        (["its bonds"] if (work / BONDS_NAME).exists() else []) + \
        (["the stress tensors (36, 42: from the contacts)"] if (work / STRESS_CONTACTS_NAME).exists() else [])
    return (f"the result has the run's spheres only: {', '.join(missing + [''])}material properties "
            "other than the density and the interactions are not in a dump, and the PBC line comes from "
            "the dump's box; `fibrelmp run` writes the complete result (docs/post.md, fibrelmp's own "
            "work dumps)")


class GranularTarget(DumpTarget):
    """MUSEN result / DEMDF snapshots through the neutral granular model and the same
    writers ``fibrelmp run`` uses (``result_writer``)."""

    lookahead = 2                 # the save interval comes from the first two frames
    # what model_from_frame and granular_frame take from a dump
    finite_columns = frozenset({"vx", "vy", "vz", "omegax", "omegay", "omegaz", "fx", "fy", "fz",
                                "sfx", "sfy", "sfz", "quatw", "quati", "quatj", "quatk", "radius", "diameter", "mass",
                                "d_musen_temperature"})
    kind: ClassVar[str]
    keeps_ids: ClassVar[bool]

    def start(self, first: list[Frame]) -> None:
        times = [self.time_of(f) for f in first]
        dt = times[1] - times[0] if len(times) > 1 else 1.0
        facts = self.context.facts
        # a MUSEN result from a DEMDF job (or back) takes the names only
        self.facts = facts if facts is not None and facts.kind == self.kind else None
        self.model = model_from_frame(first[0], Path(self.context.source), self.context.type_names,
                                      self.kind, times[0], dt, self.keeps_ids, self.facts)
        if self.facts is not None and self.facts.path is not None and self.kind == "musen":
            self.context.warn("spheres only", spheres_only(self.facts.path.parent, first[0]))
        self.out = self.adopt(self.result_writer(self.model, dt))

    def result_writer(self, model: GranularModel, dt: float) -> Writer:
        raise NotImplementedError

    def write_frame(self, frame: Frame) -> None:
        self.out.add(granular_frame(frame, self.time_of(frame), self.model, self.facts))

    def end(self) -> None:
        if self.count:
            for kind, text in self.model.warnings:
                self.context.warn(kind, text)


class SingleFileTarget(GranularTarget):
    """One result file: ``<base>`` as given when it has a suffix, else ``<base>`` plus the
    format's usual one (``-o out/run`` writes ``out/run.txt`` / ``out/run.mdem``)."""

    suffix: ClassVar[str]

    def __init__(self, base: str | Path, context=None, *, force: bool = True):
        super().__init__(self.named(Path(base)), context, force=force)

    @classmethod
    def named(cls, base: Path) -> Path:
        return base if base.suffix else base.with_name(base.name + cls.suffix)

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        return [cls.named(base)]
