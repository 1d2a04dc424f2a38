"""An independent numpy reference of FibreNet's physics, for the physics tests.

Written from shared/research/fibrenet.md (sections 1-6: kernel.cl / SimulationManager.cpp
semantics), NOT from fibrelmp: nothing here imports fibrelmp.  Everything is plain double
precision and O(n^2) (all bead pairs every step), so it is only meant for a few dozen beads.

Contents
* ``Net``: a tiny builder.  It writes a FibreNet ``model.txt`` + ``input.txt`` pair and
  builds the matching reference ``System`` with FibreNet's parse semantics (HR_FL c1/c2
  through ``std::stoi``, angle theta0 through ``std::stof``, model velocities read as
  (vx, vx, vx), ``modif_bead`` applied after the model).
* the force laws (``spring_forces``, ``angle_forces``, ``pair_forces``, ``wall_forces``,
  ``total_forces``), each returning per-bead forces and the potential energy;
* ``integrate``: FibreNet's modified velocity-Verlet step (section 1 steps 1-5);
* ``simulate``: minimisation chunks (with or without ``minimize_reset``) then the
  production run, returning the frames FibreNet would write.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


# ---------------------------------------------------------------------------------------
# the system
# ---------------------------------------------------------------------------------------
@dataclass
class System:
    L: np.ndarray                      # (3,) box lengths, box is [0, L]
    periodic: bool
    wall_k: float | None               # finite box wall stiffness (None: periodic)
    types: np.ndarray                  # (n,) int index into type_names
    type_names: list[str]
    radius: np.ndarray                 # (n,)
    mass: np.ndarray                   # (n,)  0 = constant velocity
    tag: np.ndarray                    # (n,)
    loc: np.ndarray                    # (n,)
    springs: np.ndarray                # (m,2)
    r0: np.ndarray                     # (m,)
    k: np.ndarray                      # (m,)
    fl: np.ndarray                     # (m,) bool: HR_FL spring
    c1: np.ndarray                     # (m,) HR_FL parameters (as FibreNet holds them)
    c2: np.ndarray
    angles: np.ndarray                 # (a,3), middle bead is the vertex
    theta0: np.ndarray                 # (a,) radians
    ac: np.ndarray                     # (a,)  E = ac (theta - theta0)^2
    angle_fl: np.ndarray               # (a,) bool: HR_FL angle (disabled when s1/s2 broke)
    angle_springs: np.ndarray          # (a,2) spring indices s1, s2
    # (ti, tj), ti <= tj -> ("hs", K) | ("st", Krep, Katt, l0, rc) | ("lj", sigma, eps, c3)
    pairs: dict
    cutoff: float                      # global cutoff (st and lj only)
    dt: float = 1e-3
    lam: float = 0.5
    damping: float = 0.0
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @property
    def n(self) -> int:
        return len(self.types)


@dataclass
class State:
    x: np.ndarray          # wrapped positions
    xu: np.ndarray         # unwrapped positions (springs, angles)
    v_old: np.ndarray      # the "true" velocity
    vt: np.ndarray         # v~ (what the velocity file shows)
    F: np.ndarray          # total force of the last step
    broken: np.ndarray     # (m,) bool, HR_FL springs that broke

    def copy(self) -> "State":
        return State(*(a.copy() for a in (self.x, self.xu, self.v_old, self.vt, self.F, self.broken)))


@dataclass
class Frame:
    step: int
    x: np.ndarray
    xu: np.ndarray
    vt: np.ndarray
    F: np.ndarray


def _wrap(sys_: System, x: np.ndarray) -> np.ndarray:
    if not sys_.periodic:
        return x
    return np.mod(x, sys_.L)


def _min_image(sys_: System, d: np.ndarray) -> np.ndarray:
    if not sys_.periodic:
        return d
    return d - sys_.L * np.round(d / sys_.L)


# ---------------------------------------------------------------------------------------
# force laws: every function returns (F (n,3), E)
# ---------------------------------------------------------------------------------------
def hr_fl_overstressed(sys_: System, xu: np.ndarray) -> np.ndarray:
    """HR_FL springs whose stress |c1 (r - r0) / r| exceeds c2 (tension or compression)."""
    if not len(sys_.springs):
        return np.zeros(0, bool)
    d = xu[sys_.springs[:, 1]] - xu[sys_.springs[:, 0]]
    r = np.sqrt((d * d).sum(1))
    return sys_.fl & (np.abs(sys_.c1 * (r - sys_.r0) / r) > sys_.c2)


def spring_forces(sys_: System, xu: np.ndarray, broken: np.ndarray | None = None):
    """HR springs: F_1 = k (r0 - r) r_hat_12 on unwrapped positions (no minimum image)."""
    F = np.zeros((sys_.n, 3))
    if not len(sys_.springs):
        return F, 0.0
    live = np.ones(len(sys_.springs), bool) if broken is None else ~broken
    i, j = sys_.springs[live, 0], sys_.springs[live, 1]
    d = xu[j] - xu[i]                          # from 1 to 2
    r = np.sqrt((d * d).sum(1))
    dr = r - sys_.r0[live]
    f = (sys_.k[live] * dr / r)[:, None] * d   # force on bead 1 (towards 2 when stretched)
    np.add.at(F, i, f)
    np.add.at(F, j, -f)
    return F, float((0.5 * sys_.k[live] * dr * dr).sum())


def angle_terms(u: np.ndarray, v: np.ndarray):
    """theta between u = a - b and v = c - b, and d theta / d a, d theta / d c (exact)."""
    ru = np.sqrt((u * u).sum(1))
    rv = np.sqrt((v * v).sum(1))
    uh, vh = u / ru[:, None], v / rv[:, None]
    cross = np.cross(uh, vh)
    sin = np.sqrt((cross * cross).sum(1))
    cos = (uh * vh).sum(1)
    theta = np.arctan2(sin, cos)              # accurate also near 0 and pi
    # d cos/da = (vh - cos uh)/|u|,  d theta = -d cos / sin
    dth_da = (cos[:, None] * uh - vh) / (ru * sin)[:, None]
    dth_dc = (cos[:, None] * vh - uh) / (rv * sin)[:, None]
    return theta, dth_da, dth_dc


def angle_forces(sys_: System, xu: np.ndarray, broken: np.ndarray | None = None):
    """E = c (theta - theta0)^2, F = -dE/dx with the exact gradient (no clamp of sin)."""
    F = np.zeros((sys_.n, 3))
    if not len(sys_.angles):
        return F, 0.0
    live = np.ones(len(sys_.angles), bool)
    if broken is not None and broken.any():
        dead = broken[sys_.angle_springs[:, 0]] | broken[sys_.angle_springs[:, 1]]
        live = ~(sys_.angle_fl & dead)
    a, b, c = (sys_.angles[live, k] for k in range(3))
    theta, da, dc = angle_terms(xu[a] - xu[b], xu[c] - xu[b])
    dtheta = theta - sys_.theta0[live]
    g = (-2.0 * sys_.ac[live] * dtheta)[:, None]
    fa, fc = g * da, g * dc
    np.add.at(F, a, fa)
    np.add.at(F, c, fc)
    np.add.at(F, b, -(fa + fc))
    return F, float((sys_.ac[live] * dtheta * dtheta).sum())


def excluded(sys_: System, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """FibreNet: no non-bonded interaction for the same tag and |loc_i - loc_j| <= 1."""
    return (sys_.tag[i] == sys_.tag[j]) & (np.abs(sys_.loc[i] - sys_.loc[j]) <= 1)


def pair_forces(sys_: System, x: np.ndarray):
    """hs / st / lj between all bead pairs, on wrapped positions with minimum image."""
    n = sys_.n
    F = np.zeros((n, 3))
    if n < 2:
        return F, 0.0
    i, j = np.triu_indices(n, 1)
    keep = ~excluded(sys_, i, j)
    i, j = i[keep], j[keep]
    d = _min_image(sys_, x[j] - x[i])          # from i to j
    r = np.sqrt((d * d).sum(1))
    ti, tj = np.minimum(sys_.types[i], sys_.types[j]), np.maximum(sys_.types[i], sys_.types[j])
    fmag = np.zeros(len(i))                    # > 0 is repulsive
    energy = 0.0
    for (a, b), law in sys_.pairs.items():
        sel = (ti == a) & (tj == b)
        if not sel.any():
            continue
        rr = r[sel]
        f = np.zeros(len(rr))
        e = np.zeros(len(rr))
        if law[0] == "hs":
            K = law[1]
            overlap = sys_.radius[i[sel]] + sys_.radius[j[sel]] - rr
            on = overlap > 0                   # hs ignores the global cutoff
            f[on] = K * overlap[on]
            e[on] = 0.5 * K * overlap[on] ** 2
        elif law[0] == "st":
            krep, katt, l0, rc = law[1:]
            on = rr < min(rc, sys_.cutoff)
            f[on] = katt * (l0 - rr[on]) + krep * (2 * l0 - rc - rr[on])
            B = katt + krep
            rstar = (katt * l0 + krep * (2 * l0 - rc)) / B
            e[on] = 0.5 * B * (rr[on] - rstar) ** 2
        elif law[0] == "lj":
            s, eps, c3 = law[1:]

            def lj_force(q):
                s6 = (s / q) ** 6
                return 48.0 * eps * s6 * (s6 - 0.5) / q ** 2

            fc = lj_force(c3)
            on = rr < min(c3, sys_.cutoff)
            q = rr[on]
            f[on] = lj_force(q) - fc
            e[on] = 48 * eps * s ** 12 / (13 * q ** 13) - 24 * eps * s ** 6 / (7 * q ** 7) + fc * q
        else:
            raise ValueError(law[0])
        fmag[sel] = f
        energy += float(e.sum())
    fv = (fmag / r)[:, None] * d              # force on j (away from i when repulsive)
    np.add.at(F, j, fv)
    np.add.at(F, i, -fv)
    return F, energy


def wall_forces(sys_: System, x: np.ndarray):
    """Finite box: F = k * penetration beyond 0 and L on each axis, E = k/2 pen^2."""
    F = np.zeros((sys_.n, 3))
    if sys_.periodic or sys_.wall_k is None:
        return F, 0.0
    below = np.where(x < 0, -x, 0.0)
    above = np.where(x > sys_.L, x - sys_.L, 0.0)
    F += sys_.wall_k * below - sys_.wall_k * above
    return F, float(0.5 * sys_.wall_k * ((below ** 2).sum() + (above ** 2).sum()))


def total_forces(sys_: System, x: np.ndarray, xu: np.ndarray, v_drag: np.ndarray,
                 broken: np.ndarray | None = None):
    """Total force (drag on ``v_drag``, gravity as a force, walls, springs, angles, pairs)
    and the potential energy (springs + angles + pairs + walls)."""
    F = -sys_.damping * v_drag + sys_.gravity[None, :]
    E = 0.0
    for part in (wall_forces(sys_, x), spring_forces(sys_, xu, broken),
                 angle_forces(sys_, xu, broken), pair_forces(sys_, x)):
        F = F + part[0]
        E += part[1]
    return F, E


# ---------------------------------------------------------------------------------------
# the integrator
# ---------------------------------------------------------------------------------------
def integrate(sys_: System, state: State, steps: int, every: int | None = None,
              first_step: int = 0) -> tuple[State, list[Frame]]:
    """FibreNet's modified velocity-Verlet (research note section 1), ``steps`` steps.

    Per step: v~ = v_old + lambda dt F/m; x += v_old dt + dt^2 F/(2m); F_old = F;
    F = -damping v~ + g + walls + springs + angles + pairs (HR_FL break test first);
    v_old += dt (F + F_old)/(2m).  Mass-0 beads: every dt/m factor is 0.
    Returns the final state and a frame every ``every`` steps (and at the end).
    """
    s = state.copy()
    dt, lam = sys_.dt, sys_.lam
    inv = np.where(sys_.mass > 0, 1.0 / np.where(sys_.mass > 0, sys_.mass, 1.0), 0.0)[:, None]
    frames: list[Frame] = []
    for k in range(1, steps + 1):
        s.vt = s.v_old + lam * dt * s.F * inv
        dx = s.v_old * dt + 0.5 * dt * dt * s.F * inv
        s.xu = s.xu + dx
        s.x = _wrap(sys_, s.x + dx)
        F_old = s.F
        s.broken = s.broken | hr_fl_overstressed(sys_, s.xu)
        s.F, _ = total_forces(sys_, s.x, s.xu, s.vt, s.broken)
        s.v_old = s.v_old + 0.5 * dt * inv * (s.F + F_old)
        if every and (k % every == 0 or k == steps):
            frames.append(Frame(first_step + k, s.x.copy(), s.xu.copy(), s.vt.copy(), s.F.copy()))
    return s, frames


def reset(state: State) -> State:
    """FibreNet ResetBeadEnergy: v, v_old, F and F_old become zero (all beads)."""
    s = state.copy()
    s.v_old[:] = 0.0
    s.vt[:] = 0.0
    s.F[:] = 0.0
    return s


def simulate(sys_: System, state: State, run: int, every: int, minimize_steps: int = 0,
             minimize_substeps: int | None = None, minimize_reset: bool = False) -> list[Frame]:
    """Minimisation chunks (no output, step counter restarts) then the production run.

    Frames: step 0 (after minimisation), every ``every`` steps and the final step.
    """
    s = state.copy()
    if minimize_steps > 0:
        sub = minimize_substeps or minimize_steps
        for _ in range(minimize_steps // sub):
            if minimize_reset:
                s = reset(s)
            s, _ = integrate(sys_, s, sub)
        if minimize_reset:
            s = reset(s)
    frames = [Frame(0, s.x.copy(), s.xu.copy(), s.vt.copy(), s.F.copy())]
    _, more = integrate(sys_, s, run, every)
    return frames + more


# ---------------------------------------------------------------------------------------
# a builder writing FibreNet files and the matching reference system
# ---------------------------------------------------------------------------------------
def _num(x: float) -> str:
    return repr(float(x))


def fibrenet_stoi(token: str) -> int:
    """std::stoi: the leading integer of the token ("7e6" -> 7, "0.5" -> 0)."""
    return int(re.match(r"\s*[+-]?\d+", token).group())


def fibrenet_stof(token: str) -> float:
    """std::stof: the value rounded to single precision."""
    return float(np.float32(float(token)))


class Net:
    """Collects beads, springs, angles, pairs and settings; writes FibreNet files."""

    def __init__(self, box, periodic=False, wall_k=1000.0, cutoff=1.0, dt=1e-3, lam=0.5,
                 damping=0.0, gravity=(0.0, 0.0, 0.0), unit_cell=None):
        self.L = np.asarray(box, float)
        self.periodic = periodic
        self.wall_k = wall_k
        self.cutoff = cutoff
        self.dt, self.lam, self.damping = dt, lam, damping
        self.gravity = np.asarray(gravity, float)
        self.unit_cell = unit_cell if unit_cell is not None else float(self.L.min()) / 3.0
        self.type_names: list[str] = []
        self.pair_lines: list[tuple] = []
        self.beads: list[dict] = []
        self.spring_rows: list[dict] = []
        self.angle_rows: list[dict] = []
        self.modif: list[tuple] = []

    # -- content -------------------------------------------------------------------------
    def type(self, *names: str) -> None:
        self.type_names.extend(names)

    def pair(self, kind: str, a: str, b: str, *values) -> None:
        self.pair_lines.append((kind, a, b) + tuple(values))

    def bead(self, type_: str, x, tag=0, loc=0, R=0.5, m=1.0, v=(0.0, 0.0, 0.0),
             f=(0.0, 0.0, 0.0), xu=None) -> int:
        x = np.asarray(x, float)
        xu = x.copy() if xu is None else np.asarray(xu, float)
        self.beads.append(dict(type=type_, x=x, xu=xu, tag=tag, loc=loc, R=R, m=m,
                               v=np.asarray(v, float), f=np.asarray(f, float)))
        return len(self.beads) - 1

    def spring(self, i: int, j: int, r0: float, k: float, tag=0, c1: str | None = None,
               c2: str | None = None) -> int:
        """HR spring, or HR_FL when c1/c2 (text tokens, as written in the model) are given."""
        self.spring_rows.append(dict(i=i, j=j, r0=r0, k=k, tag=tag, c1=c1, c2=c2))
        return len(self.spring_rows) - 1

    def angle(self, a: int, b: int, c: int, theta0: float | str, c1: float, s1=0, s2=0,
              kind="HR", tag=0) -> int:
        self.angle_rows.append(dict(a=a, b=b, c=c, theta0=str(theta0) if isinstance(theta0, str)
                                    else _num(theta0), c1=c1, s1=s1, s2=s2, kind=kind, tag=tag))
        return len(self.angle_rows) - 1

    def modif_bead(self, how: str, what, prop: str, *values) -> None:
        """``modif_bead how what prop values`` (how: type|tag|id; prop: mass|velocity)."""
        self.modif.append((how, str(what), prop) + tuple(float(v) for v in values))

    # -- files ---------------------------------------------------------------------------
    def model_text(self) -> str:
        out = []
        for b in self.beads:
            vals = [b["type"], str(b["tag"]), str(b["loc"]), _num(b["R"]), _num(b["m"]),
                    *map(_num, b["x"]), *map(_num, b["v"]), *map(_num, b["f"]), *map(_num, b["xu"])]
            out.append("BEAD\t" + "\t".join(vals))
        for s in self.spring_rows:
            if s["c1"] is None:
                out.append(f"SPRING\tHR\t{s['tag']}\t{s['i']}\t{s['j']}\t{_num(s['r0'])}\t{_num(s['k'])}")
            else:
                out.append(f"SPRING\tHR_FL\t{s['tag']}\t{s['i']}\t{s['j']}\t{_num(s['r0'])}\t"
                           f"{_num(s['k'])}\t{s['c1']}\t{s['c2']}")
        for a in self.angle_rows:
            out.append(f"ANGLE\t{a['kind']}\t{a['tag']}\t{a['a']}\t{a['b']}\t{a['c']}\t{a['s1']}\t"
                       f"{a['s2']}\t{a['theta0']}\t{_num(a['c1'])}")
        return "\n".join(out) + "\n"

    def input_text(self, name: str, run: int, output_freq: int, minimize_steps: int = 0,
                   minimize_substeps: int | None = None, minimize_reset: bool | None = None,
                   extra: tuple[str, ...] = ()) -> str:
        L = self.L
        lines = ["model_file\tmodel.txt", f"output_file\t{name}", ""]
        lines += [f"type\t{t}" for t in self.type_names]
        for p in self.pair_lines:
            lines.append("pair\t" + "\t".join([p[0], p[1], p[2]] + [_num(v) for v in p[3:]]))
        lines += ["", f"box_size\t{_num(L[0])}\t{_num(L[1])}\t{_num(L[2])}",
                  f"box_type\t{'pbc' if self.periodic else 'finite'}",
                  f"box_wall_rep\t{_num(self.wall_k)}", f"box_unit_cell\t{_num(self.unit_cell)}",
                  f"cutoff\t{_num(self.cutoff)}", "", f"step\t{_num(self.dt)}",
                  f"lambda\t{_num(self.lam)}", f"damping\t{_num(self.damping)}",
                  "gravity\t" + "\t".join(_num(g) for g in self.gravity), ""]
        for m in self.modif:
            lines.append("modif_bead\t" + "\t".join([m[0], m[1], m[2]] + [_num(v) for v in m[3:]]))
        if minimize_steps:
            lines.append(f"minimize_steps\t{minimize_steps}")
            if minimize_substeps is not None:
                lines.append(f"minimize_substeps\t{minimize_substeps}")
            if minimize_reset is not None:
                lines.append(f"minimize_reset\t{'yes' if minimize_reset else 'no'}")
        lines += list(extra)
        lines += ["", f"run\t{run}", f"output_freq\t{output_freq}", "output_data\tall",
                  "output_type\tall"]
        return "\n".join(lines) + "\n"

    def write(self, folder, name="case", run=10, output_freq=10, **options) -> Path:
        """Write ``model.txt`` and ``input.txt`` into ``folder``; options: minimize_steps,
        minimize_substeps, minimize_reset, extra (more input lines)."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "model.txt").write_text(self.model_text())
        path = folder / "input.txt"
        path.write_text(self.input_text(name, run, output_freq, **options))
        return path

    def restart_text(self, x, xu, vt, F, step=0) -> str:
        """A FibreNet ``_restart.res`` file: ``\tTYPE x y z ix iy iz vx vy vz fx fy fz`` rows."""
        rows = [f"{len(self.beads)}", f"FRAME\t{step}\t{self.dt:g}\t" + "\t".join(f"{v:g}" for v in self.L)]
        for b, *vals in zip(self.beads, x, xu, vt, F):
            rows.append("\t" + b["type"] + "".join("\t" + _num(c) for v in vals for c in v))
        return "\n".join(rows) + "\n"

    # -- the reference system, parsed as FibreNet parses the files -------------------------
    def system(self) -> System:
        tindex = {t: k for k, t in enumerate(self.type_names)}
        pairs = {}
        for p in self.pair_lines:          # later lines override earlier ones
            a, b = sorted((tindex[p[1]], tindex[p[2]]))
            vals = [float(v) for v in p[3:]]
            if p[0] == "hs":
                pairs[(a, b)] = ("hs", vals[0])
            elif p[0] == "st":             # pair st A B Krep Katt l0 rc
                pairs[(a, b)] = ("st", *vals)
            elif p[0] == "lj":             # pair lj A B sigma epsilon c3
                pairs[(a, b)] = ("lj", *vals)
            else:
                raise ValueError(p[0])
        ns, na = len(self.spring_rows), len(self.angle_rows)
        col = lambda key, rows, dtype=float: np.array([r[key] for r in rows], dtype=dtype)  # noqa: E731
        springs = np.array([[s["i"], s["j"]] for s in self.spring_rows], int).reshape(ns, 2)
        fl = np.array([s["c1"] is not None for s in self.spring_rows], bool)
        c1 = np.array([fibrenet_stoi(s["c1"]) if s["c1"] is not None else 0 for s in self.spring_rows], float)
        c2 = np.array([fibrenet_stoi(s["c2"]) if s["c2"] is not None else 0 for s in self.spring_rows], float)
        angles = np.array([[a["a"], a["b"], a["c"]] for a in self.angle_rows], int).reshape(na, 3)
        return System(
            L=self.L.copy(), periodic=self.periodic, wall_k=None if self.periodic else self.wall_k,
            types=np.array([tindex[b["type"]] for b in self.beads], int),
            type_names=list(self.type_names),
            radius=col("R", self.beads), mass=self._masses(), tag=col("tag", self.beads, int),
            loc=col("loc", self.beads, int), springs=springs,
            r0=col("r0", self.spring_rows).reshape(ns), k=col("k", self.spring_rows).reshape(ns),
            fl=fl.reshape(ns), c1=c1.reshape(ns), c2=c2.reshape(ns), angles=angles,
            theta0=np.array([fibrenet_stof(a["theta0"]) for a in self.angle_rows], float).reshape(na),
            ac=col("c1", self.angle_rows).reshape(na),
            angle_fl=np.array([a["kind"] == "HR_FL" for a in self.angle_rows], bool).reshape(na),
            angle_springs=np.array([[a["s1"], a["s2"]] for a in self.angle_rows], int).reshape(na, 2),
            pairs=pairs, cutoff=float(self.cutoff), dt=self.dt, lam=self.lam,
            damping=self.damping, gravity=self.gravity.copy())

    def _select(self, how: str, what: str) -> np.ndarray:
        if how == "type":
            return np.array([b["type"] == what for b in self.beads])
        if how == "tag":
            return np.array([b["tag"] == int(what) for b in self.beads])
        mask = np.zeros(len(self.beads), bool)
        mask[int(what)] = True
        return mask

    def _masses(self) -> np.ndarray:
        m = np.array([b["m"] for b in self.beads], float)
        for how, what, prop, *vals in self.modif:
            if prop == "mass":
                m[self._select(how, what)] = vals[0]
        return m

    def state(self) -> State:
        """The initial state: x, ix from the model; v_old = (vx, vx, vx) (FibreNet's reader);
        v~ shown at step 0 = (vx, vy, vz) (an assumption: the note does not say; tests use
        vx = vy = vz); modif_bead velocity sets both; F = the model's f."""
        x = np.array([b["x"] for b in self.beads], float)
        xu = np.array([b["xu"] for b in self.beads], float)
        v = np.array([b["v"] for b in self.beads], float)
        v_old = np.repeat(v[:, :1], 3, axis=1)
        vt = v.copy()
        for how, what, prop, *vals in self.modif:
            if prop == "velocity":
                sel = self._select(how, what)
                v_old[sel] = vals
                vt[sel] = vals
        F = np.array([b["f"] for b in self.beads], float)
        return State(x, xu, v_old, vt, F, np.zeros(len(self.spring_rows), bool))


def max_rel_error(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| relative to the largest |component| of b (0 when both are 0)."""
    scale = float(np.abs(b).max())
    diff = float(np.abs(np.asarray(a) - np.asarray(b)).max())
    return diff / scale if scale > 0 else diff


def unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / math.sqrt(float((v * v).sum()))
