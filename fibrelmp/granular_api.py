"""Running granular inputs (MUSEN scenes and cmusen scripts, DEMDF documents).

Readers give a GranularModel; ``granular_run.run_granular`` runs it on LAMMPS and streams
GranularFrames; the format's writer turns them into the user's own result files.  The cmusen
script driver keeps simulated results as on-disk frame spools, so a script that exports one
simulation several times never holds all frames in memory.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from .errors import InputError
from .granmodel import GranularModel


@dataclass
class GranularResult:
    outputs: list[Path] = field(default_factory=list)
    jobs: list = field(default_factory=list)        # GranularJob per simulation
    notes: list[str] = field(default_factory=list)  # things the CLI should say (renames, removals)


def _is_rank0() -> bool:
    from .runner import mpi_rank_size

    return mpi_rank_size()[0] == 0


@dataclass(frozen=True)
class Checkpoints:
    """Checkpoint settings of a run (see fibrelmp.checkpoint)."""

    every: int | None = None       # steps between checkpoints
    resume: bool = False           # continue from the checkpoint in the work folder


def simulate(model: GranularModel, work: Path, sinks: list, progress: bool = True,
             checkpoints: Checkpoints = Checkpoints()):
    """Run ``model`` and feed every saved frame to each sink's ``add``; sinks are closed on
    success and aborted (temp files removed) on any failure."""
    from .granular_run import run_granular

    def on_frame(frame) -> None:
        for sink in sinks:
            sink.add(frame)

    try:
        # a script resumes the simulation that was interrupted; finished ones simply run again
        resume = checkpoints.resume and (Path(work) / "checkpoint.json").exists()
        job = run_granular(model, Path(work), on_frame, progress=progress,
                           checkpoint_every=checkpoints.every, resume=resume)
    except BaseException:
        for sink in sinks:
            abort = getattr(sink, "abort", None)
            if abort is not None:
                abort()
        raise
    for sink in sinks:
        close = getattr(sink, "close", None)
        if close is not None:
            close()
    return job


def run_demdf(path: str | Path, out: str | Path | None = None, work: str | Path | None = None,
              progress: bool = True, time_end: float | None = None, steps: int | None = None,
              save_every: float | None = None, warn: Callable | None = None,
              say: Callable[[str], None] | None = None,
              checkpoints: Checkpoints = Checkpoints()) -> GranularResult:
    """DEMDF: snapshots ``<filename>_<saveCount>.json`` next to the input (or in ``out``)."""
    from .post.demdf_out import DemdfSnapshotWriter
    from .translate import demdf

    model = demdf.read(path, time_end=time_end, steps=steps, save_every=save_every)
    if warn is not None:
        warn(model.warnings)
    folder = (Path(out) if out is not None else Path(path).parent).resolve()
    work_folder = (Path(work) if work is not None else folder / f"{Path(path).stem}_work").resolve()
    result = GranularResult()
    writer = DemdfSnapshotWriter(model, folder) if _is_rank0() else None
    job = simulate(model, work_folder, [writer] if writer else [], progress, checkpoints)
    result.jobs.append(job)
    if writer is not None:
        result.outputs.extend(getattr(writer, "written", []))
    return result


def musen_result_path(path: str | Path) -> tuple[Path, str | None]:
    """MUSEN result name: a ``.mdem`` name becomes ``.txt`` (fibrelmp writes text only)."""
    path = Path(path)
    if path.suffix.lower() == ".mdem":
        new = path.with_suffix(".txt")
        return new, f"MUSEN binary results are not written: {path} becomes {new} (MUSEN text format)"
    return path, None


def run_musen_scene(model: GranularModel, result: str | Path, work: str | Path | None = None,
                    progress: bool = True, precision: int = 6,
                    checkpoints: Checkpoints = Checkpoints()) -> GranularResult:
    """Simulate a MUSEN scene whose plan (step, end, saves) is already set."""
    from .post.musen_out import MusenResultWriter

    check_musen_runnable(model)
    target, note = musen_result_path(result)
    target = target.resolve()
    work_folder = (Path(work) if work is not None else target.parent / f"{target.stem}_work").resolve()
    res = GranularResult(notes=[note] if note else [])
    writer = MusenResultWriter(model, target, precision=precision) if _is_rank0() else None
    res.jobs.append(simulate(model, work_folder, [writer] if writer else [], progress, checkpoints))
    if writer is not None:
        res.outputs.append(target)
    return res


def check_musen_runnable(model: GranularModel) -> None:
    if model.passthrough.get("liquid_bonds"):
        raise InputError(model.source, None, "the scene has liquid bonds (type 13), which need a "
                         "liquid-bridge model fibrelmp does not translate; remove them or export "
                         "the scene without them")
    import math

    plan = model.plan
    for name, value in (("simulation step", plan.dt), ("end time", plan.t_end)):
        if not math.isfinite(value) or value <= 0:
            raise InputError(model.source, None, f"no {name}: MUSEN text scenes do not carry one; "
                             "give it in a cmusen job script or with --step/--end-time/--save-step")
    if plan.save_every_time is None and plan.save_every_steps is None:
        raise InputError(model.source, None, "no saving step: give SAVING_STEP in the job script "
                         "or --save-step")


def read_granular(path: str | Path, kind: str, end_time: float | None = None,
                  step: float | None = None, save_step: float | None = None,
                  steps: int | None = None) -> tuple[GranularModel, list[str]]:
    """Read a MUSEN scene or DEMDF file and apply command-line overrides."""
    if kind == "demdf":
        from .translate import demdf

        return demdf.read(path, time_end=end_time, steps=steps, save_every=save_step), []
    from .translate import musen

    if steps is not None:
        raise InputError(path, None, "--steps is for DEMDF inputs; a MUSEN scene takes --end-time")
    model = musen.read(path)
    return model, bare_scene_settings(model, end_time, step, save_step)


def bare_scene_settings(model: GranularModel, end_time: float | None, step: float | None,
                        save_step: float | None) -> list[str]:
    """Settings for a bare MUSEN scene, as cmusen would simulate it after IMPORT_FROM_TEXT:
    Hertz-Mindlin particle-particle and particle-wall, elastic solid bonds (breakage on),
    gravity (0, 0, -9.81); step, saving step and end time from the command line (MUSEN's
    defaults 1e-6 s, 1e-3 s and 1 s, with a warning, when not given)."""
    from .translate.musen_script import (MUSEN_DEFAULTS, SUPPORTED_MODELS, MusenJob,
                                         MusenModelSpec, apply_simulator_settings)

    for name, value in (("end-time", end_time), ("step", step), ("save-step", save_step)):
        if value is not None and not value > 0:
            raise InputError(model.source, None, f"--{name} must be positive, got {value:g}")
    job = MusenJob(path=model.source, index=0, line=0, component="SIMULATOR",
                   simulation_step=step or 0.0, saving_step=save_step or 0.0,
                   end_time=end_time or 0.0, ext_accel=tuple(MUSEN_DEFAULTS["gravity"]))
    job.models = [MusenModelSpec(name=SUPPORTED_MODELS["PP"], params="", kind="PP", line=0)]
    if model.triangles is not None and model.triangles.count:
        job.models.append(MusenModelSpec(name=SUPPORTED_MODELS["PW"], params="", kind="PW", line=0))
    if model.bonds is not None and model.bonds.count:
        job.models.append(MusenModelSpec(name=SUPPORTED_MODELS["SB"], params="", kind="SB", line=0))
    apply_simulator_settings(model, job)
    plan = model.plan
    model.warnings = [(kind, f"no --step/--save-step/--end-time given: MUSEN's defaults are used "
                              f"(step {plan.dt:g} s, saving step {plan.save_every_time:g} s, end "
                              f"{plan.t_end:g} s)") if kind == "musen-default-settings" else (kind, text)
                      for kind, text in model.warnings]
    said = [f"models {', '.join(spec.name for spec in job.models)} (MUSEN's for a bare scene)",
            "gravity 0 0 -9.81 m/s^2 (MUSEN's default)"]
    for name, value in (("end time", end_time), ("simulation step", step), ("saving step", save_step)):
        if value is not None:
            said.append(f"{name} {value:g} s")
    return said


def _initial_frame(model: GranularModel):
    """The model's start state as a frame (exporting a scene that was never simulated)."""
    import numpy as np

    from .granmodel import GranularFrame

    s = model.spheres
    t = model.plan.t_start
    alive = (s.active_start <= t) & (s.active_end > t)
    rows = np.flatnonzero(alive)
    frame = GranularFrame(time=t, step=0, sphere_rows=rows, position=s.position[rows],
                          velocity=s.velocity[rows], omega=s.omega[rows],
                          force=np.zeros((rows.size, 3)), quaternion=s.quaternion[rows])
    if model.bonds is not None:
        b = model.bonds
        frame.bond_alive = (b.active_start <= t) & (b.active_end > t)
        frame.bond_end_time = np.where(frame.bond_alive, np.inf, b.active_end)
        frame.bond_force = np.zeros((b.count, 3)) if b.force is None else b.force
    if model.triangles is not None:
        tr = model.triangles
        frame.triangle_vertices = tr.vertices
        frame.triangle_velocity = tr.velocity
        frame.triangle_force = np.zeros((tr.count, 3))
    return frame


def _script_model(job, handles: dict, path_of) -> GranularModel:
    """The scene a SIMULATOR job starts from: a handle made earlier, or a text scene."""
    import copy

    from .translate import musen

    source = path_of(job.source_file, job, "SOURCE_FILE")
    if source in handles:
        kind, value = handles[source]
        if kind == "result":
            raise InputError(job.path, job.where("SOURCE_FILE"), f"{job.source_file} is a simulation "
                             "result of an earlier job; continuing a result is not supported: "
                             "simulate the scene with a later END_TIME instead")
        return copy.deepcopy(value)
    if source.suffix.lower() == ".mdem":
        raise InputError(job.path, job.where("SOURCE_FILE"), f"{job.source_file}: no earlier job of "
                         "this script produced this .mdem and fibrelmp cannot read binary MUSEN "
                         "files: export it as text (COMPONENT EXPORT_TO_TEXT) or import a text scene "
                         "first (COMPONENT IMPORT_FROM_TEXT)")
    return _read_scene(source, job, "SOURCE_FILE")


def _read_scene(source: Path, job, key: str) -> GranularModel:
    """A text scene named by a script line: a missing file is reported at that line."""
    from .translate import musen

    if not source.exists():
        raise InputError(job.path, job.where(key), f"{key} {source}: file not found")
    return musen.read(source)


def model_for_check(path: str | Path, kind: str) -> GranularModel:
    """The model ``check``/``translate`` show: the input itself, or for a cmusen script the
    scene of its first SIMULATOR job with that job's settings applied."""
    if kind != "musen-script":
        return read_granular(path, kind)[0]
    from .translate.musen_script import apply_simulator_settings, read_script

    jobs = read_script(path)
    handles: dict = {}
    path_of = _path_resolver(Path(path))
    for job in jobs:
        if job.component == "IMPORT_FROM_TEXT":
            from .translate import musen

            handles[path_of(job.result_file, job, "RESULT_FILE")] = \
                ("scene", _read_scene(path_of(job.source_file, job, "SOURCE_FILE"), job, "SOURCE_FILE"))
        elif job.component == "SIMULATOR":
            model = _script_model(job, handles, path_of)
            apply_simulator_settings(model, job)
            return model
    raise InputError(path, None, "the script has no SIMULATOR job")


def _path_resolver(script: Path):
    base = script.resolve().parent

    def path_of(name: str | None, job, key: str) -> Path:
        if not name:
            # no line: the job is named instead (and check's line patching stays quiet about it)
            raise InputError(job.path, None, f"job {job.index} ({job.component}, line {job.line}) "
                             f"has no '{key}'")
        p = Path(name)
        return (p if p.is_absolute() else base / p).resolve()
    return path_of


def run_musen_script(path: str | Path, work: str | Path | None = None, progress: bool = True,
                     say: Callable[[str], None] | None = None,
                     warn: Callable | None = None,
                     checkpoints: Checkpoints = Checkpoints()) -> GranularResult:
    """Run a cmusen job script unchanged.

    ``.mdem`` files produced by an earlier job of the script are handles: IMPORT_FROM_TEXT
    stores the scene in memory, SIMULATOR stores its frames in an on-disk spool, and
    EXPORT_TO_TEXT writes them as MUSEN text.  A SIMULATOR result nobody exports is written as
    text next to its ``.mdem`` name (said as a note)."""
    from .post.frame_spool import FrameSpool
    from .post.musen_out import MusenResultWriter
    from .translate import musen
    from .translate.musen_script import apply_simulator_settings, read_script

    say = say or (lambda text: None)
    script = Path(path).resolve()
    jobs = read_script(script)
    path_of = _path_resolver(script)
    work_root = (Path(work) if work is not None else script.parent / f"{script.stem}_work").resolve()
    exported = {path_of(j.source_file, j, "SOURCE_FILE") for j in jobs
                if j.component == "EXPORT_TO_TEXT" and j.source_file}
    handles: dict[Path, tuple[str, object]] = {}
    res = GranularResult()
    spools: list[FrameSpool] = []
    rank0 = _is_rank0()
    try:
        for job in jobs:
            if job.component == "IMPORT_FROM_TEXT":
                target = path_of(job.result_file, job, "RESULT_FILE")
                model = _read_scene(path_of(job.source_file, job, "SOURCE_FILE"), job, "SOURCE_FILE")
                handles[target] = ("scene", model)
                say(f"job {job.index}: imported {job.source_file} ({model.spheres.count} spheres) "
                    f"as {job.result_file} (kept in memory)")
            elif job.component == "SIMULATOR":
                model = _script_model(job, handles, path_of)
                apply_simulator_settings(model, job)
                if warn is not None:
                    warn(model.warnings)
                target = path_of(job.result_file, job, "RESULT_FILE")
                job_work = work_root / f"job{job.index}"
                say(f"job {job.index}: simulating {job.source_file} to t = {model.plan.t_end:g} s")
                sinks: list = []
                spool = None
                if target in exported and rank0:
                    spool = FrameSpool(job_work / "frames")
                    spools.append(spool)
                    sinks.append(spool)
                if not (target.suffix.lower() == ".mdem" and target in exported):
                    # nobody exports this result: write it as MUSEN text right away
                    check_musen_runnable(model)
                    text, note = musen_result_path(target)
                    if note:
                        res.notes.append(note)
                    if rank0:
                        sinks.append(MusenResultWriter(model, text))
                        res.outputs.append(text)
                res.jobs.append(simulate(model, job_work, sinks, progress, checkpoints))
                handles[target] = ("result", (model, spool))
            elif job.component == "EXPORT_TO_TEXT":
                source = path_of(job.source_file, job, "SOURCE_FILE")
                if source not in handles:
                    raise InputError(job.path, job.where("SOURCE_FILE"),
                                     f"{job.source_file}: no earlier job of this script produced it"
                                     + (" and fibrelmp cannot read binary MUSEN files"
                                        if source.suffix.lower() == ".mdem" else ""))
                target, note = musen_result_path(path_of(job.result_file, job, "RESULT_FILE"))
                if note:
                    res.notes.append(note)
                kind, value = handles[source]
                model, spool = (value, None) if kind == "scene" else value
                if rank0:
                    writer = MusenResultWriter(model, target, precision=job.precision,
                                               time_interval=job.time_interval,
                                               selectors=job.text_export)
                    try:
                        for frame in (spool if spool is not None else [_initial_frame(model)]):
                            writer.add(frame)
                    except BaseException:
                        writer.abort()
                        raise
                    writer.close()
                    res.outputs.append(target)
                say(f"job {job.index}: exported {job.source_file} as {target.name}")
            else:
                raise InputError(job.path, job.where("COMPONENT"), f"COMPONENT {job.component} is "
                                 "not supported (fibrelmp runs SIMULATOR, IMPORT_FROM_TEXT and "
                                 "EXPORT_TO_TEXT jobs)")
    finally:
        for spool in spools:
            spool.remove()
    return res
