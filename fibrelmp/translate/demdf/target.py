"""``fibrelmp post --to demdf``: LAMMPS dump frames -> DEMDF snapshots ``<base>_<n>.json``,
through the neutral granular model (``post.to_granular``) and the home's snapshot writer."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.granmodel import GranularModel
from fibrelmp.post.target import ReadBack
from fibrelmp.post.to_granular import GranularTarget
from fibrelmp.translate.demdf.record import DemdfDocument


def demdf_document(model: GranularModel, filename: str) -> dict:
    """A minimal DEMDF document describing the dump's particles (object type = LAMMPS type)."""
    s = model.spheres
    object_types = []
    for k, mat in enumerate(model.materials):
        rows = s.material == k
        entry = {"id": k, "type": "particle", "name": mat.name, "radius": float(s.radius[rows][0])}
        if np.isfinite(s.mass[rows]).all():
            entry["mass"] = float(s.mass[rows][0])
        object_types.append(entry)
        if not (np.allclose(s.radius[rows], s.radius[rows][0])):
            raise InputError(model.source, None, f"DEMDF object types carry one radius; LAMMPS type "
                             f"{mat.key.rsplit('_', 1)[-1]} has several")
    lo, hi = model.plan.domain
    particles = [[*map(float, x), *map(float, v), int(t)]
                 for x, v, t in zip(s.position, s.velocity, s.material)]
    return {"fileFormat": "demdf", "fileFormatVersion": 0.01, "name": f"from {model.source.name}",
            "dimensionality": 3, "time": model.plan.t_start, "timeStep": model.plan.dt,
            "domain": [lo.tolist(), hi.tolist()], "objectTypes": object_types,
            "objects": {"particles": particles},
            "output": {"snapshot": {"filename": filename, "saveCount": 0}}}


class DemdfTarget(GranularTarget):
    """``<base>_<n>.json``: a DEMDF snapshot per frame."""

    kind = "demdf"
    keeps_ids = False                # DEMDF particles are rows, without ids

    @classmethod
    def files(cls, base: Path) -> list[Path]:
        return sorted(p for p in base.parent.glob(f"{base.name}_*.json")
                      if p.stem[len(base.name) + 1:].isdigit())

    def result_writer(self, model: GranularModel, dt: float) -> Writer:
        from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter

        name = self.target.name
        demdf = self.facts.demdf if self.facts is not None else None
        if demdf is not None and len(demdf["particle_rows"]) != model.spheres.count:
            self.context.warn("data facts", f"{self.facts.path}: the job's document has "
                              f"{len(demdf['particle_rows'])} particles, the dump's first frame "
                              f"{model.spheres.count}; the snapshots describe the dump's particles only")
            demdf = None
        if demdf is not None:
            # the run's document, counters and object types (the rows' last entry)
            model.origin = DemdfDocument(**{**copy.deepcopy(demdf), "filename": name})
        else:
            model.origin = DemdfDocument(
                document=demdf_document(model, name), dimensionality=3,
                particle_rows=[[0.0] * 6 + [int(t)] for t in model.spheres.material],
                particles_file=None, output_location=("output", "snapshot"),
                filename=name, save_count=0, file_time_step=dt, substeps=1,
                time_step_count=0)
        return DemdfSnapshotWriter(model, self.target.parent)

    @classmethod
    def read_back(cls, files: list[Path]) -> list[ReadBack]:
        from fibrelmp.translate.demdf.reader import read_snapshot

        snaps = sorted(files, key=lambda p: int(p.stem.rsplit("_", 1)[-1]))
        return [ReadBack(s.spheres.position, values={("vx", "vy", "vz"): s.spheres.velocity})
                for s in map(read_snapshot, snaps)]
