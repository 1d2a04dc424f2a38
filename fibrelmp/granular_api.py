"""Running granular inputs (MUSEN scenes and cmusen scripts, DEMDF documents).

Readers give a GranularModel; ``granular_run.run_granular`` runs it on LAMMPS and streams
GranularFrames; the format's writer turns them into the user's own result files.  The cmusen
script driver keeps simulated results as on-disk frame spools, so a script that exports one
simulation several times never holds all frames in memory.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel

if TYPE_CHECKING:
    from fibrelmp.outputs import Outputs


@dataclass
class GranularResult:
    outputs: list[Path] = field(default_factory=list)
    jobs: list = field(default_factory=list)        # GranularJob per simulation
    notes: list[str] = field(default_factory=list)  # things the CLI should say (renames, removals)


def _is_rank0() -> bool:
    from fibrelmp.runner import mpi_rank_size

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
    from fibrelmp.granular_run import run_granular

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


def demdf_outputs(model: GranularModel, out: str | Path | None = None,
                  work: str | Path | None = None) -> tuple["Outputs", Path]:
    """Where a DEMDF run writes: ``<filename>_<n>.json`` in the input's folder (or ``-o``);
    a ``filename`` that leaves that folder is refused."""
    import re

    from fibrelmp.outputs import Outputs

    info = model.passthrough["demdf"]
    folder = (Path(out) if out is not None else Path(model.source).parent).resolve()
    name = str(info["filename"])
    if Path(name).is_absolute() or ".." in Path(name).parts or "/" in name or "\\" in name:
        raise InputError(model.source, None, f"output filename {name!r} must be a plain file name: "
                         f"snapshots are written into {folder}")
    work_folder = (Path(work) if work is not None else folder / f"{Path(model.source).stem}_work").resolve()
    inputs = [Path(model.source)] + ([Path(info["particles_file"])] if info.get("particles_file") else [])
    pattern = re.compile(re.escape(name) + r"_\d+\.json")
    return Outputs(Path(model.source), work_folder, patterns=[(folder, pattern)], inputs=inputs), folder


def run_demdf(path: str | Path, out: str | Path | None = None, work: str | Path | None = None,
              progress: bool = True, time_end: float | None = None, steps: int | None = None,
              save_every: float | None = None, warn: Callable | None = None,
              say: Callable[[str], None] | None = None,
              checkpoints: Checkpoints = Checkpoints(), force: bool = False) -> GranularResult:
    """DEMDF: snapshots ``<filename>_<saveCount>.json`` next to the input (or in ``out``);
    earlier snapshots of the same name are replaced, all of them, only with ``force``."""
    from fibrelmp.outputs import finish, locked
    from fibrelmp.translate.demdf.writer import DemdfSnapshotWriter
    from fibrelmp.translate.demdf import reader as demdf

    model = demdf.read(path, time_end=time_end, steps=steps, save_every=save_every)
    if warn is not None:
        warn(model.warnings)
    outputs, folder = demdf_outputs(model, out, work)
    said = len(model.warnings)
    result = GranularResult()
    rank0 = _is_rank0()
    with locked(outputs, force or checkpoints.resume, 0 if rank0 else 1):
        writer = DemdfSnapshotWriter(model, folder) if rank0 else None
        job = simulate(model, outputs.work, [writer] if writer else [], progress, checkpoints)
        result.jobs.append(job)
        if writer is not None:
            result.outputs.extend(getattr(writer, "written", []))
            finish(outputs, result.outputs)
    if warn is not None:
        warn(model.warnings[said:])          # found while translating or running
    return result


def scene_result_path(scene: str | Path, out: str | Path | None = None) -> Path:
    """Where a bare MUSEN scene's result goes: ``out``, else ``<scene>_result.txt`` beside it."""
    scene = Path(scene)
    return Path(out) if out is not None else scene.with_name(f"{scene.stem}_result.txt")


def musen_result_path(path: str | Path) -> tuple[Path, str | None]:
    """MUSEN result name: a ``.mdem`` name becomes ``.txt`` (fibrelmp writes text only)."""
    path = Path(path)
    if path.suffix.lower() == ".mdem":
        new = path.with_suffix(".txt")
        return new, f"MUSEN binary results are not written: {path} becomes {new} (MUSEN text format)"
    return path, None


def run_musen_scene(model: GranularModel, result: str | Path, work: str | Path | None = None,
                    progress: bool = True, precision: int = 6,
                    checkpoints: Checkpoints = Checkpoints(), force: bool = False) -> GranularResult:
    """Simulate a MUSEN scene whose plan (step, end, saves) is already set."""
    from fibrelmp.outputs import Outputs, finish, locked
    from fibrelmp.translate.musen.writer import MusenResultWriter

    check_musen_runnable(model)
    target, note = musen_result_path(result)
    target = target.resolve()
    work_folder = (Path(work) if work is not None else target.parent / f"{target.stem}_work").resolve()
    outputs = Outputs(Path(model.source), work_folder, [target], inputs=[Path(model.source)])
    res = GranularResult(notes=[note] if note else [])
    rank0 = _is_rank0()
    with locked(outputs, force or checkpoints.resume, 0 if rank0 else 1):
        writer = MusenResultWriter(model, target, precision=precision) if rank0 else None
        res.jobs.append(simulate(model, work_folder, [writer] if writer else [], progress, checkpoints))
        if writer is not None:
            res.outputs.append(target)
            finish(outputs, res.outputs)
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
        from fibrelmp.translate.demdf import reader as demdf

        return demdf.read(path, time_end=end_time, steps=steps, save_every=save_step), []
    from fibrelmp.translate.musen import scene as musen

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
    from fibrelmp.translate.musen.script import (MUSEN_DEFAULTS, SUPPORTED_MODELS, MusenJob,
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

    from fibrelmp.granmodel import GranularFrame

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
    """The scene a SIMULATOR job starts from (a copy): a handle made earlier, or a text scene."""
    import copy

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
    from fibrelmp.translate.musen import scene as musen

    if not source.exists():
        raise InputError(job.path, job.where(key), f"{key} {source}: file not found")
    return musen.read(source)


def model_for_check(path: str | Path, kind: str) -> GranularModel:
    """The model ``check``/``translate`` show: the input itself, or for a cmusen script the
    scene of its first SIMULATOR job with that job's settings applied (after checking every
    job of the script, as ``run`` does before it starts)."""
    if kind != "musen-script":
        return read_granular(path, kind)[0]
    plan = plan_musen_script(path)
    for step in plan.steps:
        if step.kind == "simulate":
            return step.model
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


@dataclass
class ScriptStep:
    """One job of a cmusen script, resolved and checked before anything runs."""
    job: object                          # MusenJob
    kind: str                            # "import" | "simulate" | "export"
    handle: Path | None = None           # the .mdem name it makes (import/simulate)
    source: Path | None = None           # the handle it reads (export)
    model: GranularModel | None = None   # import: the scene; simulate: scene + settings
    written: Path | None = None          # the MUSEN text file it writes, if any
    spool: bool = False                  # simulate: keep the frames for a later export
    notes: list[str] = field(default_factory=list)


@dataclass
class ScriptPlan:
    script: Path
    steps: list[ScriptStep]
    inputs: list[Path]                   # the script and every text scene it reads


def plan_musen_script(path: str | Path, out: str | Path | None = None) -> ScriptPlan:
    """Check every job of a cmusen script before any of them runs: scenes read, settings
    applied, the LAMMPS job of every simulation built (in memory), every result located.

    Results go where RESULT_FILE says (relative to the script), or with ``out`` into that
    folder under their relative RESULT_FILE names (an absolute or ``..`` name is refused)."""
    from fibrelmp.textio import patched_reading
    from fibrelmp.translate.granular_job import build_granular_job
    from fibrelmp.translate.musen.script import apply_simulator_settings, read_script

    script = Path(path).resolve()
    jobs = read_script(Path(path))          # messages name the script as the user did
    path_of = _path_resolver(script)
    out_folder = Path(out).resolve() if out is not None else None

    def written_path(job) -> tuple[Path, str | None]:
        name = job.result_file
        if out_folder is None:
            return musen_result_path(path_of(name, job, "RESULT_FILE"))
        if not name:
            path_of(name, job, "RESULT_FILE")       # the usual message
        rel = Path(name)
        if rel.is_absolute() or ".." in rel.parts:
            raise InputError(job.path, job.where("RESULT_FILE"), f"RESULT_FILE {name} cannot be "
                             f"placed in -o {out_folder}: use a relative name without '..', or leave out -o")
        return musen_result_path(out_folder / rel)

    exported = {path_of(j.source_file, j, "SOURCE_FILE") for j in jobs
                if j.component == "EXPORT_TO_TEXT" and j.source_file}
    handles: dict[Path, tuple[str, GranularModel]] = {}
    inputs: list[Path] = [script]
    steps: list[ScriptStep] = []
    for job in jobs:
        if job.component == "IMPORT_FROM_TEXT":
            source = path_of(job.source_file, job, "SOURCE_FILE")
            model = _read_scene(source, job, "SOURCE_FILE")
            inputs.append(source)
            handle = path_of(job.result_file, job, "RESULT_FILE")
            handles[handle] = ("scene", model)
            steps.append(ScriptStep(job, "import", handle=handle, model=model))
        elif job.component == "SIMULATOR":
            source = path_of(job.source_file, job, "SOURCE_FILE")
            if source not in handles and source.suffix.lower() != ".mdem":
                inputs.append(source)
            model = _script_model(job, handles, path_of)
            apply_simulator_settings(model, job)
            check_musen_runnable(model)
            if not patched_reading():        # (check re-reading with placeholder values)
                build_granular_job(model, script.parent)  # translation errors now, not mid-script
            handle = path_of(job.result_file, job, "RESULT_FILE")
            step = ScriptStep(job, "simulate", handle=handle, model=model, spool=handle in exported)
            if not (handle.suffix.lower() == ".mdem" and handle in exported):
                # nobody exports this result: it is written as MUSEN text right away
                step.written, note = written_path(job)
                if note:
                    step.notes.append(note)
            handles[handle] = ("result", model)
            steps.append(step)
        elif job.component == "EXPORT_TO_TEXT":
            source = path_of(job.source_file, job, "SOURCE_FILE")
            if source not in handles:
                raise InputError(job.path, job.where("SOURCE_FILE"),
                                 f"{job.source_file}: no earlier job of this script produced it"
                                 + (" and fibrelmp cannot read binary MUSEN files"
                                    if source.suffix.lower() == ".mdem" else ""))
            step = ScriptStep(job, "export", source=source, model=handles[source][1])
            step.written, note = written_path(job)
            if note:
                step.notes.append(note)
            steps.append(step)
        else:
            raise InputError(job.path, job.where("COMPONENT"), f"COMPONENT {job.component} is "
                             "not supported (fibrelmp runs SIMULATOR, IMPORT_FROM_TEXT and "
                             "EXPORT_TO_TEXT jobs)")
    inputs = list(dict.fromkeys(inputs))
    for step in steps:
        if step.written is not None and step.written in inputs:
            raise InputError(step.job.path, step.job.where("RESULT_FILE"), f"RESULT_FILE "
                             f"{step.job.result_file} is an input of this script ({step.written}): "
                             "the result would overwrite it; choose another name")
    return ScriptPlan(script, steps, inputs)


def run_musen_script(path: str | Path, work: str | Path | None = None, progress: bool = True,
                     say: Callable[[str], None] | None = None,
                     warn: Callable | None = None,
                     checkpoints: Checkpoints = Checkpoints(), out: str | Path | None = None,
                     force: bool = False) -> GranularResult:
    """Run a cmusen job script unchanged, after checking all of it (``plan_musen_script``).

    ``.mdem`` files produced by an earlier job of the script are handles: IMPORT_FROM_TEXT
    keeps the scene in memory, SIMULATOR keeps its frames in an on-disk spool, and
    EXPORT_TO_TEXT writes them as MUSEN text.  A SIMULATOR result nobody exports is written as
    text next to its ``.mdem`` name (said as a note)."""
    from fibrelmp.outputs import Outputs, finish, locked
    from fibrelmp.frame_spool import FrameSpool
    from fibrelmp.translate.musen.writer import MusenResultWriter

    say = say or (lambda text: None)
    plan = plan_musen_script(path, out)
    script = plan.script
    base = Path(out) if out is not None else script.parent
    work_root = (Path(work) if work is not None else base / f"{script.stem}_work").resolve()
    files = [st.written for st in plan.steps if st.written is not None]
    outputs = Outputs(script, work_root, list(dict.fromkeys(files)), inputs=plan.inputs)
    res = GranularResult()
    spools: dict[Path, FrameSpool] = {}
    rank0 = _is_rank0()
    with locked(outputs, force or checkpoints.resume, 0 if rank0 else 1):
        try:
            for step in plan.steps:
                job = step.job
                res.notes.extend(step.notes)
                if step.kind == "import":
                    say(f"job {job.index}: imported {job.source_file} ({step.model.spheres.count} "
                        f"spheres) as {job.result_file} (kept in memory)")
                elif step.kind == "simulate":
                    model = step.model
                    if warn is not None:
                        warn(model.warnings)
                    said = len(model.warnings)
                    job_work = work_root / f"job{job.index}"
                    say(f"job {job.index}: simulating {job.source_file} to t = {model.plan.t_end:g} s")
                    sinks: list = []
                    if step.spool and rank0:
                        spools[step.handle] = FrameSpool(job_work / "frames")
                        sinks.append(spools[step.handle])
                    if step.written is not None and rank0:
                        sinks.append(MusenResultWriter(model, step.written))
                        res.outputs.append(step.written)
                    res.jobs.append(simulate(model, job_work, sinks, progress, checkpoints))
                    if warn is not None:
                        warn(model.warnings[said:])  # found while translating or running
                else:
                    spool = spools.get(step.source)
                    if rank0:
                        writer = MusenResultWriter(step.model, step.written, precision=job.precision,
                                                   time_interval=job.time_interval,
                                                   selectors=job.text_export)
                        try:
                            for frame in (spool if spool is not None else [_initial_frame(step.model)]):
                                writer.add(frame)
                        except BaseException:
                            writer.abort()
                            raise
                        writer.close()
                        res.outputs.append(step.written)
                    say(f"job {job.index}: exported {job.source_file} as {step.written.name}")
            if rank0:
                finish(outputs, res.outputs)
        finally:
            for spool in spools.values():
                spool.remove()
    return res
