"""What a CardioProof run writes: VTK frames of the fluid with the moving wall mesh, and one
CSV time series per opening.

* ``<name>.pvd`` + ``<name>_NNNNNN.vtp``: the fluid particles (``Velocity``, ``Density``,
  ``Pressure`` from the Tait equation, and ``outflow_weight_<opening>``: the particle's share
  weight ``1 - |delta|/d`` while near the opening, else 0);
* ``<name>_walls.pvd`` + ``<name>_NNNNNN_walls.vtp``: the surface mesh at the frame's time
  (nodes interpolated linearly between motion frames, as the wall particles move), cell data
  ``opening`` (-1 on walls, else the opening's index);
* ``<name>_<opening>.csv``: ``time_s, pressure_Pa, force_x_N, force_y_N, force_z_N,
  force_normal_N, near_particles, flux_velocity_m3_s, crossed_particles, flux_crossing_m3_s``
  every ``series_interval``: the outflow force LAMMPS applied, the flux as the near particles'
  volume flux (the sum of m/rho times the outward velocity, over the search distance), and from the particles that crossed the
  opening's plane (cumulative count; the flux from its change since the previous row times
  the particle volume: the cavity's volume over the fluid particle count).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from fibrelmp.translate.cardioproof import geometry
from fibrelmp.translate.cardioproof.case import SphCase
from fibrelmp.translate.cardioproof.job import SphJob
from fibrelmp.errors import RunError, wrong_frame
from fibrelmp.formatbase import Writer

SERIES_COLUMNS = ("time_s", "pressure_Pa", "force_x_N", "force_y_N", "force_z_N", "force_normal_N",
                  "near_particles", "flux_velocity_m3_s", "crossed_particles", "flux_crossing_m3_s")


@dataclass
class SphFrame:
    step: int
    time: float
    ids: np.ndarray
    positions: np.ndarray          # (n, 3) m
    velocities: np.ndarray         # (n, 3) m/s
    density: np.ndarray            # (n,) kg/m^3
    pressure: np.ndarray           # (n,) Pa, Tait
    weights: dict[str, np.ndarray] = field(default_factory=dict)    # opening -> (n,)
    nodes: np.ndarray | None = None                                 # mesh nodes (m) at ``time``


def tait_pressure(rho: np.ndarray, rho0: float, c0: float) -> np.ndarray:
    return c0 * c0 * rho0 / 7.0 * ((rho / rho0) ** 7 - 1.0)


class MeshClock:
    """The mesh's node positions at increasing times, linear between motion frames (streams
    the motion: two frames in memory)."""

    def __init__(self, case: SphCase):
        self.case = case
        self.frames = geometry.motion_frames(case)
        self.k = 0
        self.a = next(self.frames)
        self.b = next(self.frames, None)

    def at(self, t: float) -> np.ndarray:
        motion = self.case.motion
        if motion is None or self.b is None:
            return self.a
        dt = motion.frame_interval
        while self.b is not None and t >= (self.k + 1) * dt:
            self.k += 1
            self.a, self.b = self.b, next(self.frames, None)
        if self.b is None:
            return self.a
        s = (t - self.k * dt) / dt
        return self.a + s * (self.b - self.a)


class SphFrames:
    """The frame source of a run: the fluid dump, frame by frame, with the mesh at that time."""

    def __init__(self, case: SphCase, job: SphJob):
        from fibrelmp.post.lammps_dump.reader import iter_frames

        self.case, self.job = case, job
        self.frames = iter_frames(job.frames)
        self.clock = MeshClock(case)
        self.beyond = BeyondWalls(case, job)

    def is_frame(self, words: list[str]) -> bool:
        return words[:3] == ["write_dump", "fluid", "custom"]

    def read(self, step: int) -> SphFrame:
        f = next(self.frames, None)
        if f is None or f.step != step:
            raise wrong_frame(self.job.frames, step, None if f is None else f.step)
        c = f.columns
        rho = c["c_rho"]
        time = f.time if f.time is not None else step * self.job.dt
        frame = SphFrame(step, time, c["id"].astype(np.int64), np.column_stack([c["x"], c["y"], c["z"]]),
                         np.column_stack([c["vx"], c["vy"], c["vz"]]), rho,
                         tait_pressure(rho, self.case.density, self.job.sound_speed),
                         {o.name: c[f"v_share_{o.name}"] for o in self.job.openings},
                         self.clock.at(time))
        self.beyond.add(frame)
        return frame

    def tally(self) -> dict:
        """The run summary's count of fluid beyond the walls (``fluid_beyond_walls``)."""
        return self.beyond.summary()

    def close(self) -> None:
        close = getattr(self.frames, "close", None)
        if close is not None:
            close()
        self.beyond.warn()


class BeyondWalls:
    """Counts, at every saved frame, the fluid particles that a moving wall let through: outside
    the closed surface (the mesh at the frame's time), within the wall layers' depth of a wall
    triangle and not where fluid leaves by an opening (within 2 search distances of one).  The
    fill starts every particle geometry.CLEARANCE spacings inside, so any count is penetration
    during the run; it is warned about with its figures (docs/cardioproof.md)."""

    def __init__(self, case: SphCase, job: SphJob):
        self.tri = job.surface
        self.walls = job.surface[job.opening_of < 0]
        self.openings = job.surface[job.opening_of >= 0]
        self.depth = case.layers * case.spacing
        self.reach = 2 * max((o.distance for o in job.openings), default=0.0)
        self.spacing, self.warnings = case.spacing, case.warnings
        self.counts: list[tuple[float, int, float]] = []          # (time, particles, deepest m)

    def add(self, frame: SphFrame) -> None:
        if frame.nodes is None or not len(frame.positions):
            return
        x, q = frame.nodes, frame.positions
        outside = np.flatnonzero(~geometry.is_inside(x, self.tri, q))
        depth = geometry.nearest_within(x, self.walls, q[outside], self.depth)
        if len(self.openings) and self.reach > 0:
            leaving = geometry.nearest_within(x, self.openings, q[outside], self.reach) < self.reach
            depth[leaving] = np.inf
        through = depth[np.isfinite(depth)]
        self.counts.append((frame.time, len(through), float(through.max()) if len(through) else 0.0))

    def summary(self) -> dict:
        hit = [c for c in self.counts if c[1]]
        return {"frames": len(self.counts), "frames_with": len(hit),
                "most_particles": max((c[1] for c in hit), default=0),
                "deepest_m": max((c[2] for c in hit), default=0.0),
                "first_time": hit[0][0] if hit else None}

    def warn(self) -> None:
        s = self.summary()
        if s["frames_with"] and self.warnings is not None:
            from fibrelmp.runner import mpi_rank_size

            if mpi_rank_size()[0] == 0:
                self.warnings.append(("fluid in wall", f"fluid particles beyond a wall's surface in {s['frames_with']} "
                                      f"of {s['frames']} frames (up to {s['most_particles']} per frame, up to "
                                      f"{s['deepest_m'] / self.spacing:.2f} spacings deep, first at t = "
                                      f"{s['first_time']:g} s): the flow pushed them through the wall particles; a "
                                      "finer spacing, more wall.layers or a higher fluid.sound_speed keep "
                                      "the fluid in"))


class SphVtkWriter(Writer):
    """The VTK frames (``fibrelmp.post.vtk``'s layout: ParaView opens ``<name>.pvd`` and
    ``<name>_walls.pvd``)."""

    format = "vtk"

    def __init__(self, base: Path, job: SphJob, *, force: bool = True):
        from fibrelmp.post.vtk.writer import VtkWriter

        self.vtk = VtkWriter(base, force=force)
        super().__init__(base, force=force)
        self.adopt(self.vtk)
        self.tri, self.opening = job.surface, job.opening_of
        self.lo, self.hi = job.box

    def outputs(self) -> list[Path]:
        return []                  # the adopted VtkWriter's files

    def write(self, frame: SphFrame) -> None:
        from fibrelmp.post.vtk.frame import ViewerFrame

        data: dict[str, np.ndarray] = {"Velocity": frame.velocities, "Density": frame.density,
                                       "Pressure": frame.pressure}
        for name, w in frame.weights.items():
            data[f"outflow_weight_{name}"] = w
        walls = frame.nodes[self.tri] if frame.nodes is not None else None
        self.vtk.add(ViewerFrame(frame.step, frame.time, frame.ids, frame.positions, self.lo,
                                 np.diag(self.hi - self.lo), np.zeros(3, bool), data,
                                 walls=walls, wall_data={"opening": self.opening}))


class OpeningSeriesWriter(Writer):
    """``<name>_<opening>.csv`` from LAMMPS's ``fix ave/time`` file (written at the end)."""

    def __init__(self, target: Path, source: Path, normal: np.ndarray, particle_volume: float, *,
                 force: bool = True):
        super().__init__(target, force=force)
        self.source, self.normal, self.volume = source, np.asarray(normal, float), particle_volume

    def write(self, frame: Any) -> None:
        pass                       # the series is LAMMPS's; frames carry nothing for it

    def finish(self) -> None:
        fh = self.open(self.target)
        fh.write((",".join(SERIES_COLUMNS) + "\n").encode())
        prev = None
        for _, t, p, fx, fy, fz, near, flux, crossed in iter_series(self.source):
            crossing = "" if prev is None or t <= prev[0] else \
                repr((crossed - prev[1]) * self.volume / (t - prev[0]))
            normal = fx * self.normal[0] + fy * self.normal[1] + fz * self.normal[2]
            fh.write((",".join([*(repr(v) for v in (t, p, fx, fy, fz, float(normal))), str(int(near)),
                                repr(flux), str(int(crossed)), crossing]) + "\n").encode())
            prev = (t, crossed)


def iter_series(path: Path) -> Iterator[tuple[float, ...]]:
    """The rows of a ``fix ave/time`` file, one at a time: step, t, p, fx, fy, fz, near,
    flux, crossed."""
    try:
        with open(path) as fh:
            for number, line in enumerate(fh, 1):
                if not line.strip() or line.startswith("#"):
                    continue
                words = line.split()
                if len(words) != 9:
                    raise RunError(f"{path}:{number}: unexpected row in the opening's series")
                yield tuple(float(w) for w in words)
    except OSError as exc:
        raise RunError(f"{path}: cannot read the opening's series ({exc.strerror})") from None


def result_writers(case: SphCase, job: SphJob, folder: Path, force: bool = True) -> list[Writer]:
    writers: list[Writer] = [SphVtkWriter(folder / case.name, job, force=force)]
    for o in job.openings:
        writers.append(OpeningSeriesWriter(folder / f"{case.name}_{o.name}.csv", job.folder / o.series_name(),
                                           o.normal, job.particle_volume, force=force))
    return writers
