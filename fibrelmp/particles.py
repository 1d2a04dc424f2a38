"""The particle model every job has: ``ParticleModel``, the base of the three families.

* ``model.Model``: bead-spring networks (FibreNet);
* ``granmodel.GranularModel``: DEM scenes (MUSEN, DEMDF);
* ``cardioproof.case.SphCase``: SPH water in a moving finite-element wall (CardioProof).

Each family keeps its own array storage (its readers and writers use it); the base holds what
every particle job has (``source``, ``units``, ``warnings``/``warn``) and the questions the
shared modules (``sanity``, ``record``, the pipeline) ask a model, so that none of them switches
on the family: a uniform view of the particles (``particles()``), counts (``counts()``), the
time step, the time the step has to resolve (``time_scale()``), the per-rank minimum and the
summary's figures (``final_gather``/``final_figures``/``summary_figures``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np


@dataclass
class ParticleView:
    """The particles of any model, one row each, in the model's order (LAMMPS id = row + 1
    unless ``ids`` says otherwise).  ``state`` holds the named per-particle arrays beyond
    positions and velocities a family carries (temperature will be one)."""

    ids: np.ndarray              # (n,) int: the source's ids
    positions: np.ndarray        # (n,3)
    velocities: np.ndarray       # (n,3)
    radii: np.ndarray            # (n,)
    masses: np.ndarray           # (n,)
    type_index: np.ndarray       # (n,) int: particle type (FibreNet) or material (DEM)
    state: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def count(self) -> int:
        return int(self.ids.shape[0])

    @classmethod
    def empty(cls) -> "ParticleView":
        return cls(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0),
                   np.zeros(0), np.zeros(0, np.int64))


@dataclass(frozen=True)
class ModelCounts:
    """How many of each thing a model has besides its particles."""

    bonds: int = 0
    angles: int = 0
    walls: int = 0               # wall elements: triangles and planes (DEM), shell elements (SPH)
    materials: int = 0           # materials (DEM), particle types (FibreNet), fluids (SPH)


@dataclass(frozen=True)
class TimeScale:
    """The shortest time a model's time step has to resolve (a spring period, a contact
    duration), in the family's words: ``name`` ("spring period"), ``value``, ``where`` (the
    summary's "where"), ``line`` (``check``'s line up to " = N time steps") and ``warning``
    (what follows "the time step DT exceeds 1/10 of the ")."""

    name: str
    value: float
    where: str
    line: str
    warning: str


@dataclass
class ParticleModel(ABC):
    """What every particle job holds; subclasses are dataclasses adding their own fields."""

    source: Path
    warnings: list[tuple[str, str]] = field(default_factory=list, kw_only=True)   # (kind, message)
    units: str = field(default="si", kw_only=True)

    # the family's words (class attributes of each family; ``kind``, the family's name in the
    # summary and in `check` -- "fibrenet", "musen", "demdf", "cardioproof" -- is a field of
    # the families that read several formats)
    particle_noun: ClassVar[str]                # "beads", "spheres", "SPH particles"
    # particles per MPI rank below which more ranks make a run slower (sanity.rank_check;
    # None: not measured for the family)
    min_per_rank: ClassVar[int | None] = None
    # what `fibrelmp check` compares the step with, for the blown-up run's hint
    time_scale_title: ClassVar[str | None] = None

    def warn(self, kind: str, message: str) -> None:
        self.warnings.append((kind, message))

    # ---- the particles
    @abstractmethod
    def particles_view(self) -> ParticleView:
        """Every particle the model starts with (a copy-free view where the family allows)."""

    @property
    def particle_count(self) -> int:
        """Particles known before the job is rendered (the run's size estimates)."""
        return self.particles_view().count

    @abstractmethod
    def counts(self) -> ModelCounts:
        """Bonds, angles, walls and materials."""

    # ---- time
    @abstractmethod
    def given_time_step(self) -> float | None:
        """The input's time step (None: the job chooses it)."""

    def planned_steps(self) -> int | None:
        """The time steps the run takes, known before its job is rendered (None: only the
        rendered job says)."""
        return None

    def planned_runs(self) -> int:
        """The separate LAMMPS 'run' commands the run makes, known before rendering (0:
        unknown, or a few)."""
        return 0

    def time_scale(self) -> TimeScale | None:
        """The time the step has to resolve (None: nothing to resolve, or the family checks
        its own step)."""
        return None

    def unstable_hint(self) -> str:
        """What a blown-up run's error adds after "hint: atoms moved too far in one step: "."""
        return (f"the run became unstable. `fibrelmp check` shows the time step against the "
                f"{self.time_scale_title}; a smaller step, stiffer walls or less overlap at the "
                "start usually help")

    # ---- the run summary (fibrelmp.record.Recorder, docs/record.md)
    def run_time_step(self, job: Any) -> float:
        """The step the rendered ``job`` runs with."""
        return float(self.given_time_step())

    def final_gather(self, lmp: Any) -> dict[str, Any]:
        """On every rank after the last command: the per-atom arrays ``final_figures`` needs
        beyond ids and positions (LAMMPS's gathers are collective)."""
        return {}

    def final_figures(self, job: Any, ids: np.ndarray, x: np.ndarray, box: tuple,
                      gathered: dict[str, Any]) -> dict[str, Any]:
        """On rank 0: the figures of the final state (largest overlap, spring strain)."""
        return {}

    def summary_figures(self, job: Any, final: dict[str, Any], last: dict | None,
                        tally: dict | None) -> dict[str, Any]:
        """The summary's family entries (``particles``, ``bonds``, ...), in their order."""
        return {}
