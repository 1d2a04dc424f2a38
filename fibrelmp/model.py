"""The neutral, format-free model every reader fills and every writer consumes.

Per-particle data are numpy arrays (never per-particle objects).  Indices inside the
model are 0-based; LAMMPS ids are ``index + 1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from fibrelmp.particles import ModelCounts, ParticleModel, ParticleView, TimeScale


@dataclass
class Particles:
    type_names: list[str]            # user's type names; ``types`` indexes this list
    types: np.ndarray                # (n,) int
    positions: np.ndarray            # (n,3) wrapped into the box
    unwrapped: np.ndarray            # (n,3) unwrapped ("image") positions
    velocities: np.ndarray           # (n,3) velocity the integrator starts from
    masses: np.ndarray               # (n,) 0 means "moves at constant velocity"
    radii: np.ndarray                # (n,)
    molecules: np.ndarray            # (n,) int: fibre tag / molecule id
    loc_ids: np.ndarray | None = None    # (n,) int (FibreNet loc_id)
    # State some codes carry beyond x and v (FibreNet: the force of the last step and the
    # lambda-predicted velocity shown in the step-0 frame).
    initial_forces: np.ndarray | None = None      # (n,3)
    display_velocities: np.ndarray | None = None  # (n,3)

    @property
    def count(self) -> int:
        return int(self.types.shape[0])


@dataclass
class Bonds:
    """Harmonic springs, F = k (r0 - r); optional break length (nan = unbreakable)."""

    atoms: np.ndarray            # (m,2) int particle indices
    k: np.ndarray                # (m,) force constant (F = k dr)
    r0: np.ndarray               # (m,)
    break_length: np.ndarray     # (m,) nan where the bond never breaks

    @property
    def count(self) -> int:
        return int(self.atoms.shape[0])

    @classmethod
    def empty(cls) -> "Bonds":
        return cls(np.zeros((0, 2), int), np.zeros(0), np.zeros(0), np.zeros(0))


@dataclass
class Angles:
    """Harmonic-in-angle bending, E = c (theta - theta0)^2, theta0 in radians."""

    atoms: np.ndarray            # (m,3) int; the middle atom is the vertex
    c: np.ndarray                # (m,)
    theta0: np.ndarray           # (m,) radians

    @property
    def count(self) -> int:
        return int(self.atoms.shape[0])

    @classmethod
    def empty(cls) -> "Angles":
        return cls(np.zeros((0, 3), int), np.zeros(0), np.zeros(0))


@dataclass
class PairLaw:
    """A non-bonded law between two particle types (indices into type_names).

    kind: "hs"  F = K (Ri + Rj - r) for r < Ri + Rj          params: K
          "st"  F = B (r* - r) for r < cutoff (force jump)    params: B, rstar, cutoff
          "lj"  FibreNet's shifted form (see docs/fibrenet.md)  params: sigma, epsilon, shift, cutoff
    """

    kind: str
    type_i: int
    type_j: int
    params: dict[str, float]

    @property
    def law(self) -> str:
        """The law's name (docs/fibrenet.md, "Physics mapping")."""
        return PAIR_LAWS[self.kind]


# FibreNet's pair keywords and the laws they name
PAIR_LAWS = {"hs": "harmonic soft-sphere repulsion", "st": "FibreNet's sticky spring",
             "lj": "FibreNet's shifted Lennard-Jones"}


@dataclass
class Box:
    lo: np.ndarray               # (3,)
    hi: np.ndarray               # (3,)
    periodic: tuple[bool, bool, bool]
    wall_stiffness: float | None = None   # finite walls: F = k * penetration

    @property
    def lengths(self) -> np.ndarray:
        return self.hi - self.lo


@dataclass
class Dynamics:
    dt: float
    damping: float = 0.0                       # drag F = -damping * v~ (not mass-scaled)
    lambda_: float = 0.5                       # modified velocity-Verlet prediction factor
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))   # a force, not an acceleration
    pair_cutoff: float | None = None           # global cutoff for st/lj
    exclusion: str = "none"                    # "none" | "molecule" | "bonded"


@dataclass
class Stage:
    """A block of dynamics. ``reset`` zeroes v and the stored force before each chunk."""

    name: str                    # "relax" (FibreNet "minimize") or "production"
    steps: int
    chunk: int                   # steps per chunk
    reset: bool = False
    output: bool = False         # frames are written during this stage


@dataclass
class OutputSpec:
    format: str                  # "fibrenet"
    basename: str
    folder: Path
    fields: tuple[str, ...]      # subset of ("position", "velocity", "force")
    types: tuple[int, ...] | None    # type indices written; None = all
    every: int
    line: int | None = None      # the output_file line (for messages)


@dataclass
class RunPlan:
    stages: list[Stage]
    output: OutputSpec


@dataclass
class Model(ParticleModel):
    """A bead-spring network (FibreNet)."""

    particles: Particles
    bonds: Bonds
    angles: Angles
    pairs: list[PairLaw]
    box: Box
    dynamics: Dynamics
    plan: RunPlan
    units: str = field(default="lj", kw_only=True)
    inputs: list[Path] = field(default_factory=list)     # every file it was read from

    kind: ClassVar[str] = "fibrenet"
    particle_noun: ClassVar[str] = "beads"
    # measured on 2 cores, docs/performance.md#ranks-and-threads
    min_per_rank: ClassVar[int | None] = 2_000
    time_scale_title: ClassVar[str | None] = "shortest spring period"

    def particles_view(self) -> ParticleView:
        p = self.particles
        state = {name: array for name, array in (("initial_forces", p.initial_forces),
                                                 ("display_velocities", p.display_velocities))
                 if array is not None}
        return ParticleView(np.arange(1, p.count + 1), p.positions, p.velocities, p.radii,
                            p.masses, p.types, state)

    @property
    def particle_count(self) -> int:
        return self.particles.count

    def counts(self) -> ModelCounts:
        walls = 0 if self.box.wall_stiffness is None else 6 - 2 * sum(self.box.periodic)
        return ModelCounts(self.bonds.count, self.angles.count, walls,
                           len(self.particles.type_names))

    def given_time_step(self) -> float:
        return self.dynamics.dt

    def planned_steps(self) -> int:
        """Relaxation and production."""
        return int(sum(st.steps for st in self.plan.stages))

    def planned_runs(self) -> int:
        """One per chunk of each stage."""
        return int(sum(-(-st.steps // max(st.chunk, 1)) for st in self.plan.stages if st.steps > 0))

    def time_scale(self) -> TimeScale | None:
        """The shortest spring period (``spring_period``)."""
        found = spring_period(self)
        if found is None:
            return None
        period, row = found
        i, j = (int(x) for x in self.bonds.atoms[row])
        return TimeScale("spring period", period, f"spring {row}: beads {i}-{j}",
                         f"spring period {period:.4g} (shortest, spring {row}: beads {i}-{j})",
                         f"shortest spring period {period:.4g} (spring {row}, beads {i}-{j}): "
                         "the run will be inaccurate or blow up")

    def final_gather(self, lmp: Any) -> dict[str, Any]:
        from fibrelmp.record import gather_bonds

        return {"bonds": gather_bonds(lmp)}

    def final_figures(self, job: Any, ids: np.ndarray, x: np.ndarray, box: tuple,
                      gathered: dict[str, Any]) -> dict[str, Any]:
        from fibrelmp.record import largest_strain

        bonds = gathered["bonds"]
        return {"bonds": len(bonds), "strain": largest_strain(ids, x, bonds, job.bond_lengths, *box)}

    def summary_figures(self, job: Any, final: dict[str, Any], last: dict | None,
                        tally: dict | None) -> dict[str, Any]:
        out: dict[str, Any] = {"particles": {"kind": "beads", "start": self.particles.count,
                                             "end": self.particles.count}}
        if self.bonds.count:
            out["bonds"] = {"start": self.bonds.count, "end": final["bonds"],
                            "broken": self.bonds.count - final["bonds"]}
        out["max_spring_strain"] = final["strain"]
        return out


def spring_period(model: Model) -> tuple[float, int] | None:
    """Shortest oscillation period 2 pi sqrt(mu / k) over the springs (mu the reduced mass of
    the two beads; a mass-0 bead moves at constant velocity, i.e. acts as infinitely heavy),
    and that spring's row.  None without a spring that can oscillate."""
    p, b = model.particles, model.bonds
    if not p.count or not b.count:
        return None
    inv = np.zeros(p.count)
    np.divide(1.0, p.masses, out=inv, where=p.masses > 0)
    omega2 = b.k * (inv[b.atoms[:, 0]] + inv[b.atoms[:, 1]])
    if not (omega2 > 0).any():
        return None
    row = int(np.argmax(omega2))
    return 2 * math.pi / math.sqrt(float(omega2[row])), row
