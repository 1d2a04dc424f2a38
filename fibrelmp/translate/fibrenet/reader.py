"""Read FibreNet input + model (+ restart) files into the neutral Model.

Semantics follow FibreNet's SimulationManager.cpp (commit fe11bbcc), not its README,
where the two disagree; see docs/fibrenet.md for every quirk and deviation.
This module reads the input file's keywords and applies them in FibreNet's order; the model
file is read by ``model_file.py``, the network's geometric checks are ``network_checks.py``.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.model import (Box, Dynamics, Model, OutputSpec, PairLaw, Particles,
                     RunPlan, Stage)
from fibrelmp.textio import read_text, to_float, to_int
from fibrelmp.units import LJ
from fibrelmp.translate.fibrenet.model_file import Springs, read_model
from fibrelmp.translate.fibrenet.network_checks import (bond_legs, check_lengths, check_periodic_extent,
                                                        check_positions, exclusion_rule, note_quirks)

EXTENSIONS = (".txt", ".in", ".inp")

# keyword -> (number of value tokens or None for "checked elsewhere", repeatable)
KEYWORDS: dict[str, tuple[int | None, bool]] = {
    "model_file": (1, False), "output_file": (1, False), "output_freq": (1, False),
    "output_data": (1, True), "output_type": (1, True), "restart_file": (1, True),
    "restart_data": (1, True), "run": (1, False), "minimize_steps": (1, False),
    "minimize_substeps": (1, False), "minimize_reset": (1, False), "step": (1, False),
    "cutoff": (1, False), "lambda": (1, False), "damping": (1, False), "gravity": (3, False),
    "type": (1, True), "pair": (None, True), "grid_update_freq": (1, False),
    "box_unit_cell": (1, False), "box_size": (3, False), "box_type": (1, False),
    "box_wall_rep": (1, False), "modif_bead": (None, True), "modif_spring": (None, True),
}
REQUIRED = ("model_file", "step", "lambda", "run", "cutoff", "box_unit_cell", "box_size",
            "box_type", "output_file", "output_freq", "output_type", "output_data")
MAX_CHUNK = 2 ** 31 - 1        # steps of one LAMMPS ``run`` (fibrelmp runs whole chunks)
_COMMENT = re.compile(r"^\s*(#|//|%|!)")


@dataclass
class _Line:
    number: int
    tokens: list[str]


class _InputFile:
    """FibreNet input: first token is the keyword; single keywords keep the first line."""

    def __init__(self, path: Path, notes: list[tuple[str, str]]):
        self.path = path
        self.lines: dict[str, list[_Line]] = {}
        for number, raw in enumerate(read_text(path, "FibreNet input file").splitlines(), 1):
            tokens = raw.split()
            if not tokens or _COMMENT.match(raw):
                continue
            key = tokens[0]
            if key == "box_wall_re":
                notes.append(("keyword alias", f"{path}:{number}: 'box_wall_re' (as in FibreNet's "
                              "README) is read as 'box_wall_rep'; real FibreNet ignores it and "
                              "leaves the wall stiffness uninitialised"))
                key = "box_wall_rep"
            if key not in KEYWORDS:
                hint = difflib.get_close_matches(key, KEYWORDS, n=1)
                extra = f" (did you mean '{hint[0]}'?)" if hint else ""
                raise InputError(path, number, f"unknown keyword '{key}'{extra}")
            nvalues, _ = KEYWORDS[key]
            if nvalues is not None and len(tokens) != nvalues + 1:
                raise InputError(path, number, f"'{key}' takes {nvalues} value(s), "
                                 f"found {len(tokens) - 1}")
            self.lines.setdefault(key, []).append(_Line(number, tokens))
        for key, found in self.lines.items():
            if not KEYWORDS[key][1] and len(found) > 1:
                notes.append(("repeated keyword", f"{path}:{found[1].number}: '{key}' repeated; "
                              f"FibreNet uses the first one (line {found[0].number})"))

    def first(self, key: str) -> _Line | None:
        found = self.lines.get(key)
        return found[0] if found else None

    def all(self, key: str) -> list[_Line]:
        return self.lines.get(key, [])

    def require(self, key: str) -> _Line:
        line = self.first(key)
        if line is None:
            raise InputError(self.path, None, f"required keyword '{key}' is missing")
        return line

    def number(self, key: str, default: float | None = None, positive: bool = False,
               nonnegative: bool = False) -> float:
        line = self.first(key)
        if line is None:
            if default is None:
                raise InputError(self.path, None, f"required keyword '{key}' is missing")
            return default
        value = to_float(line.tokens[1], self.path, line.number, key)
        if positive and value <= 0:
            raise InputError(self.path, line.number, f"'{key}' must be > 0, got {line.tokens[1]}")
        if nonnegative and value < 0:
            raise InputError(self.path, line.number, f"'{key}' must be >= 0, got {line.tokens[1]}")
        return value

    def integer(self, key: str, default: int | None = None, minimum: int = 0,
                maximum: int | None = None) -> int:
        line = self.first(key)
        if line is None:
            if default is None:
                raise InputError(self.path, None, f"required keyword '{key}' is missing")
            return default
        value = to_int(line.tokens[1], self.path, line.number, key)
        if value < minimum:
            raise InputError(self.path, line.number, f"'{key}' must be >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise InputError(self.path, line.number, f"'{key}' must be <= {maximum}, the most "
                             f"steps one LAMMPS run command takes; got {value}")
        return value


def read(path: str | Path) -> Model:
    """Read a FibreNet input file (and the files it names) into a Model.

    The steps run in FibreNet's order, so the first error reported is the one FibreNet
    would meet first."""
    path = Path(path)
    notes: list[tuple[str, str]] = []
    inp = _InputFile(path, notes)
    for key in REQUIRED:
        if key != "box_wall_rep":
            inp.require(key)
    folder = path.parent
    type_names, type_index, cutoff, pairs = _types_and_pairs(inp)
    box = _box(inp, notes)
    settings = _run_settings(inp)

    model_line = inp.require("model_file")
    model_path = folder / model_line.tokens[1]
    if not model_path.exists():
        raise InputError(path, model_line.number, f"model file '{model_line.tokens[1]}' not found "
                         f"(looked in {folder})")
    particles, springs, angles = read_model(model_path, type_index, type_names, box.lengths, notes)

    # restart, modif_bead, modif_spring: FibreNet's order
    restart = _apply_restart(inp, particles, type_names, notes)
    _apply_modif_bead(inp, particles, type_index, notes, pairs)
    quirk = (particles.velocities != particles.display_velocities).any(axis=1)
    if quirk.any():
        row = int(np.flatnonzero(quirk)[0])
        notes.append(("velocity quirk", f"{model_path}: bead {row}: FibreNet starts beads from "
                      "v = (vx, vx, vx) (a bug in its model reader); fibrelmp reproduces it. "
                      "Use 'modif_bead ... velocity' to set other velocities"))
    _apply_modif_spring(inp, springs, notes)
    bonds = springs.to_bonds()
    periodic = all(box.periodic)
    check_positions(particles, box, periodic, model_path, notes)
    legs = bond_legs(particles, bonds, angles)
    check_lengths(particles, legs, model_path)
    check_periodic_extent(particles, legs, box, model_path)
    exclusion = exclusion_rule(particles, bonds, model_path)

    output = _output_spec(inp, type_index, settings.out_freq)
    stages = _stages(inp, settings, notes)
    dyn = Dynamics(dt=settings.dt, damping=settings.damping, lambda_=settings.lam,
                   gravity=settings.gravity, pair_cutoff=cutoff, exclusion=exclusion)
    note_quirks(particles, bonds, angles, legs, pairs, dyn, notes, model_path)
    model = Model(path, particles, bonds, angles, pairs, box, dyn, RunPlan(stages, output),
                  units=LJ.name)
    model.warnings.extend(notes)
    model.inputs = [path, model_path] + ([restart] if restart is not None else [])
    return model


def _types_and_pairs(inp: _InputFile) -> tuple[list[str], dict[str, int], float, list[PairLaw]]:
    """The bead types, the pair cutoff and one pair law per type pair (all must be given)."""
    path = inp.path
    type_names: list[str] = []
    for line in inp.all("type"):
        if line.tokens[1] in type_names:
            raise InputError(path, line.number, f"type '{line.tokens[1]}' defined twice")
        type_names.append(line.tokens[1])
    if not type_names:
        raise InputError(path, None, "no 'type' lines: at least one bead type is needed")
    type_index = {name: i for i, name in enumerate(type_names)}
    cutoff = inp.number("cutoff", positive=True)
    pair_lines: dict[tuple[int, int], _Line] = {}
    for line in inp.all("pair"):
        t = line.tokens
        if len(t) < 5:
            raise InputError(path, line.number, "'pair' needs: pair hs|st|lj TYPE TYPE values...")
        for name in t[2:4]:
            if name not in type_index:
                raise InputError(path, line.number, f"pair refers to undefined type '{name}'")
        i, j = sorted((type_index[t[2]], type_index[t[3]]))
        pair_lines[(i, j)] = line        # later lines override earlier ones, as in FibreNet
    pairs = [_pair_law(path, line, i, j, cutoff) for (i, j), line in sorted(pair_lines.items())]
    for i in range(len(type_names)):
        for j in range(i, len(type_names)):
            if (i, j) not in pair_lines:
                raise InputError(path, None, f"no 'pair' line for types {type_names[i]} "
                                 f"{type_names[j]}: FibreNet needs every type pair defined")
    return type_names, type_index, cutoff, pairs


def _box(inp: _InputFile, notes: list) -> Box:
    path = inp.path
    size_line = inp.require("box_size")
    size = np.array([to_float(v, path, size_line.number, "box_size") for v in size_line.tokens[1:]])
    if (size <= 0).any():
        raise InputError(path, size_line.number, "box_size values must be > 0")
    box_type = inp.require("box_type")
    if box_type.tokens[1] not in ("pbc", "finite"):
        raise InputError(path, box_type.number, f"box_type must be 'pbc' or 'finite', got "
                         f"'{box_type.tokens[1]}'")
    if inp.first("box_wall_rep") is None:
        raise InputError(path, None, "'box_wall_rep' is missing: without it FibreNet silently "
                         "uses a finite box with an uninitialised wall stiffness")
    wall_k = inp.number("box_wall_rep", nonnegative=True)
    periodic = box_type.tokens[1] == "pbc"
    unit_cell = inp.number("box_unit_cell", positive=True)
    if (np.floor(size / unit_cell) < 3).any():
        notes.append(("neighbour grid", f"{path}:{inp.first('box_unit_cell').number}: FibreNet "
                      "needs at least 3 grid cells per axis (box_size / box_unit_cell); LAMMPS "
                      "does not, so this input runs here but not in FibreNet"))
    if inp.first("grid_update_freq") is not None:
        inp.integer("grid_update_freq", minimum=1)
    return Box(np.zeros(3), size, (periodic,) * 3, None if periodic else wall_k)


@dataclass
class _RunSettings:
    dt: float
    lam: float
    damping: float
    gravity: np.ndarray
    run_steps: int
    min_steps: int
    min_sub: int
    reset: bool
    out_freq: int


def _run_settings(inp: _InputFile) -> _RunSettings:
    """Time step, damping, gravity, relaxation and production lengths, output frequency."""
    path = inp.path
    dt = inp.number("step", positive=True)
    lam = inp.number("lambda", positive=True)
    damping = inp.number("damping", default=0.0)
    gravity = np.zeros(3)
    if (g := inp.first("gravity")) is not None:
        gravity = np.array([to_float(v, path, g.number, "gravity") for v in g.tokens[1:]])
    run_steps = inp.integer("run", minimum=0)
    min_steps = inp.integer("minimize_steps", default=0)
    sub_default = min_steps if min_steps > 0 else 0
    min_sub = inp.integer("minimize_substeps", default=sub_default, maximum=MAX_CHUNK)
    if min_sub > min_steps:
        raise InputError(path, inp.first("minimize_substeps").number,
                         "minimize_substeps must not exceed minimize_steps")
    if min_steps > 0 and min_sub == 0:
        raise InputError(path, inp.first("minimize_substeps").number,
                         "minimize_substeps 0 with minimize_steps > 0 (FibreNet divides by zero)")
    reset = False
    if (r := inp.first("minimize_reset")) is not None:
        if r.tokens[1] not in ("yes", "no"):
            raise InputError(path, r.number, f"minimize_reset must be yes or no, got '{r.tokens[1]}'")
        reset = r.tokens[1] == "yes"
    out_freq = inp.integer("output_freq", minimum=1, maximum=MAX_CHUNK)
    if out_freq > run_steps:
        raise InputError(path, inp.first("output_freq").number,
                         f"output_freq ({out_freq}) must not exceed run ({run_steps})")
    return _RunSettings(dt, lam, damping, gravity, run_steps, min_steps, min_sub, reset, out_freq)


def _apply_restart(inp: _InputFile, particles: Particles, type_names: list[str],
                   notes: list) -> Path | None:
    """Apply ``restart_file``/``restart_data``; the restart file read, if any."""
    path, folder, n = inp.path, inp.path.parent, particles.count
    restart_lines = inp.all("restart_file")
    restart_fields = _data_fields(inp, "restart_data")
    if not restart_lines:
        return None
    rline = restart_lines[-1]           # the last restart_file line wins
    rpath = folder / rline.tokens[1]
    if not rpath.exists():
        raise InputError(path, rline.number, f"restart file '{rline.tokens[1]}' not found")
    from fibrelmp.translate.fibrenet.writer import read_restart

    rtypes, rdata = read_restart(rpath)
    if len(rtypes) != n:
        raise InputError(rpath, None, f"restart file has {len(rtypes)} bead rows, the model has {n}")
    mismatch = np.flatnonzero(np.asarray(rtypes, dtype=object) !=
                              np.asarray(type_names, dtype=object)[particles.types])
    if mismatch.size:
        b = int(mismatch[0])
        raise InputError(rpath, None, f"bead {b}: restart type '{rtypes[b]}' differs from the "
                         f"model type '{type_names[particles.types[b]]}'")
    if "position" in restart_fields:
        particles.positions = rdata[:, 0:3].copy()
        particles.unwrapped = rdata[:, 3:6].copy()
    if "velocity" in restart_fields:
        particles.velocities = rdata[:, 6:9].copy()
        particles.display_velocities = rdata[:, 6:9].copy()
    if "force" in restart_fields:
        particles.initial_forces = rdata[:, 9:12].copy()
    if not restart_fields:
        notes.append(("restart ignored", f"{path}:{rline.number}: restart_file without "
                      "restart_data: FibreNet only validates the file and applies nothing"))
    return rpath


def _data_fields(inp: _InputFile, key: str) -> set[str]:
    """The fields named by every ``key`` line (``restart_data``/``output_data``): position,
    velocity, force, or all of them."""
    fields: set[str] = set()
    for line in inp.all(key):
        value = line.tokens[1]
        if value not in ("position", "velocity", "force", "all"):
            raise InputError(inp.path, line.number, f"{key} must be position, velocity, force "
                             f"or all, got '{value}'")
        fields |= {"position", "velocity", "force"} if value == "all" else {value}
    return fields


def _output_spec(inp: _InputFile, type_index: dict[str, int], out_freq: int) -> OutputSpec:
    path = inp.path
    fields = _data_fields(inp, "output_data")
    out_types: set[int] | None = set()
    for line in inp.all("output_type"):
        if line.tokens[1] == "all":
            out_types = None
            break
        if line.tokens[1] not in type_index:
            raise InputError(path, line.number, f"output_type refers to undefined type "
                             f"'{line.tokens[1]}'")
        out_types.add(type_index[line.tokens[1]])
    return OutputSpec("fibrenet", inp.require("output_file").tokens[1], path.parent,
                      tuple(f for f in ("position", "velocity", "force") if f in fields),
                      None if out_types is None else tuple(sorted(out_types)), out_freq,
                      inp.require("output_file").number)


def _stages(inp: _InputFile, s: _RunSettings, notes: list) -> list[Stage]:
    """Relaxation in chunks (FibreNet drops a remainder), then production with output."""
    stages: list[Stage] = []
    if s.min_steps > 0:
        chunks = s.min_steps // s.min_sub
        if chunks * s.min_sub != s.min_steps:
            notes.append(("minimize remainder", f"{inp.path}: minimize_steps {s.min_steps} is not a "
                          f"multiple of minimize_substeps {s.min_sub}; FibreNet drops the last "
                          f"{s.min_steps - chunks * s.min_sub} steps, so does fibrelmp"))
        stages.append(Stage("relax", chunks * s.min_sub, s.min_sub, reset=s.reset))
    stages.append(Stage("production", s.run_steps, s.out_freq, output=True))
    return stages


def _pair_law(path: Path, line: _Line, i: int, j: int, cutoff: float) -> PairLaw:
    t = line.tokens
    kind = t[1]
    need = {"hs": 5, "st": 8, "lj": 7}
    if kind not in need:
        raise InputError(path, line.number, f"unknown pair kind '{kind}' (hs, st or lj)")
    if len(t) != need[kind]:
        raise InputError(path, line.number, f"pair {kind} takes {need[kind] - 4} values, "
                         f"found {len(t) - 4}")
    v = [to_float(x, path, line.number, f"pair {kind}") for x in t[4:]]
    if kind == "hs":
        return PairLaw("hs", i, j, {"K": v[0]})
    if kind == "st":
        krep, katt, l0, rc = v
        if rc <= 0:
            raise InputError(path, line.number, "pair st cutoff must be > 0")
        b = katt + krep
        # What FibreNet actually runs: F = Katt(l0-r) + Krep(2 l0 - rc - r) for r < rc.
        rstar = (katt * l0 + krep * (2 * l0 - rc)) / b if b != 0 else 0.0
        return PairLaw("st", i, j, {"Krep": krep, "Katt": katt, "l0": l0, "rc": rc, "B": b,
                                    "rstar": rstar, "cutoff": min(rc, cutoff)})
    sigma, eps, shift = v
    if shift <= 0:
        raise InputError(path, line.number, "pair lj cutoff (third value) must be > 0")
    return PairLaw("lj", i, j, {"sigma": sigma, "epsilon": eps, "shift": shift,
                                "cutoff": min(shift, cutoff)})


def _select(tokens: list[str], particles: Particles, type_index: dict[str, int], path: Path,
            number: int) -> np.ndarray:
    how, what = tokens[1], tokens[2]
    if how == "type":
        if what not in type_index:
            raise InputError(path, number, f"modif_bead: undefined type '{what}'")
        return particles.types == type_index[what]
    value = to_int(what, path, number, f"modif_bead {how}")
    if how == "tag":
        return particles.molecules == value
    if how == "id":
        if not 0 <= value < particles.count:
            raise InputError(path, number, f"modif_bead id {value} out of range 0..{particles.count - 1}")
        mask = np.zeros(particles.count, bool)
        mask[value] = True
        return mask
    raise InputError(path, number, f"modif_bead selects by type, tag or id, got '{how}'")


def _apply_modif_bead(inp: _InputFile, p: Particles, type_index: dict[str, int], notes: list,
                      pairs: list = ()) -> None:
    for line in inp.all("modif_bead"):
        t, ln = line.tokens, line.number
        if len(t) < 5:
            raise InputError(inp.path, ln, "modif_bead needs: modif_bead type|tag|id X mass|velocity|skin_radius values")
        mask = _select(t, p, type_index, inp.path, ln)
        prop = t[3]
        if prop == "mass":
            if len(t) != 5:
                raise InputError(inp.path, ln, "modif_bead ... mass takes 1 value")
            m = to_float(t[4], inp.path, ln, "mass")
            if m < 0:
                raise InputError(inp.path, ln, "mass must be >= 0")
            p.masses[mask] = m
        elif prop == "velocity":
            if len(t) != 7:
                raise InputError(inp.path, ln, "modif_bead ... velocity takes 3 values")
            v = np.array([to_float(x, inp.path, ln, "velocity") for x in t[4:7]])
            p.velocities[mask] = v
            p.display_velocities[mask] = v
        elif prop == "skin_radius":
            if len(t) != 5:
                raise InputError(inp.path, ln, "modif_bead ... skin_radius takes 1 value")
            skin = to_float(t[4], inp.path, ln, "skin_radius")
            notes.append(_skin_note(f"{inp.path}:{ln}", skin, p, mask, pairs))
        else:
            raise InputError(inp.path, ln, f"modif_bead property must be mass, velocity or "
                             f"skin_radius, got '{prop}'")


def _skin_note(where: str, skin: float, p: Particles, mask: np.ndarray, pairs) -> tuple[str, str]:
    """The warning of ``modif_bead ... skin_radius``.  FibreNet lists an hs pair only when, at
    its list build (every grid_update_freq steps), r < max(R_i, R_j) + min(skin_i, skin_j)
    (kernel.cl), and pushes listed pairs while they overlap until the next build.  A skin
    below the radii therefore makes the real code miss overlapping pairs (how long depends on
    when its list was built: an artefact, not a cut-off); fibrelmp keeps every contact."""
    selected = set(int(x) for x in np.unique(p.types[mask]))
    missed = None                        # (contact distance, listing distance) of a missed pair
    for law in pairs:
        if law.kind != "hs":
            continue
        for a, b in ((law.type_i, law.type_j), (law.type_j, law.type_i)):
            if a not in selected or not (p.types == b).any():
                continue
            r_a = float(p.radii[mask & (p.types == a)].max())
            r_b = float(p.radii[p.types == b].max())
            if skin < min(r_a, r_b) and (missed is None or r_a + r_b > missed[0]):
                missed = (r_a + r_b, max(r_a, r_b) + skin)
    if missed is None:
        return ("skin radius", f"{where}: skin_radius {skin:g} only sets how far FibreNet's hs "
                "contact list reaches (max(R_i, R_j) + min(skin_i, skin_j), built every "
                "grid_update_freq steps); it reaches every contact here, and LAMMPS's neighbour "
                "lists never see a contact late, so it has no effect in fibrelmp")
    contact, listed = missed
    return ("skin radius below the bead radius",
            f"{where}: skin_radius {skin:g} is below the radius of these beads: the real FibreNet "
            f"lists an hs pair only when r < max(R_i, R_j) + min(skin_i, skin_j) (here {listed:g}) "
            f"at its list builds, so pairs overlapping at {listed:g} <= r < {contact:g} (R_i + R_j) "
            "get no hs force there until a list build finds them closer (then the force jumps in); "
            "fibrelmp keeps the full contact force K (R_i + R_j - r) for every overlap, so its "
            "results differ from FibreNet's while such pairs overlap (docs/fibrenet.md)")


def _apply_modif_spring(inp: _InputFile, springs: Springs, notes: list) -> None:
    for line in inp.all("modif_spring"):
        t, ln = line.tokens, line.number
        if len(t) != 5:
            raise InputError(inp.path, ln, "modif_spring needs: modif_spring id|tag N "
                             "rest_length|stiffness|c1|c2|damping value")
        how = t[1]
        sel = to_int(t[2], inp.path, ln, f"modif_spring {how}")
        if how == "id":
            if not 0 <= sel < len(springs.r0):
                raise InputError(inp.path, ln, f"modif_spring id {sel} out of range 0..{len(springs.r0) - 1}")
            mask = np.arange(len(springs.r0)) == sel
        elif how == "tag":
            mask = springs.tags == sel
        else:
            raise InputError(inp.path, ln, f"modif_spring selects by id or tag, got '{how}'")
        value = to_float(t[4], inp.path, ln, f"modif_spring {t[3]}")
        if t[3] == "rest_length":
            springs.r0[mask] = value
        elif t[3] == "stiffness":
            springs.k[mask] = value
        elif t[3] == "c1":      # read with std::stod here, unlike the model file
            springs.c1[mask] = value
        elif t[3] == "c2":
            springs.c2[mask] = value
        elif t[3] == "damping":
            notes.append(("spring damping unused", f"{inp.path}:{ln}: FibreNet stores a spring "
                          "damping value but its kernel never uses it; ignored"))
        else:
            raise InputError(inp.path, ln, f"modif_spring property must be rest_length, "
                             f"stiffness, c1, c2 or damping, got '{t[3]}'")


# --------------------------------------------------------------------------- fibrelmp check
# Values that pass every check, appended by ``fibrelmp check`` when a required keyword is
# missing (or its line was taken out), so that checking goes on.
_NEUTRAL = {"step": "1", "lambda": "0.5", "cutoff": "1", "box_unit_cell": "1",
            "box_type": "pbc", "box_wall_rep": "0", "box_size": "1e300 1e300 1e300",
            "run": str(MAX_CHUNK), "output_freq": "1", "output_file": "out",
            "output_data": "all", "output_type": "all"}
_MISSING = re.compile(r"required keyword '(\w+)' is missing|'(box_wall_rep)' is missing|"
                      r"no 'pair' line for types (\S+) (\S+):")


def check_patch(input_path: str | Path):
    """What ``textio.collect_errors`` puts in place of a failing line of a FibreNet input or
    model file while ``fibrelmp check`` looks for further errors.

    A BEAD line becomes a bead of the first type at the origin with a tag of its own (beads
    are numbered by line, so removing one would shift every spring after it); a keyword line
    is blanked (a 'type' line first loses surplus names); a missing keyword or pair gets a neutral
    line appended."""
    def first_type() -> str | None:
        try:
            text = read_text(input_path, "FibreNet input file")
        except InputError:
            return None
        for raw in text.splitlines():
            tok = raw.split()
            if len(tok) == 2 and tok[0] == "type":
                return tok[1]
        return None

    def patch(err: InputError, line: str | None, attempt: int) -> str | None:
        if line is None:
            m = _MISSING.search(err.message)
            if m is None:
                return None
            key = m.group(1) or m.group(2)
            if key is None:
                return f"pair hs {m.group(3)} {m.group(4)} 0"
            return f"{key} {_NEUTRAL[key]}" if key in _NEUTRAL else None
        tok = line.split()
        key = tok[0] if tok else ""
        candidates: list[str] = []
        if key == "BEAD" and (name := first_type()) is not None:
            candidates.append(f"BEAD {name} {-(2 ** 40 + (err.line or 0))} 0" + " 0" * 14)
        elif key == "type" and len(tok) > 2:     # keep the type defined: beads use it
            candidates.append(" ".join(tok[:2]))
        candidates.append("")
        return candidates[attempt] if attempt < len(candidates) else None
    return patch
