"""The neutral mesh: points in a stated length unit, and blocks of cells of one kind each.

Points keep the unit of the file they came from (openCARP: µm), so a mesh read and written in
the same format is the same numbers; ``points_m`` gives metres.  Cell kinds use meshio's names.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# cell kind -> nodes per cell
CELL_NODES = {"line": 2, "triangle": 3, "quad": 4, "tetra": 4, "pyramid": 5, "wedge": 6,
              "hexahedron": 8}


@dataclass
class CellBlock:
    kind: str                      # a CELL_NODES key
    nodes: np.ndarray              # (m, CELL_NODES[kind]) int64, 0-based point indices
    tags: np.ndarray               # (m,) int64 region tags (0 when the file has none)

    def __post_init__(self) -> None:
        self.nodes = np.asarray(self.nodes, np.int64).reshape(-1, CELL_NODES[self.kind])
        self.tags = np.asarray(self.tags, np.int64).reshape(-1)
        if len(self.tags) != len(self.nodes):
            raise ValueError(f"{self.kind}: {len(self.nodes)} cells but {len(self.tags)} tags")


@dataclass
class Mesh:
    points: np.ndarray             # (n, 3) float64, in ``unit``
    cells: list[CellBlock]
    unit: float = 1.0              # metres per coordinate unit (openCARP: 1e-6)
    name: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def points_m(self) -> np.ndarray:
        return self.points * self.unit

    @property
    def cell_count(self) -> int:
        return sum(len(b.nodes) for b in self.cells)

    def in_unit(self, unit: float) -> np.ndarray:
        """Points in ``unit`` (metres per unit): unchanged numbers when it is the mesh's own."""
        return self.points if unit == self.unit else self.points * (self.unit / unit)

    def equals(self, other: "Mesh") -> bool:
        """Same points (in metres, exactly), same cell blocks in the same order."""
        if not np.array_equal(self.points_m, other.points_m) or len(self.cells) != len(other.cells):
            return False
        return all(a.kind == b.kind and np.array_equal(a.nodes, b.nodes) and np.array_equal(a.tags, b.tags)
                   for a, b in zip(self.cells, other.cells))


class MeshFormat:
    """The ``mesh`` hook of a format: its reader and writer classes (``formatbase.Reader`` /
    ``Writer`` subclasses: ``reader(path).read() -> Mesh``, ``writer(target).add(mesh)``)."""

    reader: type
    writer: type
