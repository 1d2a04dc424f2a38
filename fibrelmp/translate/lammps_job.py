"""Turn a bead-spring Model into a LAMMPS data file and input script (rendered to disk).

The script is self-contained LAMMPS (no Python hooks): ``lmp -in in.lammps`` inside the job
folder replays exactly what ``fibrelmp run`` executes line by line.  FibreNet's angles use
fibrelmp's ``angle_style fibrenet`` (``plugin load`` of fibrelmp's styles); without the
plugin (``--stock-styles``) the same law runs as ``angle_style lepton`` (slower, see
``stock_angle_warning``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple
from pathlib import Path

import numpy as np

from fibrelmp import lammps_styles
from fibrelmp.errors import InputError, RunError
from fibrelmp.lammps_text import comment_text, lammps_path, lammps_token, template_environment
from fibrelmp.model import Model
from fibrelmp.textio import atomic_write
from fibrelmp.translate.lammps_data import DataSection, write_data_file
from fibrelmp.translate.lammps_format import atomfile_blocks, float_text
from fibrelmp.translate.steps import MIN_PIECE_STEPS, SaveSteps, run_piece
from fibrelmp.translate.topology_file import write_topology_file
from fibrelmp.translate.work_facts import WorkFacts, write_facts

# FibreNet's result file names (<prefix><suffix>): fix fibrenet/output writes them in the job
# folder, the FibreNet home's writers (translate.fibrenet.writer) beside the input
XYZ_SUFFIX = {"position": "_coord.xyz", "velocity": "_vel.xyz", "force": "_force.xyz"}
RESTART_SUFFIX = "_restart.res"

SCRIPT_NAME = "in.lammps"
DATA_NAME = "data.lammps"
TOPOLOGY_NAME = "topology.bin"      # data.lammps's box and topology for fibrenet/read_data
FRAMES_NAME = "frames.dump"
# FibreNet's per-bead state (fix fn_state), read by LAMMPS as an atomfile variable: kept out of
# the data file, whose custom section other readers (MDAnalysis, OVITO) cannot skip
STATE_NAME = "fibrenet_state.txt"
STATE_COLUMNS = ("d_fox", "d_foy", "d_foz", "d_vtx", "d_vty", "d_vtz")
# the work dump's columns named as LAMMPS names them (velocity and force are FibreNet's)
DUMP_NAMES = {"v_fn_vx": "vx", "v_fn_vy": "vy", "v_fn_vz": "vz", "v_fn_fx": "fx", "v_fn_fy": "fy",
              "v_fn_fz": "fz", "v_fn_radius": "radius", "v_fn_mass": "mass"}
OUTPUT_FIX = "fn_out"                  # fix fibrenet/output (fibrelmp's plugin)
NATIVE_KIND = "FibreNet files after the run"


@dataclass
class NativeFiles:
    """FibreNet's files the job itself writes into its folder (fix fibrenet/output)."""
    xyz: list[Path]                       # _coord/_vel/_force.xyz of output_data: appended
    restart: Path                         # _restart.res: rewritten whole
    nonfinite: int | None = None          # nan/inf the fix wrote into them (set after the run)


@dataclass
class Job:
    folder: Path
    script: Path
    data: Path
    frames: Path
    total_steps: int
    type_of_ltype: np.ndarray            # LAMMPS type (1-based, index 0 unused) -> user type
    output_steps: SaveSteps | tuple = ()   # the steps of the frames (lazy)
    text: str = ""                        # the script, also when only rank 0 wrote files
    native: NativeFiles | None = None     # FibreNet's files written by LAMMPS (the plugin)
    state: Path | None = None             # the per-bead state file (STATE_NAME)
    bond_lengths: np.ndarray | None = None   # rest length of each LAMMPS bond type (1-based: [type - 1])
    topology: Path | None = None          # TOPOLOGY_NAME, when the script reads it instead of data

    @property
    def inputs(self) -> list[Path]:
        """The files the script reads (a checkpoint is refused when one changed)."""
        read = self.topology if self.topology is not None else self.data
        return [read] + ([self.state] if self.state is not None else [])


def _factorize(col: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """np.unique(col, return_inverse=True), faster for the few distinct values per column a
    model has (types, masses, stiffnesses): the distinct values of a sample, checked to cover
    the column, else np.unique itself."""
    nan = col.dtype.kind == "f" and bool(np.isnan(col).any())     # np.unique merges NaNs
    if len(col) > 8192 and not nan:
        u = np.unique(col[:: len(col) // 2048])
        inv = np.minimum(np.searchsorted(u, col), len(u) - 1)
        if (u[inv] == col).all():
            return u, inv
    u, inv = np.unique(col, return_inverse=True)
    return u, inv.reshape(-1)


def _unique_rows(*cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """np.unique(rows, axis=0) via per-column integer codes (sorting ints, not byte rows)."""
    if not cols[0].size:
        return np.zeros((0, len(cols))), np.zeros(0, np.int64)
    key = np.zeros(len(cols[0]), np.int64)
    span = 1                                       # key < span
    for col in cols:
        u, inv = _factorize(np.asarray(col))
        if span * len(u) >= 2 ** 62:               # re-compress first: no overflow
            key = np.unique(key, return_inverse=True)[1].reshape(-1)
            span = int(key.max(initial=0)) + 1
        key = key * len(u) + inv.reshape(-1)       # order-preserving: lexicographic by column
        span *= len(u)
    u, inverse = _factorize(key)
    if len(u) <= 64:        # a row per distinct key: where it first occurs
        first = np.array([int(np.argmax(inverse == j)) for j in range(len(u))], np.int64)
    else:
        _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    return np.column_stack([np.asarray(c)[first] for c in cols]), inverse.reshape(-1)


def _pair_coeffs(model: Model, ltypes: np.ndarray) -> tuple[list[str], list[str], float]:
    """pair_coeff lines per LAMMPS type pair, the sub-styles used, and the largest cutoff."""
    laws = {(law.type_i, law.type_j): law for law in model.pairs}
    lines, styles, max_cut = [], set(), 0.0
    nl = len(ltypes)
    for a in range(nl):
        for b in range(a, nl):
            ti, tj = int(ltypes[a, 0]), int(ltypes[b, 0])
            law = laws[(min(ti, tj), max(ti, tj))]
            p = law.params
            if law.kind == "hs":
                rc = ltypes[a, 2] + ltypes[b, 2]
                if p["K"] == 0 or rc <= 0:
                    lines.append(f"pair_coeff {a + 1} {b + 1} none")
                    continue
                # harmonic/cut: E = k (rc - r)^2, so k = K/2 gives F = K (Ri + Rj - r)
                lines.append(f"pair_coeff {a + 1} {b + 1} harmonic/cut {float_text(p['K'] / 2)} {float_text(rc)}")
                styles.add("harmonic/cut")
                max_cut = max(max_cut, rc)
            elif law.kind == "st":
                expr = f"0.5*{float_text(p['B'])}*(r-{float_text(p['rstar'])})^2"
                lines.append(f'pair_coeff {a + 1} {b + 1} lepton "{expr}" {float_text(p["cutoff"])}')
                styles.add("lepton")
                max_cut = max(max_cut, p["cutoff"])
            else:  # FibreNet lj: F = 48 eps (s/r)^6 ((s/r)^6 - 1/2) / r^2 - Fc, shifted to 0 at c3
                s, e, c3 = p["sigma"], p["epsilon"], p["shift"]
                fc = 48 * e * (s / c3) ** 6 * ((s / c3) ** 6 - 0.5) / c3 ** 2
                expr = (f"{float_text(48 * e * s ** 12 / 13)}/r^13-{float_text(24 * e * s ** 6 / 7)}/r^7"
                        f"+{float_text(fc)}*r")
                lines.append(f'pair_coeff {a + 1} {b + 1} lepton "{expr}" {float_text(p["cutoff"])}')
                styles.add("lepton")
                max_cut = max(max_cut, p["cutoff"])
    return lines, sorted(styles), max_cut


ANGLE_CLAMP = 0.001     # LAMMPS angle styles use max(sin(theta), 0.001) when spreading forces


def angle_expression(c: float, theta0: float) -> str:
    """Lepton energy for E = c (theta - theta0)^2 whose forces are exact near straight triples.

    LAMMPS divides dE/dtheta by max(sin(theta), 0.001).  Inside that clamp the expression adds
    a term D with dD/dtheta = dE/dtheta * (0.001/sin(theta) - 1), so the clamped division gives
    the exact force (FibreNet's).  Its energy is cancelled by subtracting a derivative-free copy
    (floor() has zero derivative in Lepton) quantised to 2^-60, so E stays c (theta - theta0)^2.
    With phi = pi - theta:  integral of (phi - u)/sin(phi) = phi + phi^3/18 - u ln tan(phi/2)
    (u = pi - theta0; the phi^5 term is below 1e-17 inside the clamp).
    """
    u = math.pi - theta0
    q = 2.0 ** 60
    s = ANGLE_CLAMP
    return (f"{float_text(c)}*theta^2+select(step({float_text(s)}-sin(phi)),D-floor(D*{float_text(q)})/{float_text(q)},0);"
            f"D={float_text(2 * c * s)}*(phi+phi^3/18-{float_text(u)}*log(tan(max(abs(phi),1e-300)/2)))"
            f"-{float_text(c)}*theta^2;phi={float_text(u)}-theta")


STOCK_ANGLES = "FibreNet angles via angle_style lepton"


def stock_angle_warning(why: str) -> str:
    """What a job without fibrelmp's plugin says about its angles (figures measured by
    tests/test_style_fibrenet_angle.py and benchmarks/fibrenet_angle.py)."""
    return (f"fibrelmp's LAMMPS styles are not used ({why}): FibreNet's angles run as "
            "angle_style lepton with fibrelmp's clamp-cancelling expression instead of "
            "angle_style fibrenet. This is not a physics approximation -- the law is the same, "
            "E = c1 (theta - theta0)^2 with FibreNet's force directions -- but it is the slower "
            "route: ~70 ns per angle and step plus ~1.5 ms per step of expression set-up, i.e. "
            "4x (50k beads) to 17x (5k beads) the angle cost of angle_style fibrenet. Its theta "
            "comes from acos(cos theta), as "
            "FibreNet's does, which costs ~1e-16/phi^2 of the force for triples phi = pi - theta "
            "from straight (2e-8 at 1e-4 rad, 2e-4 at 1e-6 rad, all of it below ~1e-8 rad); "
            "angle_style fibrenet is exact there")


def _schedule(model: Model, general_lambda: bool) -> tuple[list[tuple], SaveSteps, int]:
    """The sequence of actions the script performs (see the template for each action).

    FibreNet's first step of a fresh start (or after a velocity reset) uses a stored force
    instead of F(x): the "kick" action reproduces that step exactly.  Repeated identical
    chunks (relaxation chunks with resets, production chunks between frames) become one
    LAMMPS loop ("loop" ... "end"), so the script does not grow with the number of frames.
    Returns the actions, the output steps (lazy) and the total number of steps.
    """
    acts: list[tuple] = []
    total = sum(st.steps for st in model.plan.stages)
    piece = run_piece(total, MIN_PIECE_STEPS)     # progress pieces (translate.steps)
    fresh = True                                   # next step starts from the stored state

    def advance(n: int, store_before_last: bool) -> None:
        nonlocal fresh
        if n <= 0:
            return
        if fresh:
            acts.append(("kick",))
            fresh = False
            n -= 1
            if n == 0:
                return
        body = n - 1 if store_before_last else n
        while body > 0:
            k = min(piece, body)
            acts.append(("run", k))
            body -= k
        if store_before_last:
            acts.append(("store_force",))
            acts.append(("run", 1))

    def repeat(count: int, body) -> None:
        """``body()`` ``count`` times: as a loop when that is shorter than writing it out."""
        if count <= 0:
            return
        if count == 1:
            body()
            return
        name = f"fn_loop{sum(1 for a in acts if a[0] == 'loop') + 1}"
        acts.append(("loop", name, count))
        body()
        acts.append(("end", name))

    relax = [st for st in model.plan.stages if st.name == "relax"]
    production = [st for st in model.plan.stages if st.name == "production"][0]
    frame0 = "state"
    if relax:
        st = relax[0]
        if st.reset:        # FibreNet zeroes v and F before and after every chunk
            def chunk() -> None:
                nonlocal fresh
                acts.append(("reset",))
                fresh = True
                advance(st.chunk, False)
            repeat(st.steps // st.chunk, chunk)
            acts.append(("reset",))
            fresh = True
        else:               # without resets the chunks are one continuous damped run
            advance(st.steps, general_lambda)
            frame0 = "dynamic"
        acts.append(("reset_timestep",))
    acts.append(("frame", frame0))
    every, steps = production.chunk, production.steps

    def frame_chunk(n: int) -> None:
        advance(n, general_lambda and not (fresh and n == 1))
        acts.append(("frame", "dynamic"))

    if steps > 0:
        first = min(every, steps)
        frame_chunk(first)                   # a fresh start begins with the kick
        full, rest = divmod(steps - first, every)
        repeat(full, lambda: frame_chunk(every))
        if rest:
            frame_chunk(rest)
    return acts, SaveSteps(steps, period=every), total


def write_job(model: Model, folder: str | Path, write_files: bool = True) -> Job:
    """Write data file + input script for ``model`` into ``folder``.

    ``write_files=False`` (MPI ranks other than 0) renders the script in memory only: LAMMPS
    reads the data file on rank 0 and broadcasts it."""
    folder = Path(folder)
    try:
        if write_files:
            folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(folder, None, f"cannot create job folder: {exc.strerror or exc}") from None
    p, dyn, box = model.particles, model.dynamics, model.box
    if dyn.damping < 0:
        raise InputError(model.source, None, "damping must be >= 0")

    # LAMMPS types: one per (user type, mass, radius) so masses and hs radii are per type
    ltypes, atype = _unique_rows(p.types.astype(float), p.masses, p.radii)
    frozen_types = [i + 1 for i in range(len(ltypes)) if ltypes[i, 1] == 0]
    mobile_types = [i + 1 for i in range(len(ltypes)) if ltypes[i, 1] > 0]
    bonds = _bonds_alive_at_first_step(model)
    btypes, btype = _unique_rows(bonds.k, bonds.r0, np.nan_to_num(bonds.break_length, nan=-1.0))
    atypes, antype = _unique_rows(model.angles.c, model.angles.theta0)
    pair_lines, pair_styles, max_cut = _pair_coeffs(model, ltypes)

    general_lambda = dyn.lambda_ != 0.5
    use_mvv = general_lambda and dyn.damping != 0 and bool(mobile_types)

    skin, comm_cut = _skin_and_ghost_cutoff(model, bonds, max_cut)

    acts, out_steps, total = _schedule(model, general_lambda)
    type_names = [p.type_names[int(t)] for t in ltypes[:, 0]]
    styles = lammps_styles.plugin()
    native, native_files = _native_output(model, folder, type_names, styles.path is not None)
    if model.angles.count and not styles.available:
        model.warn(STOCK_ANGLES, stock_angle_warning(styles.how))

    data_path = folder / DATA_NAME
    state_path = folder / STATE_NAME if p.count else None
    # the plugin's fibrenet/read_data loads atom_style angle jobs from a binary copy of the data
    # file (read once on rank 0, not parsed twice on every rank); data.lammps stays for post
    topology_path = folder / TOPOLOGY_NAME if styles.path is not None and not use_mvv and p.count else None
    if write_files:
        atoms = _data_atoms(model, ltypes)
        _write_data(model, bonds, data_path, atoms, ltypes, atype, btypes, btype, atypes, antype, use_mvv)
        if topology_path is not None:
            _write_topology(model, bonds, topology_path, atoms, atype, btypes, btype, atypes, antype)
        if state_path is not None:
            _write_state(model, state_path)
        write_facts(data_path, _facts(model, type_names))
    script = template_environment().get_template("bead_spring.lammps.j2").render(
        model=model, dyn=dyn, box=box, fmt=float_text, use_mvv=use_mvv,
        frozen_types=frozen_types, mobile_types=mobile_types,
        bond_types=btypes, angle_types=atypes, pair_lines=pair_lines, pair_styles=pair_styles,
        max_cut=max(max_cut, 1e-6), skin=skin, comm_cut=comm_cut, acts=acts,
        general_lambda=general_lambda, data_name=DATA_NAME, frames_name=FRAMES_NAME,
        topology_name=TOPOLOGY_NAME if topology_path is not None else None,
        state_name=STATE_NAME if state_path is not None else None, state_columns=STATE_COLUMNS,
        wall_pad=float(box.lengths.max()), type_names=type_names,
        radius_expression=_per_type_expression(ltypes[:, 2]), dump_names=DUMP_NAMES,
        rad2deg=180.0 / math.pi, inf=float("inf"), angle_expression=angle_expression,
        extra_packages=_extra_packages(pair_styles, btypes, use_mvv),
        # the plugin is loaded only for a style of its own: angle_style fibrenet, fix
        # fibrenet/output, fibrenet/read_data
        plugin=lammps_path(styles.path, "plugin") if styles.path and (len(atypes) or native or topology_path) else None,
        native=native,
        thermo_every=min(out_steps.period or 0, 2 ** 31 - 1),     # thermo N is a C int
    )
    script_path = folder / SCRIPT_NAME
    if write_files:
        atomic_write(script_path, script)
    type_of_ltype = np.r_[-1, ltypes[:, 0].astype(np.int64)]
    return Job(folder, script_path, data_path, folder / FRAMES_NAME, total, type_of_ltype, out_steps,
               text=script, native=native_files, state=state_path,
               bond_lengths=btypes[:, 1].astype(float) if bonds.count else np.zeros(0),
               topology=topology_path)


def _skin_and_ghost_cutoff(model: Model, bonds, max_cut: float) -> tuple[float, float]:
    """The neighbour skin and the ghost cutoff (comm_modify cutoff)."""
    p = model.particles
    # communication must reach across bonds and angles (1-3 pairs) as well as pair cutoffs
    # ghosts must reach both legs of every angle and every bond, as well as the pair cutoffs
    legs = [bonds.atoms] + [model.angles.atoms[:, [0, 1]], model.angles.atoms[:, [2, 1]]]
    leg_len = 0.0
    for pairs_ in legs:
        if len(pairs_):
            d = p.unwrapped[pairs_[:, 0]] - p.unwrapped[pairs_[:, 1]]
            leg_len = max(leg_len, float(np.sqrt((d * d).sum(1)).max()))
    leg_len = max(leg_len, float(np.max(bonds.r0, initial=0.0)))
    # half the longest cutoff: fewer neighbour-list builds for a few more pair distances a
    # step; measured 12 % (50k beads) and 9 % (260k) faster than a quarter (docs/performance.md)
    skin = max(0.05, 0.5 * max(max_cut, 1e-12)) if max_cut > 0 else 0.3
    comm_cut = max(max_cut + skin, 2.0 * leg_len + skin)
    return skin, comm_cut


def _per_type_expression(values: np.ndarray) -> str:
    """An atom-style variable formula giving each LAMMPS type its value (1-based types)."""
    return "+".join(f"{float_text(v)}*(type=={t})" for t, v in enumerate(values, 1)) or "0.0"


def _facts(model: Model, type_names: list[str]) -> WorkFacts:
    """What ``fibrelmp post --data`` needs beyond the data file to write FibreNet's files
    exactly as the run does (translate.work_facts)."""
    spec = model.plan.output
    only = None if spec.types is None else sorted({model.particles.type_names[t] for t in spec.types})
    return WorkFacts(kind="fibrenet", source=model.source.name, time_start=0.0,
                     time_step=model.dynamics.dt,
                     type_names={k: name for k, name in enumerate(type_names, 1)},
                     box_lengths=np.asarray(model.box.lengths, float), output_types=only,
                     output_fields=list(spec.fields))


def _write_state(model: Model, path: Path) -> None:
    """FibreNet's state of each bead (the force of the last step, the lambda-predicted
    velocity): the values of fix fn_state's columns, as atomfile blocks."""
    p = model.particles
    n = p.count
    f0 = p.initial_forces if p.initial_forces is not None else np.zeros((n, 3))
    vt = p.display_velocities if p.display_velocities is not None else p.velocities
    values = [f0[:, 0], f0[:, 1], f0[:, 2], vt[:, 0], vt[:, 1], vt[:, 2]]
    title = ("fibrelmp: FibreNet's per-bead state (fix fn_state), read by in.lammps as 'variable\n"
             "fn_state atomfile': a block per column (a count, then 'atom-id value' lines); beads\n"
             "not listed are 0")
    atomic_write(path, atomfile_blocks(np.arange(1, n + 1), [
        (name, np.asarray(v, np.float64)) for name, v in zip(STATE_COLUMNS, values)], title))


def _native_output(model: Model, folder: Path, type_names: list[str],
                   plugin: bool) -> tuple[dict | None, NativeFiles | None]:
    """The ``fix fibrenet/output`` that writes FibreNet's files from inside LAMMPS (template
    values, and the files in the job folder), or (None, None): without fibrelmp's plugin, or
    when a name cannot reach LAMMPS verbatim, the job writes only its dump and fibrelmp
    converts the frames (``translate.fibrenet.target``), as before the plugin existed."""
    if not plugin:
        return None, None
    spec = model.plan.output
    prefix = Path(spec.basename).name
    names = [lammps_token(name) for name in type_names]
    problem = None
    try:
        prefix_text = lammps_path(prefix, "FibreNet output")
    except RunError:
        problem = f"output_file name {prefix!r} holds characters LAMMPS would interpret"
    bad = [name for name, token in zip(type_names, names) if token is None]
    if bad:
        problem = f"type name {bad[0]!r} is not one plain LAMMPS word"
    if problem is not None:
        model.warn(NATIVE_KIND, f"{problem}, so LAMMPS cannot write FibreNet's files itself: the "
                   "job writes frames.dump, which fibrelmp run converts (after lmp -in in.lammps: "
                   "fibrelmp post frames.dump --to xyz / --to res)")
        return None, None
    only = None
    if spec.types is not None:
        wanted = {model.particles.type_names[t] for t in spec.types}
        only = [k + 1 for k, name in enumerate(type_names) if name in wanted]
    production = [st for st in model.plan.stages if st.name == "production"][0]
    files = {"position": "coord", "velocity": "vel", "force": "force"}
    native = {"id": OUTPUT_FIX, "prefix": prefix_text, "names": names,
              "files": [files[f] for f in spec.fields], "only": only, "restart": production.steps}
    return native, NativeFiles([folder / f"{prefix}{XYZ_SUFFIX[f]}" for f in spec.fields],
                               folder / f"{prefix}{RESTART_SUFFIX}")


def _extra_packages(pair_styles, btypes: np.ndarray, use_mvv: bool) -> list[str]:
    """LAMMPS packages beyond MOLECULE and LEPTON this job needs (named in the script header)."""
    packages = []
    if "harmonic/cut" in pair_styles:
        packages.append("EXTRA-PAIR")
    if len(btypes) and bool(np.any((btypes[:, 2] > 0) & np.isfinite(btypes[:, 2]))):
        packages.append("MC")                 # fix bond/break
    if use_mvv:
        packages += ["DPD-MESO", "DPD-BASIC"]
    return packages


def _bonds_alive_at_first_step(model: Model):
    """Drop HR_FL springs already beyond their break length where the first step checks them.

    FibreNet tests the stress before the first force; fix bond/break acts only after the
    first integration, so such springs are left out of the data file instead.
    """
    from fibrelmp.model import Bonds

    b, p = model.bonds, model.particles
    breakable = np.isfinite(b.break_length)
    if not breakable.any():
        return b
    first = model.plan.stages[0]
    x = p.unwrapped.copy()
    if not (first.name == "relax" and first.reset):
        dt = model.dynamics.dt
        f0 = p.initial_forces if p.initial_forces is not None else np.zeros_like(x)
        mobile = p.masses > 0
        x += p.velocities * dt
        x[mobile] += 0.5 * dt * dt * f0[mobile] / p.masses[mobile, None]
    d = x[b.atoms[:, 0]] - x[b.atoms[:, 1]]
    broken = breakable & (np.sqrt((d * d).sum(1)) > b.break_length)
    if not broken.any():
        return b
    model.warn("HR_FL broken at start", f"{int(broken.sum())} HR_FL spring(s) exceed their break "
               "length at the first step; FibreNet breaks them before any force acts, so they are "
               "left out of the LAMMPS data file")
    keep = ~broken
    return Bonds(b.atoms[keep], b.k[keep], b.r0[keep], b.break_length[keep])


class _DataAtoms(NamedTuple):
    """What data.lammps and topology.bin both hold of the atoms, decided once for both."""
    bounds: list[tuple[float, float]]     # the box: on finite axes it holds every bead
    masses: list[float]                   # per LAMMPS type
    x: np.ndarray                         # unwrapped (read_data wraps them and sets image flags)
    v: np.ndarray | None                  # None: every bead at rest (+0.0, LAMMPS's start)


def _data_atoms(model: Model, ltypes: np.ndarray) -> _DataAtoms:
    p, box = model.particles, model.box
    x = p.unwrapped if any(box.periodic) else p.positions
    # finite axes: the box must hold beads already pushed into a wall (restarts); the walls
    # themselves sit at box.lo / box.hi in the script
    bounds = []
    for axis in range(3):
        lo, hi = box.lo[axis], box.hi[axis]
        if not box.periodic[axis] and p.count:
            margin = 1e-6 * (hi - lo)
            lo = min(lo, float(x[:, axis].min()) - margin)
            hi = max(hi, float(x[:, axis].max()) + margin)
        bounds.append((lo, hi))
    # mass-0 beads are not integrated: 1.0 is a placeholder
    masses = [float(row[1]) if row[1] > 0 else 1.0 for row in ltypes]
    v = p.velocities
    # a network at rest (e.g. 2.6M beads) has no velocities to write and for LAMMPS to read
    return _DataAtoms(bounds, masses, x, v if (v.any() or np.signbit(v).any()) else None)


def _write_topology(model: Model, bonds, path: Path, atoms: _DataAtoms, atype, btypes, btype, atypes,
                    antype) -> None:
    """``topology.bin``: what ``_write_data`` writes for ``read_data``, for fibrenet/read_data."""
    write_topology_file(
        path, atoms.bounds, atoms.masses, model.particles.molecules, atype + 1, atoms.x, atoms.v,
        bonds.atoms + 1, btype + 1, len(btypes) if bonds.count else 0,
        model.angles.atoms + 1, antype + 1, len(atypes) if model.angles.count else 0)


def _write_data(model: Model, bonds, path: Path, atoms: _DataAtoms, ltypes, atype, btypes, btype, atypes,
                antype, use_mvv: bool) -> None:
    p = model.particles
    n = p.count
    ids = np.arange(1, n + 1)
    counts = [(n, "atoms"), (bonds.count, "bonds"), (model.angles.count, "angles"),
              (len(ltypes), "atom types"), (len(btypes) if bonds.count else 0, "bond types"),
              (len(atypes) if model.angles.count else 0, "angle types")]
    x = atoms.x
    masses = [float_text(m) for m in atoms.masses]
    notes = [f"{comment_text(p.type_names[int(row[0])])} m={row[1]:g} R={row[2]:g}" for row in ltypes]
    sections = [DataSection("Masses", "%d %s  # %s\n", [np.arange(1, len(ltypes) + 1), masses, notes])]
    # unwrapped coordinates: read_data wraps them into periodic boxes and sets image flags
    if use_mvv:
        sections.append(DataSection("Atoms # hybrid angle mdpd", "%d %d %.17g %.17g %.17g %d 0\n",
                                    [ids, atype + 1, x[:, 0], x[:, 1], x[:, 2], p.molecules]))
    else:
        sections.append(DataSection("Atoms # angle", "%d %d %d %.17g %.17g %.17g\n",
                                    [ids, p.molecules, atype + 1, x[:, 0], x[:, 1], x[:, 2]]))
    if atoms.v is not None:
        v = atoms.v
        sections.append(DataSection("Velocities", "%d %.17g %.17g %.17g\n", [ids, v[:, 0], v[:, 1], v[:, 2]]))
    if bonds.count:
        b = bonds.atoms + 1
        sections.append(DataSection("Bonds", "%d %d %d %d\n",
                                    [np.arange(1, len(b) + 1), btype + 1, b[:, 0], b[:, 1]]))
    if model.angles.count:
        a = model.angles.atoms + 1
        sections.append(DataSection("Angles", "%d %d %d %d %d\n",
                                    [np.arange(1, len(a) + 1), antype + 1, a[:, 0], a[:, 1], a[:, 2]]))
    write_data_file(path, f"LAMMPS data file written by fibrelmp from {comment_text(model.source.name)}",
                    counts, atoms.bounds, sections)
