"""Turn a ``GranularModel`` (MUSEN scene / DEMDF document) into a LAMMPS job on disk.

``in.lammps`` + ``data.lammps`` are LAMMPS (GRANULAR + BPM packages, MISC for fix evaporate,
PLUGIN only when a fibrelmp style is used; no Python hooks):
``lmp -in in.lammps`` inside the job folder replays exactly what ``fibrelmp run`` executes
line by line.  The mapping and every deviation from MUSEN are described in docs/granular.md.
``build_granular_job`` runs the steps of the ``translate.granular`` package in order (their
checks and warnings come in that order); the names other modules use from them are
importable from here as well.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp import lammps_styles
from fibrelmp.lammps_text import LammpsText, comment_text, lammps_path, template_environment
from fibrelmp.textio import atomic_write
from fibrelmp.translate.granular.bonds import (GEOMETRY_FIX, GEOMETRY_NAME, PARTNERS, VALUES, BondGeometry,
                                              SimulatedBonds, bond_geometry, select_bonds)
from fibrelmp.translate.granular.box import BoxAxes, box_axes, box_commands, domain_bounds, fit_box, periodic_axes
from fibrelmp.translate.granular.contacts import (STOCK_PAIR_WARNING, law_args, pair_coeff_lines,
                                                  rolling_spring, stock_pair_deviates)
from fibrelmp.translate.granular.data import write_data
from fibrelmp.translate.granular.reach import Travel, speed_bound
from fibrelmp.translate.granular.musen_clock import MusenClock
from fibrelmp.translate.granular.schedule import (STOP_LABEL, RunTime, compress_ids, run_time, save_steps,
                                                  schedule, variable_schedule, variable_step_refusals,
                                                  with_presaves, with_stop_criterion)
from fibrelmp.translate.granular.fields import TEMPERATURE, field_commands, uses_temperature
from fibrelmp.translate.granular.inlets import LOG_NAME as INLET_LOG
from fibrelmp.translate.granular.inlets import inlet_bond_capacity, inlet_bond_reach, inlet_commands
from fibrelmp.translate.granular.spheres import SimulatedSpheres, select_spheres
from fibrelmp.translate.granular.tiles import TILE_MASS_FACTOR, WallTiles, place_tiles, tile_estimate, tile_types
from fibrelmp.translate.granular.verlet import VerletSchedule, musen_verlet
from fibrelmp.translate.granular import models as physics
from fibrelmp.translate.granular.mesh import MESH_FIX, MESH_FORCES_NAME, MESH_NAME, mesh_rows, write_mesh
from fibrelmp.translate.granular.walls import (WallPlan, describe_walls, plan_walls, wall_commands,
                                               wall_warnings)
from fibrelmp.translate.lammps_format import float_text
from fibrelmp.translate.steps import SaveSteps
from fibrelmp.translate.work_facts import VARIABLE_CLOCK, WorkFacts, write_facts

__all__ = ["BONDS_NAME", "BREAKS_NAME", "CONTACTS_NAME", "DATA_NAME", "FRAMES_NAME", "SCRIPT_NAME", "TILES_NAME",
           "GranularJob", "WallPlan", "build_granular_job", "describe_walls", "law_args", "plan_walls",
           "rolling_spring", "speed_bound", "tile_estimate", "write_granular_job"]

SCRIPT_NAME = "in.lammps"
DATA_NAME = "data.lammps"
FRAMES_NAME = "frames.dump"
BONDS_NAME = "bonds.dump"
TILES_NAME = "walls.dump"
BREAKS_NAME = "breaks.dump"
CONTACTS_NAME = "contacts.dump"
# MUSEN's stress tensor: the previous evaluation's contacts and sphere-wall contacts (fix
# musen/wall/mesh), one step before each frame (schedule.with_presaves); its bonds are the
# frame's bonds.dump, written there too
STRESS_CONTACTS_NAME = "stress_contacts.dump"
STRESS_WALLS_NAME = "stress_walls.dump"
CLOCK_NAME = VARIABLE_CLOCK      # variable time step: "step time dt" of every frame (fix musen/leapfrog)


@dataclass
class GranularJob:
    folder: Path
    script: Path
    data: Path
    total_steps: int
    save_steps: SaveSteps                # lazy: iterate, len(), `in`
    frames: Path                     # spheres, one write_dump per saved frame
    bond_dump: Path | None           # alive bonds (compute bond/local) per frame
    tile_dump: Path | None           # wall tiles (forces) per frame
    breaks: Path | None              # one line "step id1 id2" per broken bond, every step
    walls: list[tuple[str, str]]     # geometry name -> representation
    dt: float
    t_start: float
    clock: MusenClock | None         # MUSEN: its summed time at a step (else t_start + step dt)
    sphere_rows: np.ndarray          # rows simulated (LAMMPS id = row + 1)
    outside_rows: np.ndarray         # active at t_start but outside the domain: dropped
    late_rows: np.ndarray            # active only after t_start: not simulated
    bond_rows: np.ndarray            # bonds simulated
    deletions: list[tuple[int, np.ndarray]]   # (step, sphere rows) removed at activity end
    wall_plans: list[WallPlan]
    domain_lo: np.ndarray | None     # removal box (non-periodic axes), None: nothing removed
    domain_hi: np.ndarray | None
    removal_axes: np.ndarray         # (3,) bool: axes where leaving the box removes a sphere
    frame_columns: list[str] = field(default_factory=list)
    warnings: list[tuple[str, str]] = field(default_factory=list)
    wall_forces: Path | None = None  # fix musen/wall/mesh: per-triangle forces per frame
    mesh_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))   # model row of each
    geometry: Path | None = None     # per-atom bond geometry (musen/elastic), beside the data file
    contacts: Path | None = None     # sphere-sphere contacts per frame (compute pair/local)
    inlet_log: Path | None = None    # fix musen/inlet: "STEP ID" per inserted sphere
    # bond rows reserved for generated agglomerates (inlets.reserve_agglomerate_rows)
    inlet_bond_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    type_materials: dict[int, int] | None = None   # LAMMPS sphere type -> material
    variable_clock: Path | None = None   # variable time step: each frame's step, time and dt
    # MUSEN's stress tensor: contacts one step before each frame (granular_run.stress), where
    # bond_dump is written then too (stress_contacts set: presaves)
    stress_contacts: Path | None = None
    stress_walls: Path | None = None

    @property
    def inputs(self) -> list[Path]:
        """The files the script reads (a checkpoint is refused when one changed)."""
        return [self.data] + ([self.geometry] if self.geometry is not None else [])


def _bond_style_law(model: GranularModel) -> tuple[str, str]:
    """bond_style musen/elastic's laws; a heat law gets the bonds' thermal conductivity first."""
    from fibrelmp.translate.granular.models.sb_heat_conduction import set_conductivity
    from fibrelmp.translate.granular.models.sb_thermal import set_expansion
    set_conductivity(model)
    set_expansion(model)
    return physics.bond_style_law(model.plan)


def write_granular_job(model: GranularModel, folder: str | Path) -> GranularJob:
    """Write ``in.lammps`` + ``data.lammps`` for ``model`` into ``folder``."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(folder, None, f"cannot create job folder: {exc.strerror or exc}") from None
    job, script, write_data = build_granular_job(model, folder)
    write_data()
    atomic_write(job.script, script)
    for kind, message in job.warnings:
        if (kind, message) not in model.warnings:
            model.warn(kind, message)
    return job


def granular_packages(uses_plugin: bool, wall_cmds: list[str]) -> list[str]:
    """The LAMMPS packages a granular script needs (its header names them): BPM (atom_style
    bpm/sphere, fix nve/bpm/sphere, bpm/rotational bonds), GRANULAR (compute contact/atom,
    pair granular, fix wall/gran), MISC for fix evaporate (spheres leaving an oversized
    domain), PLUGIN to load fibrelmp's styles."""
    packages = ["GRANULAR", "BPM"]
    if any(" evaporate " in cmd for cmd in wall_cmds):
        packages.append("MISC")
    if uses_plugin:
        packages.append("PLUGIN")
    return packages


def job_facts(model: GranularModel, spheres, tiles, t_start: float, dt: float,
              musen_clock: bool = False) -> WorkFacts:
    # (MUSEN's variable time step: the frames' times are fix musen/leapfrog's clock file's)
    """What ``fibrelmp post --data`` needs beyond the data file and dump to write the spheres
    as the run does (translate.work_facts): names, MUSEN keys and ids, initial orientations,
    the DEMDF document."""
    sp = model.spheres
    types = {**spheres.type_of_mat, **tiles.type_of_mat}          # material -> LAMMPS type
    q = np.asarray(sp.quaternion, float)
    identity = bool((q == np.array([1.0, 0.0, 0.0, 0.0])).all()) if len(q) else True
    demdf = model.origin.post_facts() if model.origin is not None else None
    return WorkFacts(
        kind=model.kind, source=model.source.name, time_start=t_start, time_step=dt,
        type_names={t: model.materials[m].name for m, t in types.items()},
        material_keys={t: model.materials[m].key for m, t in types.items()},
        object_ids=np.asarray(sp.ids, np.int64) if model.kind == "musen" else None,
        orientation=None if identity else q,
        radius=None if np.array_equal(spheres.crad, sp.radius) else np.asarray(sp.radius, float),
        demdf=demdf, clock=("variable" if model.plan.variable_step is not None else
                            "musen" if musen_clock else "product"))


def build_granular_job(model: GranularModel, folder: str | Path):
    """(job, script text, data-file writer) without touching the disk (MPI ranks > 0 need
    the script text only: LAMMPS reads data files on rank 0)."""
    folder = Path(folder)
    parts = _plan_parts(model)
    spheres, tiles, bonds, run = parts.spheres, parts.tiles, parts.bonds, parts.run
    data_path = folder / DATA_NAME

    def write_data_file() -> None:
        write_data(model, data_path, spheres.rows, spheres.type_of_mat, spheres.smat, spheres.crad,
                   parts.axes.lo, parts.axes.hi, parts.ntypes, tiles.x, tiles.types, tiles.v, tiles.ids,
                   tiles.radius, TILE_MASS_FACTOR * float(spheres.mass.max() if len(spheres.mass) else 1.0),
                   bonds.rows, bonds.type, len(bonds.types), parts.geometry,
                   inlet_bond_capacity(model))
        if len(parts.mesh):
            write_mesh(model, parts.wall_plans, spheres, folder / MESH_NAME)
        write_facts(data_path, job_facts(model, spheres, tiles, run.t_start, run.dt, run.clock is not None))

    saves = save_steps(model, run)
    script = _render_script(model, parts, saves)
    has_bonds = len(bonds.rows) > 0 or inlet_bond_capacity(model)[0] > 0
    breakage = model.plan.bonds_may_break()
    has_mesh = len(parts.mesh) > 0
    job = GranularJob(
        folder=folder, script=folder / SCRIPT_NAME, data=data_path, total_steps=run.total,
        save_steps=saves,
        frames=folder / FRAMES_NAME,
        bond_dump=folder / BONDS_NAME if has_bonds else None,
        tile_dump=folder / TILES_NAME if tiles.total else None,
        breaks=folder / BREAKS_NAME if has_bonds and breakage else None,
        walls=[(wp.name, wp.description) for wp in parts.wall_plans], dt=run.dt, t_start=run.t_start, clock=run.clock,
        sphere_rows=spheres.rows, outside_rows=spheres.outside_rows, late_rows=spheres.late_rows,
        bond_rows=bonds.rows, deletions=spheres.deletions, wall_plans=parts.wall_plans,
        domain_lo=parts.dom_lo, domain_hi=parts.dom_hi, removal_axes=parts.axes.removal_axes,
        frame_columns=parts.frame_columns, warnings=parts.warnings,
        wall_forces=folder / MESH_FORCES_NAME if has_mesh else None, mesh_rows=parts.mesh,
        # (not written when the data file has no atom: only generated agglomerates' bonds)
        geometry=folder / GEOMETRY_NAME if parts.geometry is not None and len(parts.geometry.partners) else None,
        contacts=folder / CONTACTS_NAME,
        inlet_log=folder / INLET_LOG if model.plan.inlets else None,
        inlet_bond_rows=_inlet_bond_rows(model),
        type_materials={t: m for m, t in spheres.type_of_mat.items()},
        variable_clock=folder / CLOCK_NAME if model.plan.variable_step is not None else None,
        stress_contacts=folder / STRESS_CONTACTS_NAME if parts.stress else None,
        stress_walls=folder / STRESS_WALLS_NAME if parts.stress and has_mesh else None)
    return job, script, write_data_file


def _inlet_bond_rows(model: GranularModel) -> np.ndarray:
    """The bond rows reserved for generated agglomerates (empty without)."""
    layout = model.plan.inlet_layout or []
    return np.concatenate([np.arange(bfirst, bfirst + count * m) for _, _, bfirst, count, _, m in layout]
                          + [np.zeros(0, np.int64)]).astype(np.int64)


@dataclass
class _JobParts:
    """The planned pieces of a granular job (spheres, walls, box, bonds, laws) and the
    warnings their steps gave, in order."""

    run: RunTime
    warnings: list[tuple[str, str]]
    dom_lo: np.ndarray | None
    dom_hi: np.ndarray | None
    spheres: SimulatedSpheres
    wall_plans: list[WallPlan]
    mesh: np.ndarray
    tiles: WallTiles
    ntypes: int
    axes: BoxAxes
    styles: lammps_styles.Plugin
    bonds: SimulatedBonds
    musen_hm: bool
    pair_lines: list[str]
    sb_model: type[physics.PhysicsModel]
    wall_cmds: list[str]
    var_cmds: list[str]
    frame_columns: list[str]
    geometry: BondGeometry | None
    verlet: VerletSchedule | None    # fix musen/verlet's settings (None: not needed)
    stress: bool = False             # MUSEN's stress tensor computed (presave dumps)


def _plan_parts(model: GranularModel) -> _JobParts:
    """Run the steps of ``translate.granular`` in order (their checks and warnings come in
    that order)."""
    plan = model.plan
    run = run_time(model)
    dim, dt, total, t_start = run.dim, run.dt, run.total, run.t_start
    warnings: list[tuple[str, str]] = []
    periodic = periodic_axes(plan, dim)
    warnings.extend(physics.periodic_contact_warnings(model, periodic))
    dom_lo, dom_hi = domain_bounds(plan)
    spheres = select_spheres(model, run, periodic, dom_lo, dom_hi, warnings)
    wall_plans = plan_walls(model, dt, run.t_end)
    warnings.extend(wall_warnings(model, wall_plans, t_start, run.t_end, spheres))
    mesh = mesh_rows(wall_plans)
    tiles = tile_types(wall_plans, spheres.r_min, len(spheres.mats))
    ntypes = len(spheres.mats) + len(tiles.materials) or 1
    axes = box_axes(model, dim, periodic, dom_lo, dom_hi, spheres)
    travel = Travel(model, spheres, total * dt, wall_plans)
    place_tiles(model, wall_plans, tiles, spheres, axes, travel, t_start, warnings)
    fit = fit_box(model, axes, spheres, tiles, dim)
    box_cmds = box_commands(fit, axes, spheres, tiles, travel, dt, warnings)
    if any(i.makes_agglomerates for i in plan.inlets) and not any("atom_modify" in c for c in box_cmds):
        # a resumed run sorts its atoms at once, the uninterrupted one at multiples of 1000
        # steps: agglomerates' bonded spheres (3 and more forces each) would then sum their
        # forces in other orders and differ in the last bit; unsorted, the order is the same
        box_cmds += [LammpsText("# " + comment_text("atoms kept in creation order: a resumed run "
                                                    "sums forces as the uninterrupted one")),
                     "atom_modify     sort 0 0.0"]
    styles = lammps_styles.plugin()
    if not styles.available and model.kind == "musen":     # DEMDF's law is stock-exact
        warnings.append(("approximate MUSEN physics", f"fibrelmp's LAMMPS styles are not used "
                         f"({styles.how}): stock LAMMPS styles stand in for MUSEN's contact, "
                         "bond and wall laws (see the warnings that follow and docs/granular.md)"))
    bonds = select_bonds(model, run, spheres, periodic, warnings, exact=styles.available)
    # MUSEN's particle-particle law exactly with the plugin; DEMDF's soft-sphere stand-in for
    # BOS's instantaneous collisions (frictionless Hertz, docs/demdf.md) stays on the stock
    # style, which is exact for it
    musen_hm = styles.available and model.kind == "musen"
    pair_lines = pair_coeff_lines(model, spheres, tiles.materials, tiles.radius, dt, musen_hm)
    sb_model = physics.solid_bond_model(plan)
    wall_cmds, var_cmds, frame_columns = wall_commands(model, wall_plans, spheres, dt)
    if uses_temperature(model):
        frame_columns.append(TEMPERATURE)
    if model.plan.inlets and not musen_hm:
        raise InputError(model.source, None, "MUSEN's dynamic generators need fibrelmp's LAMMPS "
                         f"styles (fix musen/inlet): {styles.how}")
    # generated agglomerates: bonds per sphere (geometry slots, LAMMPS's extra bond room)
    stored, _ = inlet_bond_capacity(model)
    if stored:
        bonds.max_length = max(bonds.max_length, inlet_bond_reach(model))
    # musen/elastic: each bond's d, L0 (and initial tangential overlap) on its first sphere
    geometry = (bond_geometry(model, bonds, spheres.rows, len(spheres.rows) + len(tiles.x), stored)
                if bonds.exact and (len(bonds.rows) or stored) else None)
    wall_cmds += inlet_commands(model, spheres.type_of_mat, dt, t_start, run.t_end,
                                MESH_FIX if len(mesh) else None, bonds.type_of_material,
                                geometry.slots if geometry is not None else 0)
    # broken bonds' spheres touch from MUSEN's next contact-list update (fix musen/verlet):
    # only where contacts between bonded spheres are off (else they touch all along)
    verlet = None
    if (geometry is not None and musen_hm and plan.bonds_may_break()
            and not plan.contacts_between_bonded):
        verlet = musen_verlet(model)
        if verlet.approximate:
            warnings.append(("musen-verlet-schedule", f"MUSEN's contact-list updates, which let "
                             f"broken bonds' spheres touch, may come at other steps: "
                             f"{verlet.approximate}"))
    why_not = _no_stress(model, musen_hm, geometry, len(bonds.rows) > 0 or stored > 0, len(mesh))
    if why_not is not None and model.kind == "musen":
        warnings.append(("musen-no-stress", f"the stress tensor and principal stresses (MUSEN's "
                         f"36 and 42) are left out of the results: {why_not}"))
    return _JobParts(run, warnings, dom_lo, dom_hi, spheres, wall_plans, mesh, tiles, ntypes, axes,
                     styles, bonds, musen_hm, pair_lines, sb_model, box_cmds + wall_cmds, var_cmds,
                     frame_columns, geometry, verlet, why_not is None)


def _no_stress(model: GranularModel, musen_hm: bool, geometry, has_bonds: bool, meshed: int) -> str | None:
    """Why fibrelmp does not compute MUSEN's stress tensor for this job (None: it does,
    granular_run.stress)."""
    if model.kind != "musen":
        return "not a MUSEN job"
    if not musen_hm:
        return "it needs fibrelmp's LAMMPS styles"
    if model.plan.variable_step is not None:
        return "not with MUSEN's variable time step (the step before a save is not known in advance)"
    if has_bonds and geometry is None:
        return "it needs bond style musen/elastic"
    if len(physics.chosen_all(model, "PP")) > 1:
        return "with several particle-particle models (MUSEN takes the last one's force alone)"
    walls = model.triangles.count if model.triangles is not None else 0
    if walls and meshed < walls:
        return "with walls outside fix musen/wall/mesh"
    if walls and len(physics.chosen_all(model, "PW")) > 1:
        return "with several particle-wall models (MUSEN takes the last one's force alone)"
    return None


def _render_script(model: GranularModel, parts: _JobParts, saves: SaveSteps) -> str:
    """in.lammps of the planned job (templates/granular.lammps.j2)."""
    plan, run, spheres, tiles, bonds = model.plan, parts.run, parts.spheres, parts.tiles, parts.bonds
    if plan.variable_step is not None:
        _check_variable_step(model, parts)
        acts = _stop_criterion(model, parts, variable_schedule(), last_unchecked=True)
    else:
        # MUSEN's integrator (with fibrelmp's styles) starts with its half-step prediction
        acts = schedule(run.total, saves, spheres.deletions, predict=parts.musen_hm)
        # cmusen's save of the step reaching END_TIME (FinalizeSimulation) checks no criterion
        acts = _stop_criterion(model, parts, acts, last_unchecked=acts[-1] == ("frame", run.total))
        if parts.stress:
            acts = with_presaves(acts)
    skin = 0.5 * tiles.largest_radius(spheres.r_max)
    pair_cut = 2.0 * tiles.largest_radius(spheres.r_max)
    comm_cut = max(pair_cut, 1.5 * bonds.max_length) + skin
    g = np.asarray(plan.gravity, float)
    if run.dim == 2 and g[2] != 0:
        raise InputError(model.source, None, "2D model with a z component of gravity")
    tile_groups = [(wp, f"w{k + 1}") for k, wp in enumerate(parts.wall_plans)
                   if wp.kind == "tiles" and wp.tile_ids is not None and len(wp.tile_ids)]
    mats, tile_mats = spheres.mats, tiles.materials
    if model.kind == "musen" and not parts.musen_hm and stock_pair_deviates(model, spheres.mats):
        parts.warnings.append(("approximate MUSEN physics (particle-particle contact)", STOCK_PAIR_WARNING))
    geometry, styles = parts.geometry, parts.styles
    # the plugin is loaded only for a style of its own (a DEMDF job uses stock styles only)
    if plan.velocity_limit is not None and not parts.musen_hm:
        raise InputError(model.source, None, "a particle velocity limit needs fibrelmp's LAMMPS "
                         "styles (fix musen/leapfrog)")
    pbc_velocity = _moving_periodic_box(model, parts.axes, styles)
    if plan.external_fields and not parts.musen_hm:
        raise InputError(model.source, None, f"{plan.external_fields[0].model} needs fibrelmp's "
                         f"LAMMPS styles (fix musen/field): {styles.how}")
    uses_plugin = bool(styles.path) and (parts.musen_hm or geometry is not None or len(parts.mesh) > 0
                                         or plan.velocity_limit is not None or pbc_velocity is not None
                                         or bool(plan.external_fields))
    return template_environment().get_template("granular.lammps.j2").render(
        model=model, plugin=lammps_path(styles.path, "plugin") if uses_plugin else None,
        packages=granular_packages(uses_plugin, parts.wall_cmds),
        fmt=float_text, dim=run.dim, bnd=parts.axes.bnd, data_name=DATA_NAME, frames_name=FRAMES_NAME,
        bonds_name=BONDS_NAME, tiles_name=TILES_NAME, breaks_name=BREAKS_NAME,
        comm_cut=comm_cut, skin=skin, musen_hm=parts.musen_hm, pair_lines=parts.pair_lines,
        has_bonds=len(bonds.rows) > 0 or inlet_bond_capacity(model)[0] > 0,
        overlay=bool(plan.contacts_between_bonded), breakage=plan.bonds_may_break(),
        bond_types=bonds.types,
        musen_bonds=geometry is not None, bond_geometry=geometry, bond_partners=PARTNERS,
        bond_values=VALUES, geometry_fix=GEOMETRY_FIX, geometry_name=GEOMETRY_NAME,
        bond_criterion=int(plan.bond_breakage),
        bond_law=_bond_style_law(model) if geometry is not None else None,
        pair_style_lines=physics.pair_style_lines(model, parts.musen_hm),
        sphere_types=[spheres.type_of_mat[m] for m in mats],
        sphere_type_names=[model.materials[m].name for m in mats],
        tile_types=[tiles.type_of_mat[m] for m in tile_mats],
        tile_type_names=[model.materials[m].name for m in tile_mats],
        tile_groups=[(tag, compress_ids(wp.tile_ids)) for wp, tag in tile_groups],
        mat_groups=spheres.material_groups(), dt=run.dt, t_start=run.t_start, gravity=g,
        gnorm=float(np.linalg.norm(g)), var_cmds=parts.var_cmds, wall_cmds=parts.wall_cmds,
        frame_columns=parts.frame_columns, acts=acts, compress_ids=compress_ids,
        lost=bool(parts.axes.removal_axes.any()),
        walls=[(wp.name, wp.description) for wp in parts.wall_plans],
        mesh_fix=MESH_FIX if len(parts.mesh) else None, mesh_forces_name=MESH_FORCES_NAME,
        contacts_name=CONTACTS_NAME, presaves=parts.stress,
        stress_contacts_name=STRESS_CONTACTS_NAME, stress_walls_name=STRESS_WALLS_NAME, velocity_limit=plan.velocity_limit, pbc_velocity=pbc_velocity,
        musen_integrator=parts.musen_hm, verlet=parts.verlet,
        fields=field_commands(model, spheres.rows, spheres.type_of_mat, parts.ntypes),
        variable_step=None if plan.variable_step is None else " ".join(float_text(v) for v in (
            *plan.variable_step, run.dt, plan.save_every_time or 1e300, run.t_end)),
        clock_name=CLOCK_NAME,
        thermo_every=min(saves.period or 0, 2 ** 31 - 1),      # thermo N is a C int
        stop_label=STOP_LABEL,
    )


def _check_variable_step(model: GranularModel, parts: _JobParts) -> None:
    why = variable_step_refusals(model, parts.musen_hm, bool(parts.spheres.deletions))
    if why is not None:
        raise InputError(model.source, None, why)


def _stop_criterion(model: GranularModel, parts: _JobParts, acts: list[tuple],
                    last_unchecked: bool = False) -> list[tuple]:
    """The actions with MUSEN's stop criterion BROKEN_BONDS checked at every save (none
    without bonds: none can break)."""
    limit, bonds = model.plan.stop_broken_bonds, parts.bonds
    if limit is None or not len(bonds.rows):
        return acts
    if parts.geometry is None:
        raise InputError(model.source, None, "a stop criterion on broken bonds needs fibrelmp's "
                         "LAMMPS styles (bond style musen/elastic counts the breaks)")
    bonded = model.bonds.pair[bonds.rows]
    if any(np.isin(bonded, rows).any() for _, rows in parts.spheres.deletions):
        raise InputError(model.source, None, "a stop criterion on broken bonds with bonded spheres "
                         "whose activity ends is not supported (their bonds would count as broken)")
    return with_stop_criterion(acts, limit, len(bonds.rows), last_unchecked)


def _moving_periodic_box(model: GranularModel, axes: BoxAxes, styles) -> np.ndarray | None:
    """MUSEN's moving periodic box (a .mdem's ``periodic_conditions_vel``) on the job's periodic
    axes, or None; it needs fibrelmp's ``fix musen/pbc/move``."""
    v = model.plan.periodic_velocity
    if v is None:
        return None
    v = np.where([b == "p" for b in axes.bnd], np.asarray(v, float), 0.0)
    if not v.any():
        return None
    if not styles.path:
        raise InputError(model.source, None, "a moving periodic box needs fibrelmp's LAMMPS styles "
                         "(fix musen/pbc/move)")
    return v
