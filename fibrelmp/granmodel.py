"""The neutral model for granular (DEM) inputs: MUSEN scenes and DEMDF documents.

Readers fill a ``GranularModel``; ``translate.granular_job`` turns it into a LAMMPS job
(``units si``-style consistent units, ``pair_style granular``); the writers in ``post/``
turn LAMMPS frames back into MUSEN time points or DEMDF snapshots.  No format-to-format
shortcuts: everything a writer needs that LAMMPS does not compute (names, keys, the
original document) travels in this model.

Conventions: arrays are numpy, rows are objects in the order the reader met them;
LAMMPS atom id = sphere row + 1.  ``inf`` is "never" for activity ends.  Units are whatever
the input uses consistently (MUSEN: SI; DEMDF: dimensionless) - the translator never
converts, it only has to be self-consistent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, ClassVar

import numpy as np

from fibrelmp.particles import ModelCounts, ParticleModel, ParticleView, TimeScale
from fibrelmp.sanity import hertz_contact_time, pair_speed, speed_bounds

# objects all dynamic generators of one run may ask for: fibrelmp reserves a LAMMPS atom (and
# its rows) for each before the run, so a hostile rate cannot make it allocate gigabytes
MAX_GENERATED = 10_000_000


@dataclass
class Material:
    """A material / object type.  ``props`` keeps every numbered property the input had
    (MUSEN property ids: 0 density, 2 viscosity, 7 E, 8 normal strength, 9 tangential
    strength, 10 Poisson ratio, ...), so writers can copy it through unchanged."""

    key: str
    name: str
    density: float = float("nan")
    youngs: float = float("nan")           # E [Pa]
    poisson: float = float("nan")          # nu
    normal_strength: float = float("nan")  # sigma_n [Pa] (bond breakage)
    shear_strength: float = float("nan")   # tau_s [Pa]
    props: dict[int, float] = field(default_factory=dict)

    @property
    def shear_modulus(self) -> float:
        return self.youngs / (2.0 * (1.0 + self.poisson))


@dataclass
class ContactLaw:
    """One unordered material pair's contact parameters, in the *effective* (already
    mixed) form the source code uses:  F_n = 4/3 E* sqrt(R*) d^1.5 (Hertz) with damping
    from ``restitution``; tangential stiffness 8 G* a, Coulomb limit ``friction``·|F_n|;
    rolling torque ``rolling_friction``·|F_n|·R_i (MUSEN's constant-torque rolling)."""

    youngs_eff: float          # E*
    shear_eff: float           # G*  (0 = frictionless, no tangential spring)
    restitution: float         # e in (0, 1]
    friction: float = 0.0      # mu sliding
    rolling_friction: float = 0.0
    # the MUSEN PP model it stands for (translate/granular/models; None: a law no MUSEN model
    # chose, DEMDF's Hertz law)
    model: str | None = None


@dataclass
class SolidBondLaw:
    """The law a scene's solid bonds follow (MUSEN type 9), naming its MUSEN SB model (the
    module in translate/granular/models that set it) and the form ``granular.bonds`` renders."""

    model: str | None = None   # MUSEN's name, e.g. "ModelSBKelvin" (None: no SB model chosen)
    # "elastic" (ModelSBElastic) | "kelvin" (ModelSBKelvin) | "plastic"
    # (ModelSBElasticPerfectlyPlastic) | "linear_plastic" (ModelSBLinearPlastic) | "creep"
    # (ModelSBCreep) | "weakening" (ModelSBWeakening) | "aerogel" (ModelSBAerogel) | "concrete"
    # (ModelSBPlasticConcrete)
    form: str = "elastic"
    max_damp_ratio: float = 1.0   # ModelSBKelvin's MAX_DAMP_RATIO (0: no cap)
    breakage: int = 1          # its stress criterion, CONSIDER_BREAKAGE (a later law's; the
                               # first law's is the plan's bond_breakage)
    # the model's parameters as MUSEN names them (the .mdem model manager; the plastic laws'
    # bond_style words)
    parameters: dict[str, float] = field(default_factory=dict)

    @property
    def breaks_anyway(self) -> bool:
        """Whether the law breaks bonds whatever its stress criterion: the plastic and creep
        laws test a fracture strain in tension, the aerogel law its force."""
        return self.form in ("plastic", "creep", "aerogel")

    @property
    def needs_yield(self) -> bool:
        """Whether the law uses the bond material's yield strength (property 15)."""
        return self.form in ("plastic", "creep", "weakening", "concrete")


@dataclass
class Spheres:
    ids: np.ndarray            # (n,) int64 source ids (MUSEN object ids / DEMDF array index)
    material: np.ndarray       # (n,) int index into GranularModel.materials
    radius: np.ndarray         # (n,)
    contact_radius: np.ndarray # (n,) (MUSEN flag 30; equal to radius elsewhere)
    mass: np.ndarray           # (n,)
    position: np.ndarray       # (n,3)
    velocity: np.ndarray       # (n,3)
    omega: np.ndarray          # (n,3)
    quaternion: np.ndarray     # (n,4) w x y z
    active_start: np.ndarray   # (n,)
    active_end: np.ndarray     # (n,) inf = active for ever
    compound_key: list[str] | None = None   # per-sphere key as written (MUSEN 23)
    temperature: np.ndarray | None = None   # (n,) K, MUSEN 37 (simulated by ModelEFHeatTransfer)

    @property
    def count(self) -> int:
        return int(self.ids.shape[0])


@dataclass
class SolidBonds:
    """Cylindrical solid bonds between two spheres (MUSEN type 9)."""

    ids: np.ndarray            # (m,) int64 source ids
    pair: np.ndarray           # (m,2) sphere *rows* (not ids)
    material: np.ndarray       # (m,) material index
    diameter: np.ndarray       # (m,)
    length0: np.ndarray        # (m,) stored initial length L0
    active_start: np.ndarray
    active_end: np.ndarray
    compound_key: list[str] | None = None
    # state carried over from a later time point of a result file (optional)
    force: np.ndarray | None = None             # (m,3)
    tangential_overlap: np.ndarray | None = None
    source_line: np.ndarray | None = None       # (m,) line of each bond in a text scene

    @property
    def count(self) -> int:
        return int(self.ids.shape[0])


@dataclass
class Triangles:
    """Triangular wall elements (MUSEN type 14)."""

    ids: np.ndarray            # (k,) int64
    material: np.ndarray       # (k,) material index
    vertices: np.ndarray       # (k,3,3) V1 V2 V3
    velocity: np.ndarray       # (k,3)
    active_start: np.ndarray
    active_end: np.ndarray
    compound_key: list[str] | None = None

    @property
    def count(self) -> int:
        return int(self.ids.shape[0])


@dataclass
class MotionInterval:
    """Time-dependent rigid motion (MUSEN 26 type 1): in [t_begin, t_end) the geometry
    translates with ``velocity`` and rotates with ``angular_velocity`` about ``centre``."""

    t_begin: float
    t_end: float
    velocity: np.ndarray           # (3,)
    centre: np.ndarray             # (3,)
    angular_velocity: np.ndarray   # (3,)


@dataclass
class ForceInterval:
    """Force-dependent rigid motion (MUSEN 26 types 2 and 3, ``GeometryMotion.h``
    SForceMotionInterval): the geometry moves with ``velocity`` until the z component of the
    total force on its walls passes ``limit`` (above it when ``limit_max``, else below it)."""

    limit: float
    limit_max: bool
    velocity: np.ndarray           # (3,)
    centre: np.ndarray             # (3,)
    angular_velocity: np.ndarray   # (3,)


@dataclass
class Geometry:
    """A named group of triangles that moves as one body (MUSEN 25/26/27)."""

    name: str
    key: str
    mass: float
    free: tuple[bool, bool, bool]
    rotate_around_centre: bool | None       # None: old 6-field line without the flag
    motion_type: int                         # 0 none, 1 time, 2 force, 3 constant force
    motion: list[MotionInterval]
    triangle_rows: np.ndarray                # (k,) rows into GranularModel.triangles
    raw_lines: list[str] = field(default_factory=list)  # 25/26/27 lines as read, for write-back
    force_motion: list[ForceInterval] = field(default_factory=list)   # motion types 2 and 3


@dataclass
class Plane:
    """An infinite wall plane; ``normal`` points into the domain (DEMDF walls)."""

    normal: np.ndarray     # (3,) unit
    point: np.ndarray      # (3,)
    material: int          # material / object-type index of the wall


@dataclass
class ExternalField:
    """One MUSEN external-force (EF) model acting on every sphere (fibrelmp's ``fix
    musen/field``, translate/granular/models/ef_*.py)."""
    model: str                      # MUSEN's name, e.g. "ModelEFViscousField"
    parameters: dict[str, float]    # its parameters (MUSEN's names)
    fix_args: str                   # what follows ``musen/field``: the law and its numbers
    # the law changes the spheres' temperature (then the job defines fix musen/heat, owner of
    # the heat flux and the temperature update, and keeps the temperature in d_musen_temperature)
    heat: bool = False
    style: str = "musen/field"      # its LAMMPS fix style


@dataclass
class GranularPlan:
    dt: float
    t_start: float
    t_end: float
    save_every_steps: int | None = None     # one of these two says when frames are saved
    save_every_time: float | None = None
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    domain: tuple[np.ndarray, np.ndarray] | None = None   # (lo, hi): particles leaving are removed
    periodic: tuple[bool, bool, bool] = (False, False, False)
    periodic_box: tuple[np.ndarray, np.ndarray] | None = None
    periodic_velocity: np.ndarray | None = None   # MUSEN's moving periodic box: faces move out at v
    bond_breakage: int = 1                  # MUSEN CONSIDER_BREAKAGE: 0 none, 1 combined, 2 separate
    bond_law: SolidBondLaw = field(default_factory=SolidBondLaw)   # the solid bonds' law
    # further SB models acting on every bond after bond_law, in cmusen's order (cmusen runs
    # every active model of a kind; each continues the bond's state and may break it)
    then_bond_laws: list[SolidBondLaw] = field(default_factory=list)
    contacts_between_bonded: bool = True    # MUSEN default
    # False: spheres never touch each other (a cmusen job with no PP model runs so)
    particle_contacts: bool = True
    # MUSEN's active EF models, in cmusen's order (each adds its force in turn, before all others)
    external_fields: list[ExternalField] = field(default_factory=list)
    # MUSEN's contact-list update (fix musen/verlet): Verlet distance = coeff x the smallest
    # contact radius, auto-adjusted or not (its defaults; a .mdem or VERLET_COEF/AUTO set them)
    verlet_coeff: float = 2.0
    verlet_auto: bool = True
    velocity_limit: float | None = None     # MUSEN's particle velocity limit (m/s; None: none)
    # MUSEN's variable time step (MAX_PART_MOVE m, STEP_INC_FACTOR); None: the fixed step
    variable_step: tuple[float, float] | None = None
    # MUSEN's stop criterion BROKEN_BONDS N: at a save with more than N bonds broken since the
    # start, one more step, its frame, the end (None: no criterion)
    stop_broken_bonds: int | None = None
    # the particle-particle law's contact duration (m*, R*, E*, approach speed) when it is not
    # Hertz's (set by its model in translate/granular/models; None: Hertz)
    pp_contact_time: Callable[[float, float, float, float], float] | None = None
    pp_contact_law: str = "Hertz"           # its name in check's contact-time line
    pw_contact_time: Callable[[float, float, float, float], float] | None = None   # the same for
    pw_contact_law: str = "Hertz"                                                 # sphere-wall
    dimension: int = 3
    # MUSEN's active dynamic generators (translate/musen/mdem/generators.py Inlet): fix musen/inlet
    inlets: list = field(default_factory=list)
    inlet_rows: int | None = None   # the first sphere row reserved for them (inlets.reserve_rows)
    # generators of agglomerates: (generator, first sphere row, first bond row) each
    # (inlets.reserve_agglomerate_rows), and the first MUSEN id of what they make
    inlet_layout: list | None = None
    inlet_next_id: int = 0
    # generators of agglomerates: draw cmusen's own random numbers, glibc's rand() seeded from
    # this time(0) of a cmusen run (fix musen/inlet musen_rand; None: fibrelmp's seeded stream)
    inlet_musen_time0: int | None = None
    # (dt, t_end) -> their GenerationEvents on cmusen's summed clock (generation_schedule)
    inlet_schedule: Callable[[float, float], list] | None = None

    def bonds_may_break(self) -> bool:
        """Whether any of the solid bonds' laws has a breakage criterion."""
        return (int(self.bond_breakage) != 0 or self.bond_law.breaks_anyway
                or any(law.breakage or law.breaks_anyway for law in self.then_bond_laws))

    def bond_laws_use(self, form: str) -> bool:
        """Whether any of the solid bonds' laws is ``form`` (SolidBondLaw.form)."""
        return any(law.form == form for law in (self.bond_law, *self.then_bond_laws))

    def bond_laws_need_yield(self) -> bool:
        """Whether any of the solid bonds' laws uses the yield strength."""
        return any(law.needs_yield for law in (self.bond_law, *self.then_bond_laws))


class SourceRecord:
    """What a format keeps of its source to write it back (MUSEN's scene lines, a DEMDF
    document): each format's home derives its own record (``translate.musen.scene_record.
    MusenSceneRecord``, ``translate.demdf.record.DemdfDocument``)."""

    def post_facts(self) -> dict[str, Any] | None:
        """What ``post`` needs of it beside the job's data file (``WorkFacts``; JSON)."""
        return None


@dataclass
class LiquidBond:
    """A MUSEN liquid bond (object type 13): it exerts no force, as in cmusen 1.74.2 (MUSEN
    e0ff360's ModelLBCapilarViscous is a no-op); kept for the result files, which hold its
    activity as cmusen writes it (translate/musen/liquid_bonds.py)."""

    id: int                    # source id
    left: int                  # the two spheres' source ids
    right: int
    diameter: float
    length0: float
    key: str                   # its material's key
    active_start: float
    active_end: float


@dataclass
class ModelChoice:
    """A physics model a scene runs (``translate/granular/models``, the one place that knows
    each model): MUSEN's name and kind, its checked parameters and where it was chosen."""

    name: str                  # MUSEN's, e.g. "ModelPPHertzMindlin"
    kind: str                  # "PP", "PW", "SB", "LB", "EF"
    parameters: dict[str, float]
    source: Path | None = None  # the job script or .mdem that chose it
    line: int | None = None     # its MODEL_ line (None: a .mdem's stored model)


@dataclass
class GranularModel(ParticleModel):
    """A DEM scene (MUSEN, DEMDF)."""

    kind: str                              # "musen" | "demdf"
    materials: list[Material]
    contacts: dict[tuple[int, int], ContactLaw]   # key (a, b) with a <= b, material indices
    spheres: Spheres
    plan: GranularPlan
    bonds: SolidBonds | None = None
    triangles: Triangles | None = None
    geometries: list[Geometry] = field(default_factory=list)
    planes: list[Plane] = field(default_factory=list)
    # what the format keeps of its source to write it back (MUSEN scene lines, DEMDF document)
    origin: SourceRecord | None = None
    liquid_bonds: list[LiquidBond] = field(default_factory=list)
    models: dict[str, ModelChoice] = field(default_factory=dict)   # kind -> chosen model
    # further PP, PW and EF models acting after models[kind], in cmusen's order
    # (cmusen runs every selected model of a kind in turn; forces add)
    later_models: list[ModelChoice] = field(default_factory=list)
    # post: the dump's atom ids of the spheres and their sort order (post.to_granular)
    atom_ids: np.ndarray | None = None
    atom_order: np.ndarray | None = None

    particle_noun: ClassVar[str] = "spheres"
    # measured on 2 cores, docs/performance.md#ranks-and-threads
    min_per_rank: ClassVar[int | None] = 1_000
    time_scale_title: ClassVar[str | None] = "Hertz contact time"

    def contact(self, a: int, b: int) -> ContactLaw:
        return self.contacts[(min(a, b), max(a, b))]

    def particles_view(self) -> ParticleView:
        s = self.spheres
        return ParticleView(s.ids, s.position, s.velocity, s.radius, s.mass, s.material,
                            {"omega": s.omega, "quaternion": s.quaternion})

    @property
    def particle_count(self) -> int:
        return self.spheres.count

    def counts(self) -> ModelCounts:
        bonds = 0 if self.bonds is None else self.bonds.count
        triangles = 0 if self.triangles is None else self.triangles.count
        return ModelCounts(bonds, 0, triangles + len(self.planes), len(self.materials))

    def given_time_step(self) -> float:
        return self.plan.dt

    def planned_steps(self) -> int:
        span = (self.plan.t_end - self.plan.t_start) / self.plan.dt
        # beyond LAMMPS's step counter (2^63-1): sanity refuses it
        return int(math.ceil(span)) if math.isfinite(span) else 2 ** 63

    def time_scale(self) -> TimeScale | None:
        """The shortest contact duration (``contact_time``), when finite."""
        with np.errstate(all="ignore"):
            found = contact_time(self)
        if found is None or not math.isfinite(found[0]):
            return None
        tc, pair, law = found
        return TimeScale("contact time", tc, f"{law}, {pair}, fastest approach in the input",
                         f"contact time {tc:.3g} ({law}, {pair}, fastest approach in the input)",
                         f"{law} contact time {tc:.3g}: contacts will be poorly resolved")

    def run_time_step(self, job: Any) -> float:
        return float(job.dt)

    def final_gather(self, lmp: Any) -> dict[str, Any]:
        from fibrelmp.record import gather_atoms

        return {"radius": gather_atoms(lmp, "radius", 1, 1)}

    def final_figures(self, job: Any, ids: np.ndarray, x: np.ndarray, box: tuple,
                      gathered: dict[str, Any]) -> dict[str, Any]:
        from fibrelmp.record import largest_overlap

        spheres = np.isin(ids, np.asarray(job.sphere_rows, np.int64) + 1)
        if job.domain_lo is not None:          # beyond the domain: removed (the frames' rule)
            for a in np.flatnonzero(job.removal_axes):
                spheres &= (x[:, a] >= job.domain_lo[a]) & (x[:, a] <= job.domain_hi[a])
        radius = gathered["radius"]
        return {"overlap": largest_overlap(ids[spheres], x[spheres], radius[spheres], *box)}

    def summary_figures(self, job: Any, final: dict[str, Any], last: dict | None,
                        tally: dict | None) -> dict[str, Any]:
        from fibrelmp.record import line_count, thermo_int

        tally = tally or {}
        out: dict[str, Any] = {
            "particles": {"kind": "spheres", "start": len(job.sphere_rows), "end": tally.get("spheres"),
                          "generated": tally.get("generated", 0),
                          "removed_at_activity_end": tally.get("activity_end"),
                          "left_domain": tally.get("left_domain")},
            "contacts": thermo_int(last, "Contacts"),
            "max_overlap": final["overlap"]}
        nbonds = len(job.bond_rows)
        if nbonds:
            out["bonds"] = {"start": nbonds, "end": tally.get("bonds"),
                            "broken": line_count(job.breaks) if job.breaks is not None else 0}
        if tally.get("temperature"):
            # a heat model: the spheres' temperatures at the frames this session saved (every
            # `every`-th one and the last: a long run's summary stays small)
            out["temperature"] = {"unit": "K", "every": tally.get("temperature_every", 1),
                                  "frames": tally["temperature"]}
        return out


def extent(model: GranularModel) -> np.ndarray:
    """The box gravity can accelerate spheres over: the domain, else the spheres' and walls'
    bounding box grown by a diameter."""
    if model.plan.domain is not None:
        return model.plan.domain[1] - model.plan.domain[0]
    s = model.spheres
    parts = [s.position] + [p.point[None, :] for p in model.planes]
    if model.triangles is not None and model.triangles.count:
        parts.append(model.triangles.vertices.reshape(-1, 3))
    points = np.vstack(parts)
    return points.max(axis=0) - points.min(axis=0) + 2 * float(s.contact_radius.max(initial=0))


def contact_time(model: GranularModel) -> tuple[float, str, str] | None:
    """The shortest contact duration (Hertz's, or the PP / PW model's ``plan.pp_contact_time``,
    ``plan.pw_contact_time``) of the contacts the input can have, at the fastest
    approach: for each material pair with a contact law, the smallest spheres of each
    (m* = m1 m2 / (m1 + m2), R* = r1 r2 / (r1 + r2); a sphere-sphere pair of one material
    needs two spheres of it) approaching at the sum of the two fastest speed bounds, and
    for a wall material, the smallest sphere (m* = m, R* = r) at its material's fastest
    bound (``sanity.speed_bounds``).  Where nothing can move (no speed, no gravity), at an
    approach speed of 1.  (time, "material-material", law); None when there are no spheres.
    DEMDF's reader sizes its contact stiffness and time step by this same figure."""
    s = model.spheres
    if s.count == 0:
        return None
    bounds = speed_bounds(s.velocity, model.plan.gravity, extent(model))
    walls = {int(p.material) for p in model.planes}
    if model.triangles is not None and model.triangles.count:
        walls |= {int(m) for m in np.unique(model.triangles.material)}
    smallest: dict[int, tuple[float, float, np.ndarray]] = {}
    for mat in np.unique(s.material).tolist():
        rows = np.flatnonzero(s.material == mat)
        # the contact time grows as (m^2 / r)^(1/5): the smallest sphere of a material
        k = rows[int(np.argmin(s.mass[rows] ** 2 / s.contact_radius[rows]))]
        smallest[mat] = (float(s.mass[k]), float(s.contact_radius[k]), bounds[rows])
    partners = []                      # (m*, R*, E*, approach speed, name, duration law)
    pp_time = model.plan.pp_contact_time or hertz_contact_time
    pp_law = model.plan.pp_contact_law if model.plan.pp_contact_time else "Hertz"
    pw_time = model.plan.pw_contact_time or hertz_contact_time
    pw_law = model.plan.pw_contact_law if model.plan.pw_contact_time else "Hertz"
    for (a, b), law in model.contacts.items():
        if not law.youngs_eff > 0:
            continue
        name = f"{model.materials[a].name}-{model.materials[b].name}"
        if a in smallest and b in smallest:
            (ma, ra, va), (mb, rb, vb) = smallest[a], smallest[b]
            partners.append((ma * mb / (ma + mb), ra * rb / (ra + rb), law.youngs_eff,
                             pair_speed(va, va if a == b else vb), name, pp_time, pp_law))
        for sphere, wall in ((a, b), (b, a)):
            if sphere in smallest and wall in walls:
                m, r, v = smallest[sphere]
                partners.append((m, r, law.youngs_eff, pair_speed(v, None), name, pw_time, pw_law))
    possible = [p for p in partners if p[3] > 0] or [p[:3] + (1.0,) + p[4:] for p in partners]
    best = None
    for m_eff, r_eff, e_star, speed, name, duration, law in possible:
        tc = duration(m_eff, r_eff, e_star, speed)
        if best is None or tc < best[0]:
            best = (tc, name, law)
    return best


def quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a (x) b of (n,4) w,x,y,z quaternions (a sphere's orientation is its
    LAMMPS rotation since the start times its initial orientation: the run and ``post`` use
    this one function, so both give the same bits)."""
    w1, v1 = a[:, :1], a[:, 1:]
    w2, v2 = b[:, :1], b[:, 1:]
    w = w1 * w2 - (v1 * v2).sum(1, keepdims=True)
    v = w1 * v2 + w2 * v1 + np.cross(v1, v2)
    return np.hstack([w, v])


def hertz_effective(m1: Material, m2: Material) -> tuple[float, float]:
    """MUSEN's mixing (SimplifiedScene::CalculateInteractionProperty): E*, G*."""
    e_star = 1.0 / ((1 - m1.poisson ** 2) / m1.youngs + (1 - m2.poisson ** 2) / m2.youngs)
    g_star = 1.0 / ((2 - m1.poisson) / m1.shear_modulus + (2 - m2.poisson) / m2.shear_modulus)
    return e_star, g_star


@dataclass
class GranularFrame:
    """One saved time point as LAMMPS computed it, in model terms.

    Sphere arrays are aligned with ``sphere_rows`` (spheres still in the simulation; removed
    ones are absent).  Bond arrays are aligned with the model's bond rows; ``bond_alive``
    False means broken or removed (its activity end is then ``bond_end_time``).  Triangle
    arrays are aligned with the model's triangle rows (vertices where the wall is now).
    """

    time: float
    step: int
    sphere_rows: np.ndarray          # (n',) int rows into GranularModel.spheres
    position: np.ndarray             # (n',3)
    velocity: np.ndarray             # (n',3) at the same time as position
    omega: np.ndarray                # (n',3)
    force: np.ndarray                # (n',3) total force
    quaternion: np.ndarray           # (n',4)
    bond_alive: np.ndarray | None = None       # (m,) bool
    bond_end_time: np.ndarray | None = None    # (m,) break / removal time, inf if alive
    bond_force: np.ndarray | None = None       # (m,3) force on the bond's first sphere
    bond_saved: np.ndarray | None = None       # (m,) bool: bonds whose values the save holds
                                               # (MUSEN: alive, or broken since the previous
                                               # save, as they broke); None: bond_alive
    bond_torque: np.ndarray | None = None      # (m,) |total torque| if known
    bond_tangential_overlap: np.ndarray | None = None   # (m,3) if known
    triangle_vertices: np.ndarray | None = None # (k,3,3)
    triangle_velocity: np.ndarray | None = None # (k,3)
    triangle_force: np.ndarray | None = None    # (k,3) force the particles exert on each triangle
    saved_triangle_force: np.ndarray | None = None   # (k,3) what cmusen saves now (MUSEN jobs
                                                     # with presaves: the previous evaluation's)
    temperature: np.ndarray | None = None      # (n',) K, when a heat model changes it
    stress_tensor: np.ndarray | None = None    # (n',9) MUSEN's stress tensor, row-major
                                               # (granular_run.stress), when the job computes it
    saved_force: np.ndarray | None = None      # (n',3) the force cmusen saves now (MUSEN's
                                               # integrator: the previous evaluation's)

    # what a MUSEN result saves (cmusen's values where the frame has them, else the frame's)
    def sphere_force_as_saved(self) -> np.ndarray:
        """(n',3) the sphere forces a MUSEN result saves."""
        return np.asarray(self.force if self.saved_force is None else self.saved_force,
                          np.float64).reshape(-1, 3)

    def triangle_force_as_saved(self) -> np.ndarray | None:
        """(k,3) the wall triangles' forces a MUSEN result saves (None: not known)."""
        return self.triangle_force if self.saved_triangle_force is None else self.saved_triangle_force

    def bonds_as_saved(self, count: int) -> np.ndarray:
        """(count,) bool: the bonds whose values a MUSEN result saves (``bond_saved``, else
        the alive ones, else all)."""
        held = self.bond_alive if self.bond_saved is None else self.bond_saved
        return np.ones(count, bool) if held is None else np.asarray(held, bool)
