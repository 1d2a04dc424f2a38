"""The neutral, format-free model every reader fills and every writer consumes.

Per-particle data are numpy arrays (never per-particle objects).  Indices inside the
model are 0-based; LAMMPS ids are ``index + 1``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


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
class Model:
    source: Path
    particles: Particles
    bonds: Bonds
    angles: Angles
    pairs: list[PairLaw]
    box: Box
    dynamics: Dynamics
    plan: RunPlan
    warnings: list[tuple[str, str]] = field(default_factory=list)   # (kind, message)
    units: str = "lj"
    inputs: list[Path] = field(default_factory=list)     # every file it was read from

    def warn(self, kind: str, message: str) -> None:
        self.warnings.append((kind, message))
