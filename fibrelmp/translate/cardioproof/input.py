"""CardioProof case files (JSON, first key ``"cardioproof"``): SPH water in a moving
finite-element wall with pressure-outflow openings (``fibrelmp.translate.cardioproof``)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fibrelmp.errors import InputError
from fibrelmp.inputformat import InputFormat, RunSettings, Say, Warn, no_overrides

if TYPE_CHECKING:
    from fibrelmp.translate.cardioproof.case import SphCase
    from fibrelmp.translate.cardioproof.job import SphJob
    from fibrelmp.outputs import Outputs
    from fibrelmp.runplan import Rendered, RunOptions, RunPlan


class CaseInput(InputFormat):
    name = "cardioproof"
    styles = "stock LAMMPS only (packages SPH and MISC)"

    def read(self, path: Path) -> "SphCase":
        from fibrelmp.translate.cardioproof.case import read_case

        return read_case(path)

    def precision_unused(self, path: Path, out: Path | None) -> str | None:
        return "its VTK frames and CSV series keep every number exactly"

    def check_lines(self, path: Path, model: "SphCase") -> list[str]:
        from fibrelmp.translate.cardioproof.job import plan_job

        p = plan_job(model)
        mesh = model.mesh
        motion = model.motion
        lines = [f"input        {model.source}",
                 f"mesh         {model.mesh_file} ({len(mesh.points)} nodes, {mesh.cell_count} shell elements, "
                 f"{mesh.unit:g} m per unit)",
                 "motion       " + (f"{motion.count} frames {motion.frame_interval:g} s apart ({motion.files[0].name})"
                                    if motion else "none (static wall)"),
                 f"fluid        {len(p['fluid'])} particles, spacing {model.spacing:g} m, rho0 {model.density:g}, "
                 f"c0 {p['c0']:g} m/s, " + (f"viscosity {model.viscosity:g} Pa s" if model.viscosity is not None
                                            else f"artificial viscosity {model.artificial_viscosity:g}"),
                 f"wall         {len(p['walls'].rows)} particles in {model.layers} layers "
                 f"({int(p['wall_moving'].sum())} moving)",
                 f"time step    {p['dt']:g} s, {p['total']} steps to {model.end_time:g} s"]
        for o in p["openings"]:
            lines.append(f"opening      {o.name}: area {o.area:g} m^2, normal ({', '.join(f'{v:g}' for v in o.normal)}), "
                         f"search distance {o.distance:g} m, p from {o.pressure[0, 1]:g} Pa")
        outputs, folder = case_outputs(model)
        lines.append(f"results      {folder / model.name}.pvd, {model.name}_walls.pvd"
                     + "".join(f", {model.name}_{o.name}.csv" for o in model.openings) + " (or in -o DIR)")
        return lines

    def write_job(self, model: "SphCase", folder: Path) -> "SphJob":
        from fibrelmp.translate.cardioproof.job import write_job

        return write_job(model, folder)[0]

    def plan(self, path: Path, settings: RunSettings, options: "RunOptions", say: Say,
             warn: Warn) -> "RunPlan":
        from fibrelmp.translate.cardioproof.results import SphFrames, result_writers
        from fibrelmp.runplan import Rendered, RunPlan, RunRequest, feed

        no_overrides(path, settings, "a CardioProof case sets its own times (run.end_time, "
                     "output.interval): --end-time/--step/--save-step/--steps are for MUSEN and DEMDF inputs")
        if options.resume or options.checkpoint_every:
            raise InputError(path, None, "CardioProof runs cannot be checkpointed or resumed yet "
                             "(the wall velocity files are read as the run goes): run it again")
        from fibrelmp.translate.cardioproof.job import plan_job

        from fibrelmp.translate.cardioproof.results import SphVtkWriter

        for name in settings.also:     # its frames are VTK already; nothing else is written from them
            if name != SphVtkWriter.format:
                raise InputError(path, None, f"--also {name}: a CardioProof run writes its frames only "
                                 f"as its own results ({SphVtkWriter.format} frames and CSV series)")
            say(f"--also {name}: a CardioProof run's results are {name} frames already")
        model = self.read(path)
        plan_job(model)            # the geometry's input errors before anything is locked
        outputs, folder = case_outputs(model, settings.out, settings.work)

        def build(work: Path, write_files: bool) -> Rendered:
            from fibrelmp.translate.cardioproof.job import write_job

            job, text = write_job(model, work, write_files)
            dumps = [job.frames] + ([job.walls] if job.walls else []) + [work / o.series_name() for o in job.openings]
            return Rendered(job, text, job.save_steps, dumps)

        request = RunRequest(model, build, lambda rendered: SphFrames(model, rendered.job),
                             lambda rendered: feed(result_writers(model, rendered.job, folder)),
                             outputs.work, recorder=SphRecorder)
        warn(model.warnings)
        return RunPlan(outputs, [request], options)

    def work_folder(self, path: Path, out: Path | None, work: Path | None) -> Path:
        from fibrelmp.outputs import work_folder

        folder = Path(out) if out is not None else Path(path).parent
        return work_folder(folder, Path(path).stem, work)


def case_outputs(case: "SphCase", out: str | Path | None = None,
                 work: str | Path | None = None) -> tuple["Outputs", Path]:
    """Where a case writes: ``<name>.pvd`` + frames, ``<name>_walls.pvd`` + frames and
    ``<name>_<opening>.csv`` beside the case file (or in ``out``)."""
    from fibrelmp.outputs import Outputs, work_folder

    folder = (Path(out) if out is not None else case.source.parent).resolve()
    name = re.escape(case.name)
    files = [folder / f"{case.name}.pvd", folder / f"{case.name}_walls.pvd"]
    files += [folder / f"{case.name}_{o.name}.csv" for o in case.openings]
    inputs = [case.source, case.mesh_file] + (case.motion.files if case.motion else [])
    patterns = [(folder, re.compile(name + r"_\d{6}(_walls\.vtp|_walls\.vtu|\.vtp)"))]
    job = work_folder(folder, case.source.stem, work)
    _check_name_lengths(case, [*files, folder / f"{case.name}_000000_walls.vtp"], staged=True)
    _check_name_lengths(case, [job, *(job / f"opening_{o.name}.txt" for o in case.openings)], staged=False)
    return Outputs(case.source, job, files=files, patterns=patterns, inputs=inputs), folder


# a staged file is ".<name>.tmp<pid>" (fibrelmp.textio.temp_name) and the earlier file a --force run
# keeps aside ".<name>.tmp<pid>.old" (formatbase.replacing): 9 bytes and a pid of up to 7 digits
TEMP_NAME_EXTRA = 16


def _check_name_lengths(case: "SphCase", paths: list[Path], staged: bool) -> None:
    """Every file name a run writes (and a ``staged`` file's temp name) fits its folder's file system
    (``PC_NAME_MAX``, asked of the nearest existing folder): an output.name or an opening name
    too long must fail here, not after the work folder was written."""
    import os

    limits: dict[Path, int] = {}
    for path in paths:
        folder = path.parent
        if folder not in limits:
            probe = folder
            while not probe.exists() and probe != probe.parent:
                probe = probe.parent
            try:
                limits[folder] = os.pathconf(probe, "PC_NAME_MAX")
            except (OSError, ValueError):
                limits[folder] = 255
        size = len(os.fsencode(path.name))
        extra = TEMP_NAME_EXTRA if staged else 0
        if size + extra > limits[folder]:
            raise InputError(case.source, None, f"the file name {path.name[:32]}... is {size} bytes"
                             + (f" ({extra} more while it is written)" if extra else "")
                             + f", over the {limits[folder]}-byte limit of its folder {folder}: a shorter "
                             "output.name, opening name or case file name")


class SphRecorder:
    """The run summary of a CardioProof case (docs/record.md)."""

    def __init__(self, model: "SphCase", job: "SphJob", script: str = ""):
        self.model, self.job = model, job
        self.steps = self.resumed = 0
        self.final: dict[str, Any] = {}

    def end(self, lmp: Any, steps: int, resumed: int) -> None:
        self.steps, self.resumed = steps, resumed
        self.final["step"] = int(lmp.extract_global("ntimestep"))
        self.final["atoms"] = int(lmp.get_natoms())
        # at the last step (the series' rows come every series_interval)
        self.final["crossed"] = {o.name: int(round(lmp.extract_variable(f"crossed_{o.name}")))
                                 for o in self.job.openings}
        # in the cavity: not yet removed from in front of an opening is out already
        self.final["fluid"] = self.final["atoms"] - self.job.wall_count - sum(
            int(round(lmp.extract_variable(f"out_{o.name}"))) for o in self.job.openings)
        # fluid neither in the cavity nor out by an opening went through a wall and off the box
        lost = self.job.fluid_count - self.final["fluid"] - sum(self.final["crossed"].values())
        if lost > 0 and self.model.warnings is not None:
            from fibrelmp.runner import mpi_rank_size

            if mpi_rank_size()[0] == 0:
                self.model.warnings.append(("fluid lost", f"{lost} fluid particles went through the wall and "
                                            "left the box: a finer spacing, more wall.layers or a higher "
                                            "fluid.sound_speed keep the fluid in"))

    def summary(self, rendered: "Rendered", wall_time: float, warnings: list[tuple[str, str]],
                tally: dict | None = None) -> dict:
        from fibrelmp.record import LOG_NAME, SUMMARY_VERSION, warning_counts

        job, case = self.job, self.model
        folder = Path(rendered.folder)
        walls = job.wall_count
        openings = {}
        for o in job.openings:
            crossed = self.final.get("crossed", {}).get(o.name, 0)
            openings[o.name] = {"area": o.area, "crossed_particles": crossed,
                                "crossed_volume": crossed * job.particle_volume}
        return {
            "summary_version": SUMMARY_VERSION, "input": str(case.source), "kind": "cardioproof",
            "units": "si", "folder": str(folder),
            "log": LOG_NAME if (folder / LOG_NAME).exists() else None,
            "steps": {"total": self.steps, "this_session": self.steps - self.resumed, "resumed_from": self.resumed},
            "time_step": job.dt, "sound_speed": job.sound_speed,
            "time": {"start": 0.0, "end": self.final.get("step", 0) * job.dt},
            "wall_time": wall_time,
            "steps_per_second": self.steps / wall_time if wall_time > 0 else None,
            "frames": len(job.save_steps),
            "particles": {"kind": "sph", "fluid_start": job.fluid_count, "wall": walls,
                          "fluid_end": self.final.get("fluid")},
            "openings": openings, "final_step": self.final.get("step"),
            # fluid particles beyond a wall's surface at the saved frames (BeyondWalls)
            "fluid_beyond_walls": tally,
            "warnings": warning_counts(warnings),
        }
