"""Granular frames: a ``GranularFrame`` per saved step, built from a running job's dumps.

The job (``translate.granular_job``) dumps the spheres, the alive bonds (a local dump) and the
wall tiles (or fix musen/wall/mesh's triangle forces) at every saved step, and appends every
bond break to ``breaks.dump``.  A
``FrameBuilder`` reads them back (``post.lammps_dump``'s reader, local dumps included) as
soon as LAMMPS has written them and keeps only one frame plus the per-bond/per-sphere end
times in memory.  It is the pipeline's frame source for granular jobs.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from fibrelmp.errors import RunError, wrong_frame
from fibrelmp.granmodel import GranularFrame, GranularModel, quat_multiply
from fibrelmp.granular_run.stress import stress_tensors
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.translate.granular_job import GranularJob
from fibrelmp.translate.granular.geometry import nearest_triangle
from fibrelmp.translate.granular.musen_clock import MusenClock
from fibrelmp.translate.granular.schedule import UNKNOWN_STEP


class _BreakLog:
    """Reads the per-step broken-bond dump as LAMMPS appends it: ``step id1 id2 fx fy fz ox oy
    oz m`` lines (bond_style musen/elastic: the force on id1, the tangential overlap and
    |M_n + M_t| as it broke), with MUSEN's time 4th with a variable time step, ``step id1
    id2`` from other bond styles."""

    def __init__(self, path: Path | None, keep_states: bool = False):
        self.path = path
        self.keep_states = keep_states       # keep what each bond held as it broke (presaves)
        self.fh = None
        self.pending = b""
        self.rows: list[tuple[float, float, float]] = []
        self.times: dict[tuple[int, int, int], float] = {}    # a variable step's break times
        # (step, id1, id2, fx, fy, fz, ox, oy, oz, m) of breaks a frame may still need
        self.forces: list[tuple] = []

    def time(self, step: int, id1: int, id2: int) -> float:
        """The time logged with a break (variable time step)."""
        return self.times[(step, id1, id2)]

    def upto(self, step: int) -> list[tuple[int, int, int]]:
        if self.path is None:
            return []
        if self.fh is None:
            if not self.path.exists():
                return []
            self.fh = open(self.path, "rb")
        self.pending += self.fh.read()
        *complete, self.pending = self.pending.split(b"\n")
        for ln in complete:
            w = ln.split()
            if len(w) >= 3:
                self.rows.append((float(w[0]), float(w[1]), float(w[2])))
            if len(w) in (4, 11):
                self.times[(int(w[0]), int(w[1]), int(w[2]))] = float(w[3])
            if len(w) >= 10 and self.keep_states:
                self.forces.append((int(w[0]), int(w[1]), int(w[2]), *map(float, w[-7:])))
        out = [(int(s), int(a), int(b)) for s, a, b in self.rows if s <= step]
        self.rows = [r for r in self.rows if r[0] > step]
        return out

    def broken_between(self, first: int, last: int) -> np.ndarray:
        """(k, 10) rows of the breaks read so far at steps ``first`` .. ``last`` with their
        state (step, id1, id2, force, overlap, |moment|); those before ``first`` are forgotten."""
        self.forces = [r for r in self.forces if r[0] >= first]
        return np.array([r for r in self.forces if r[0] <= last], np.float64).reshape(-1, 10)

    def close(self) -> None:
        if self.fh is not None:
            self.fh.close()


class FrameBuilder:
    """Turns the dumps of one saved step into a GranularFrame (call ``next`` in order)."""

    def __init__(self, model: GranularModel, job: GranularJob):
        self.model, self.job = model, job
        sp = model.spheres
        self.q0 = np.asarray(sp.quaternion, float)
        self.frames = iter_frames(job.frames)
        self.bonds = iter_frames(job.bond_dump) if job.bond_dump is not None else None
        self.tiles = iter_frames(job.tile_dump) if job.tile_dump is not None else None
        self.mesh = iter_frames(job.wall_forces) if job.wall_forces is not None else None
        # presaves (MUSEN's stress tensor, its saved bonds and wall forces): the previous
        # evaluation's bonds, contacts and wall contacts, one block per frame
        self.presaves = job.stress_contacts is not None
        self.breaks = _BreakLog(job.breaks, keep_states=self.presaves)
        self.stress_contacts = iter_frames(job.stress_contacts) if self.presaves else None
        self.stress_walls = iter_frames(job.stress_walls) if job.stress_walls is not None else None
        self.first_frame = True
        # the blocks of the frame being read: the bond dump's (read by _bonds), the contacts',
        # the wall contacts'
        self.bond_block = self.contact_block = self.wall_block = None
        self.prev_frame_step = 0
        self.sphere_end = np.full(sp.count, np.inf)
        self.present = np.zeros(sp.count, bool)
        self.present[job.sphere_rows] = True
        self.removed = np.zeros(sp.count, bool)
        self.prev_t = job.t_start
        self.prev_x = np.asarray(sp.position, float).copy()
        self.prev_v = np.asarray(sp.velocity, float).copy()
        # the time of a step: MUSEN's summed clock (read forwards) or t_start + step dt
        self.frame_clock, self.break_clock = _clock(job), _clock(job)
        self.variable_clock = None     # variable time step: fix musen/leapfrog's line per frame
        self.inlet_clock = _clock(job)
        self.next_inlet_id = model.plan.inlet_next_id     # generated agglomerates' next id
        self.deletion_time: dict[int, float] = {}
        deletion_clock = _clock(job)
        for step, rows in sorted(job.deletions, key=lambda d: d[0]):
            for r in rows:
                self.deletion_time[int(r)] = deletion_clock(step)
        b = model.bonds
        self.nb = b.count if b is not None else 0
        if self.nb:
            self.bond_alive = np.zeros(self.nb, bool)
            self.bond_alive[job.bond_rows] = True
            self.bond_end = np.where(self.bond_alive, np.inf, np.asarray(b.active_end, float))
            # bonds of spheres dropped at the start end at the start
            dropped = ~self.bond_alive & (b.active_end > job.t_start) & (b.active_start <= job.t_start + 0.5 * job.dt)
            self.bond_end[dropped] = job.t_start
            pair = b.pair.astype(np.int64) + 1
            lo, hi = pair.min(1), pair.max(1)
            self.id_base = int(pair.max()) + 1
            key = lo * self.id_base + hi
            sim = np.r_[job.bond_rows, job.inlet_bond_rows].astype(np.int64)
            order = np.argsort(key[sim], kind="stable")
            self.bkeys = key[sim][order]
            self.brows = sim[order]
            self.first_id = pair[:, 0]
        tri = model.triangles
        self.v0 = np.asarray(tri.vertices, float) if tri is not None and tri.count else None
        # a heat model's spheres: {time, step, min, mean, max} of their temperature, thinned
        self.temperatures = ThinnedSeries()

    def tally(self) -> dict:
        """Spheres and bonds as of the last frame read, for the run summary (fibrelmp.record):
        spheres present, removed at their activity end or by leaving the domain, bonds alive."""
        removed = np.flatnonzero(self.removed)
        at_end = sum(1 for r in removed.tolist()
                     if self.deletion_time.get(r) == self.sphere_end[r])
        first = self.model.plan.inlet_rows
        made = 0 if first is None else int(np.isfinite(self.model.spheres.active_start[first:]).sum())
        out = {"spheres": int(self.present.sum()), "activity_end": at_end, "generated": made,
               "left_domain": len(removed) - at_end,
               "bonds": int(self.bond_alive.sum()) if self.nb else 0}
        if self.temperatures.count:
            out["temperature"] = self.temperatures.entries()
            out["temperature_every"] = self.temperatures.every
        return out

    def _bond_lookup(self, id1: np.ndarray, id2: np.ndarray) -> np.ndarray:
        """Bond rows (or -1) for atom-id pairs."""
        key = np.minimum(id1, id2) * self.id_base + np.maximum(id1, id2)
        pos = np.searchsorted(self.bkeys, key)
        pos = np.minimum(pos, len(self.bkeys) - 1)
        ok = self.bkeys[pos] == key if len(self.bkeys) else np.zeros(len(key), bool)
        return np.where(ok, self.brows[pos], -1)

    def is_frame(self, words: list[str]) -> bool:
        """The sphere dump's ``write_dump`` saves a frame (bonds and walls are dumped with it)."""
        return words[:3] == ["write_dump", "spheres", "custom"]

    def read(self, step: int) -> GranularFrame:
        """The next frame, saved at ``step`` (UNKNOWN_STEP: a variable time step's, whose step
        and time fix musen/leapfrog wrote to ``job.variable_clock``)."""
        job = self.job
        f = next(self.frames, None)
        if step == UNKNOWN_STEP:
            if f is None:
                raise wrong_frame(job.frames, -1, None)
            step, t = f.step, self._variable_time(f.step)
        else:
            t = self.frame_clock(step)
        if f is None or f.step != step:
            raise wrong_frame(job.frames, step, None if f is None else f.step)
        c = f.columns
        rows = c["id"].astype(np.int64) - 1
        pos = np.column_stack([c["x"], c["y"], c["z"]])
        # LAMMPS drops atoms beyond an 'f' face at its next re-neighbouring: a sphere already
        # outside the domain (or removed before) counts as removed now
        keep = ~self.removed[rows]
        if job.domain_lo is not None:
            for a in np.flatnonzero(job.removal_axes):
                keep &= (pos[:, a] >= job.domain_lo[a]) & (pos[:, a] <= job.domain_hi[a])
        if not keep.all():
            c = {k: col[keep] for k, col in c.items()}
            rows, pos = rows[keep], pos[keep]
        if job.inlet_log is not None:
            self._generated(rows, c)
        vel = np.column_stack([c["vx"], c["vy"], c["vz"]])
        omega = np.column_stack([c["omegax"], c["omegay"], c["omegaz"]])
        force = np.column_stack([c["fx"], c["fy"], c["fz"]])
        ql = np.column_stack([c["quatw"], c["quati"], c["quatj"], c["quatk"]])
        quat = quat_multiply(ql, self.q0[rows])

        # spheres gone since the previous frame: activity end (exact) or domain exit (estimate)
        now = np.zeros_like(self.present)
        now[rows] = True
        gone = np.flatnonzero(self.present & ~now)
        self.removed[gone] = True
        for r in gone:
            if int(r) in self.deletion_time:
                self.sphere_end[r] = self.deletion_time[int(r)]
            else:
                self.sphere_end[r] = self._exit_time(int(r), t)
        self.present = now

        frame = GranularFrame(time=t, step=step, sphere_rows=rows, position=pos, velocity=vel,
                              omega=omega, force=force, quaternion=quat)
        if "d_musen_temperature" in c:    # a heat model (fix musen/heat): MUSEN's temperature
            frame.temperature = np.asarray(c["d_musen_temperature"], np.float64)
            self.temperatures.append(_temperature_figures(t, step, frame.temperature))
        if "sfx" in c:      # fix musen/leapfrog: the force cmusen saves (the previous evaluation's)
            frame.saved_force = np.column_stack([c["sfx"], c["sfy"], c["sfz"]])
        if self.presaves:
            self.contact_block = next(self.stress_contacts, None)
            self.wall_block = next(self.stress_walls, None) if self.stress_walls is not None else None
        if self.nb:
            self._bonds(frame, step)
        if self.presaves:
            self._check_presaves(step)
        if self.v0 is not None:
            self._triangles(frame, t, c)
        if self.presaves:
            self._stress(frame, step)
        self.prev_t, self.prev_x[rows], self.prev_v[rows] = t, pos, vel
        return frame

    def _variable_time(self, step: int) -> float:
        """MUSEN's summed time of the frame at ``step`` (the clock file's next line)."""
        path = self.job.variable_clock
        if self.variable_clock is None:
            self.variable_clock = open(path, encoding="ascii")
        line = self.variable_clock.readline().split()
        if len(line) != 3 or int(line[0]) != step:
            raise RunError(f"{path}: expected the time of the frame at step {step}, found "
                           f"{' '.join(line) or 'nothing'}")
        return float(line[1])

    def _generated(self, rows: np.ndarray, c: dict) -> None:
        """Spheres fix musen/inlet made since the last frame fill their reserved rows:
        activity start (cmusen's clock at the step of the inlet log), radius, mass and
        material of the dump."""
        sp = self.model.spheres
        new = np.flatnonzero(~np.isfinite(sp.active_start[rows]))
        if not len(new):
            return
        made: dict[int, int] = {}
        lengths: dict[tuple[int, int], float] = {}
        with open(self.job.inlet_log) as fh:          # "STEP ID"; a resumed run repeats lines
            for line in fh:
                words = line.split()
                if len(words) == 4:                   # an agglomerate's bond: STEP LEFT RIGHT L0
                    lengths[int(words[1]), int(words[2])] = float(words[3])
                    continue
                step, tag = words
                made[int(tag)] = int(step)
        steps = [made.get(int(rows[k]) + 1) for k in new]
        if None in steps:
            raise RunError(f"{self.job.inlet_log}: no line for the new atom "
                           f"{int(rows[new[steps.index(None)]]) + 1} of the dump")
        for k in np.argsort(steps, kind="stable"):   # the clock is read forwards
            r, i = int(rows[new[k]]), new[k]
            sp.active_start[r] = self.inlet_clock(steps[k])
            sp.radius[r] = sp.contact_radius[r] = c["radius"][i]
            sp.mass[r] = c["mass"][i]
            sp.material[r] = self.job.type_materials[int(c["type"][i])]
            if sp.compound_key is not None:
                sp.compound_key[r] = self.model.materials[int(sp.material[r])].key
        if self.model.plan.inlet_layout is not None:
            self._generated_agglomerates(rows[new], made, lengths)

    def _generated_agglomerates(self, new_rows: np.ndarray, made: dict[int, int],
                                lengths: dict[tuple[int, int], float]) -> None:
        """Agglomerates fix musen/inlet made since the last frame: MUSEN's ids (spheres, then
        bonds, agglomerate after agglomerate in MUSEN's order of generation: by step, then
        generator, then request) and their bonds alive from the spheres' generation."""
        sp, b = self.model.spheres, self.model.bonds
        objects = set()
        for r in new_rows.tolist():
            for k, first, bfirst, count, n, m in self.model.plan.inlet_layout:
                if first <= r < first + count * n:
                    objects.add((made[r + 1], k, (r - first) // n))
                    break
        layout = {entry[0]: entry for entry in self.model.plan.inlet_layout}
        for step, k, j in sorted(objects):
            _, first, bfirst, _, n, m = layout[k]
            srows = first + j * n + np.arange(n)
            sp.ids[srows] = self.next_inlet_id + np.arange(n)
            if m:
                brows = bfirst + j * m + np.arange(m)
                b.ids[brows] = self.next_inlet_id + n + np.arange(m)
                b.active_start[brows] = sp.active_start[srows[0]]
                for row in brows.tolist():
                    b.length0[row] = lengths[int(b.pair[row, 0]) + 1, int(b.pair[row, 1]) + 1]
                self.bond_alive[brows] = True
            self.next_inlet_id += n + m

    def _bonds(self, frame: GranularFrame, step: int) -> None:
        """Bond states at ``step``: breaks logged since the last frame, bonds of removed
        spheres ended, forces from the bond dump (zero for broken bonds)."""
        broken = np.array(self.breaks.upto(step), np.int64).reshape(-1, 3)
        if len(broken):
            broken = broken[np.argsort(broken[:, 0], kind="stable")]
            r = self._bond_lookup(broken[:, 1], broken[:, 2])
            ok = r >= 0
            r, bsteps, records = r[ok], broken[ok, 0], broken[ok]
            r, first = np.unique(r, return_index=True)     # earliest record per bond (MPI
            bsteps, records = bsteps[first], records[first]     # ranks may both report it)
            live = self.bond_alive[r]
            self.bond_alive[r[live]] = False
            order = np.argsort(bsteps[live], kind="stable")
            ends = np.empty(len(order))
            if self.job.variable_clock is not None:      # the bond style logged MUSEN's time
                ends[:] = [self.breaks.time(*map(int, rec)) for rec in records[live]]
            else:
                ends[order] = [self.break_clock(int(s)) for s in bsteps[live][order]]
            self.bond_end[r[live]] = ends
        pair = self.model.bonds.pair
        end = np.minimum(self.sphere_end[pair[:, 0]], self.sphere_end[pair[:, 1]])
        dead = self.bond_alive & np.isfinite(end)
        self.bond_alive[dead] = False
        self.bond_end[dead] = end[dead]
        frame.bond_alive = self.bond_alive.copy()
        frame.bond_end_time = self.bond_end.copy()
        bf = np.full((self.nb, 3), np.nan)
        # no bond dump when no bond survives the start (e.g. all left the domain at t = 0);
        # with presaves (MUSEN's stress tensor) it is the previous evaluation's, as cmusen saves
        self.bond_block = next(self.bonds, None) if self.bonds is not None else None
        cols = self.bond_block.columns if self.bond_block is not None else {}
        # musen/elastic also dumps the tangential overlap and |M_n + M_t| (MUSEN's TotalTorque)
        extra = "c_fl_bforce[7]" in cols
        overlap = np.full((self.nb, 3), np.nan) if extra else None
        torque = np.full(self.nb, np.nan) if extra else None
        dumped = np.zeros(self.nb, bool)          # the bonds the dump lists
        if len(cols.get("c_fl_bpair[1]", [])):
            i1 = cols["c_fl_bpair[1]"].astype(np.int64)
            i2 = cols["c_fl_bpair[2]"].astype(np.int64)
            fb = np.column_stack([cols[f"c_fl_bforce[{k}]"] for k in range(1, 4)])
            if self.presaves and self.first_frame:
                fb = np.zeros_like(fb)   # cmusen's first save: no evaluation yet, TotalForce 0
            br = self._bond_lookup(i1, i2)
            ok = br >= 0
            # the force on batom1 (and the overlap seen from it): report them for the bond's
            # first sphere
            sign = np.where(i1[ok] == self.first_id[br[ok]], 1.0, -1.0)
            bf[br[ok]] = fb[ok] * sign[:, None]
            dumped[br[ok]] = True
            if extra:
                ov = np.column_stack([cols[f"c_fl_bforce[{k}]"] for k in range(4, 7)])
                overlap[br[ok]] = ov[ok] * sign[:, None]
                torque[br[ok]] = cols["c_fl_bforce[7]"][ok]
        held = self.bond_alive
        if self.presaves and extra:
            # cmusen's save holds the bonds alive before its step's evaluation (the presave's)
            # and, once more, those broken since the previous save, as they broke
            held = dumped
            gone = (self.breaks.broken_between(self.prev_frame_step, step - 1) if not self.first_frame
                    else np.zeros((0, 10)))
            rows = self._bond_lookup(gone[:, 1].astype(np.int64), gone[:, 2].astype(np.int64))
            gone, rows = gone[rows >= 0], rows[rows >= 0]
            sign = np.where(gone[:, 1] == self.first_id[rows], 1.0, -1.0)
            bf[rows], overlap[rows] = gone[:, 3:6] * sign[:, None], gone[:, 6:9] * sign[:, None]
            torque[rows] = gone[:, 9]
            held[rows] = True
            # a bond alive but not in the presave (an inlet made it in the frame's last step):
            # new in cmusen's save, its values 0
            new = self.bond_alive & ~held
            bf[new], overlap[new], torque[new] = 0.0, 0.0, 0.0
            held |= new
            frame.bond_saved = held
        bf[~held] = 0.0
        frame.bond_force = bf
        if extra:
            overlap[~held] = 0.0
            torque[~held] = 0.0
            frame.bond_tangential_overlap = overlap
            frame.bond_torque = torque

    def _check_presaves(self, step: int) -> None:
        """Every presave block of the frame at ``step`` is there, written one step before it
        (the first frame's at its own step)."""
        job = self.job
        blocks = [(job.bond_dump, self.bond_block)] if self.bonds is not None else []
        blocks += [(job.stress_contacts, self.contact_block)]
        blocks += [(job.stress_walls, self.wall_block)] if self.stress_walls is not None else []
        for path, block in blocks:
            if block is None or (not self.first_frame and block.step != step - 1):
                raise wrong_frame(path, step - 1, None if block is None else block.step)

    def _stress(self, frame: GranularFrame, step: int) -> None:
        """MUSEN's stress tensor of the frame's spheres (granular_run.stress) from the presave
        dumps written one step before it; 0 at the first frame (cmusen saves it before any
        evaluation, with no contact listed and no bond force yet).  The bonds are those the
        save holds, with their saved force (``_bonds``): a bond broken since the previous
        frame still counts, with the force it broke with, as MUSEN marks its object inactive
        only at the save after the break."""
        first, self.first_frame = self.first_frame, False
        self.prev_frame_step = step
        if first:
            frame.stress_tensor = np.zeros((len(frame.sphere_rows), 9))
            return
        pairs = []
        if frame.bond_saved is not None:       # in MUSEN's bond order, force on the first sphere
            held = np.flatnonzero(frame.bond_saved)
            pair = self.model.bonds.pair[held]
            pairs.append((pair[:, 0], pair[:, 1], frame.bond_force[held]))
        cols = self.contact_block.columns      # contacts: normal and tangential force on id1
        if len(cols.get("id1", [])):
            ids = np.column_stack([cols["id1"], cols["id2"]]).astype(np.int64)
            force = (np.column_stack([cols["fx"], cols["fy"], cols["fz"]])
                     + np.column_stack([cols["ftx"], cols["fty"], cols["ftz"]]))
            order = np.lexsort((ids.max(1), ids.min(1)))          # by sphere pair
            pairs.append((ids[order, 0] - 1, ids[order, 1] - 1, force[order]))
        walls = None
        if self.wall_block is not None:
            rows, _, point, force = _wall_contacts(self.wall_block.columns)
            walls = (rows, point, force)
        frame.stress_tensor = stress_tensors(np.asarray(frame.sphere_rows, np.int64), frame.position,
                                             np.asarray(self.model.spheres.radius, np.float64), pairs,
                                             walls)

    def _exit_time(self, r: int, t: float) -> float:
        """Ballistic estimate of when sphere r crossed the domain, from the previous frame."""
        job = self.job
        if job.domain_lo is None:
            return t
        x, v = self.prev_x[r], self.prev_v[r]
        best = np.inf
        for a in np.flatnonzero(job.removal_axes):
            if v[a] > 0:
                best = min(best, (job.domain_hi[a] - x[a]) / v[a])
            elif v[a] < 0:
                best = min(best, (job.domain_lo[a] - x[a]) / v[a])
        if not np.isfinite(best):
            return t
        return float(self.prev_t + min(max(best, 0.0), t - self.prev_t))

    def _triangles(self, frame: GranularFrame, t: float, cols: dict) -> None:
        tri = self.model.triangles
        verts = self.v0.copy()
        tvel = np.zeros((tri.count, 3))
        tforce = np.zeros((tri.count, 3))
        for wp in self.job.wall_plans:
            if not len(wp.triangle_rows):
                continue
            if wp.kinematics.moving:
                R, b = wp.kinematics.transform(t)
                verts[wp.triangle_rows] = self.v0[wp.triangle_rows] @ R.T + b
                tvel[wp.triangle_rows] = wp.kinematics.velocity(t)
            if wp.contact_vars:
                fw = np.column_stack([cols[v] for v in wp.contact_vars[:3]])
                cp = np.column_stack([cols[v] for v in wp.contact_vars[3:]])
                hit = np.flatnonzero(np.abs(fw).sum(1) > 0)
                if len(hit):
                    k = nearest_triangle(cp[hit], verts[wp.triangle_rows])
                    np.add.at(tforce, wp.triangle_rows[k], -fw[hit])
        if self.mesh is not None:
            # fix musen/wall/mesh: the force on each triangle (id = its position in the mesh)
            fm = next(self.mesh).columns
            k = fm["id"].astype(np.int64) - 1
            tforce[self.job.mesh_rows[k]] = np.column_stack([fm["fx"], fm["fy"], fm["fz"]])
            if self.wall_block is not None:
                # with presaves, what cmusen saves: minus the previous evaluation's contact
                # forces, sphere by sphere (MUSEN's ConsolidateWall; 0 before any evaluation)
                saved = tforce.copy()
                saved[self.job.mesh_rows] = 0.0
                if not self.first_frame:
                    rows, tri, _, force = _wall_contacts(self.wall_block.columns)
                    np.add.at(saved, self.job.mesh_rows[tri], -1 * force)
                frame.saved_triangle_force = saved
            if "x1" in fm:
                # geometries the fix moves step by step: where it moved them, their velocity
                _stepped_walls(self.job, fm, k, verts, tvel)
        if self.tiles is not None:
            ft = next(self.tiles).columns
            ids = ft["id"].astype(np.int64)
            fxyz = np.column_stack([ft["fx"], ft["fy"], ft["fz"]])
            for wp in self.job.wall_plans:
                if wp.tile_ids is None or not len(wp.tile_ids):
                    continue
                pos = ids - wp.tile_ids[0]
                sel = (pos >= 0) & (pos < len(wp.tile_ids))
                np.add.at(tforce, wp.tile_owner[pos[sel]], fxyz[sel])
        frame.triangle_vertices = verts
        frame.triangle_velocity = tvel
        frame.triangle_force = tforce

    def close(self) -> None:
        self.breaks.close()
        if self.variable_clock is not None:
            self.variable_clock.close()
        for dump in (self.frames, self.bonds, self.tiles, self.mesh, self.stress_contacts, self.stress_walls):
            if dump is not None:
                dump.close()


class ThinnedSeries:
    """At most ``limit`` + 1 entries of a per-frame series, however many frames a run saves:
    every frame while they fit, then every 2nd, 4th, ... frame (the stride doubles each time the
    store fills, keeping frames 0, every, 2·every, ...), and always the last frame."""

    def __init__(self, limit: int = 1024):
        self.limit = limit
        self.kept: list[dict] = []
        self.last: dict | None = None
        self.count = 0          # frames offered
        self.every = 1          # the stride of the kept frames

    def append(self, entry: dict) -> None:
        if self.count % self.every == 0:
            self.kept.append(entry)
            if len(self.kept) > self.limit:
                self.kept = self.kept[::2]
                self.every *= 2
        self.count += 1
        self.last = entry

    def entries(self) -> list[dict]:
        """The kept entries, the last frame's included."""
        if self.last is not None and (not self.kept or self.kept[-1] is not self.last):
            return [*self.kept, self.last]
        return list(self.kept)


def _temperature_figures(t: float, step: int, temperature: np.ndarray) -> dict:
    """The summary's temperature entry of one frame (None for a frame without spheres)."""
    if not len(temperature):
        return {"time": t, "step": step, "min": None, "mean": None, "max": None}
    return {"time": t, "step": step, "min": float(temperature.min()),
            "mean": float(temperature.mean()), "max": float(temperature.max())}


def _stepped_walls(job, fm: dict, k: np.ndarray, verts: np.ndarray, tvel: np.ndarray) -> None:
    """The vertices and velocity fix musen/wall/mesh reports for triangles of stepped
    geometries (force-dependent or free motion), into the frame's arrays."""
    rows = job.mesh_rows[k]
    stepped = np.zeros(len(verts), bool)
    for wp in job.wall_plans:
        if wp.stepped is not None:
            stepped[wp.triangle_rows] = True
    sel = stepped[rows]
    cols = [fm[f"{c}{a}"] for a in (1, 2, 3) for c in "xyz"]
    verts[rows[sel]] = np.column_stack(cols)[sel].reshape(-1, 3, 3)
    tvel[rows[sel]] = np.column_stack([fm["vx"], fm["vy"], fm["vz"]])[sel]


def _wall_contacts(cols: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(sphere rows, triangle rows in the mesh, contact points, forces on the spheres) of a
    presave block of fix musen/wall/mesh's contacts, each sphere's in its collision order."""
    rows = np.asarray(cols.get("id", []), np.float64).astype(np.int64) - 1
    order = np.argsort(rows, kind="stable")
    tri = np.asarray(cols.get("tri", []), np.float64).astype(np.int64)[order] - 1
    point = np.column_stack([cols.get(c, []) for c in ("cpx", "cpy", "cpz")]).reshape(-1, 3)[order]
    force = np.column_stack([cols.get(c, []) for c in ("fx", "fy", "fz")]).reshape(-1, 3)[order]
    return rows[order], tri, point, force


def _clock(job) -> Callable[[int], float]:
    """The time at a step, for steps asked in increasing order."""
    if job.clock is None:
        return lambda step: job.t_start + step * job.dt
    return MusenClock(job.clock.t_start, job.clock.dt).time
