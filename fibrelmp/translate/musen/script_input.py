"""cmusen job scripts: IMPORT_FROM_TEXT, SIMULATOR and EXPORT_TO_TEXT jobs, run unchanged.

The whole script is checked first (``plan_musen_script``: every scene read, every job's
settings applied and its LAMMPS job built, every result located), then it becomes one
``RunPlan``: a ``RunRequest`` per SIMULATOR job and an ``Action`` per import/export, whose
results are locked together.  Every job writes what cmusen writes: IMPORT_FROM_TEXT the
``.mdem`` scene, SIMULATOR its result (``.mdem``, or text by its name), EXPORT_TO_TEXT MUSEN
text.  Within a script, the scene an import made and the frames a simulation saved (in an
on-disk spool, ``granular_run.spool``) are handed on in memory; a ``.mdem`` made elsewhere is read
from its file (a scene to simulate, or a file to export with MUSEN's exporter).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.errors import InputError
from fibrelmp.granmodel import GranularModel
from fibrelmp.inputformat import InputFormat, RunSettings, Say, Warn, no_overrides
from fibrelmp.translate.musen.input import check_musen_runnable, is_mdem, musen_result_writer

if TYPE_CHECKING:
    from fibrelmp.outputs import Outputs
    from fibrelmp.runplan import RunOptions, RunPlan, Step
    from fibrelmp.granular_run.spool import FrameSpool
    from fibrelmp.textio import Patch
    from fibrelmp.translate.granular_job import GranularJob


class ScriptInput(InputFormat):
    name = "musen-script"

    def read(self, path: Path) -> "ScriptPlan":
        """The checked plan of the script (``fibrelmp.read`` gives it for a script)."""
        return plan_musen_script(path)

    def model(self, path: Path) -> GranularModel:
        """The scene of the first SIMULATOR job with that job's settings applied (after
        checking every job of the script, as ``run`` does before it starts)."""
        for step in plan_musen_script(path).steps:
            if step.kind == "simulate":
                return step.model
        raise InputError(path, None, "the script has no SIMULATOR job")

    def check_patch(self, path: Path) -> "Patch":
        from fibrelmp.translate.musen.script import check_patch

        return check_patch

    def precision_unused(self, path: Path, out: Path | None) -> str | None:
        return ("a cmusen script sets the digits of its text exports itself "
                "(TEXT_EXPORT_PRECISION in the EXPORT_TO_TEXT job)")

    def check_lines(self, path: Path, model: GranularModel) -> list[str]:
        from fibrelmp.granular_check import summary

        written = [str(st.written) for st in plan_musen_script(path).steps if st.written is not None]
        return summary(model) + [f"results      {', '.join(written) or 'none (the script exports nothing)'}"]

    def write_job(self, model: GranularModel, folder: Path) -> "GranularJob":
        from fibrelmp.translate.granular_job import write_granular_job

        return write_granular_job(model, folder)

    def plan(self, path: Path, settings: RunSettings, options: "RunOptions", say: Say,
             warn: Warn) -> "RunPlan":
        from fibrelmp.outputs import Outputs
        from fibrelmp.runplan import Action, RunPlan

        no_overrides(path, settings, "a cmusen job script sets END_TIME, SIMULATION_STEP and "
                     "SAVING_STEP itself; edit the script instead")
        plan = plan_musen_script(path, settings.out)
        work = self.work_folder(plan.script, settings.out, settings.work).resolve()
        files = [st.written for st in plan.steps if st.written is not None]
        outputs = Outputs(plan.script, work, list(dict.fromkeys(files)), inputs=plan.inputs)
        spools: dict[Path, "FrameSpool"] = {}
        steps: list["Step"] = []
        for st in plan.steps:
            if st.kind == "simulate":
                steps.append(Action(partial(_announce, st, say, warn)))
                steps.append(_simulation(st, work / f"job{st.job.index}", spools,
                                         outputs, settings.also))
            elif st.kind == "generate":
                steps.append(Action(partial(_generated, st, say)))
            else:
                steps.append(Action(partial(_import if st.kind == "import" else _export, st, spools, say)))

        def remove_spools() -> None:
            for spool in spools.values():
                spool.remove()
        return RunPlan(outputs, steps, options, notes=[n for st in plan.steps for n in st.notes],
                       cleanup=[remove_spools])

    def work_folder(self, path: Path, out: Path | None, work: Path | None) -> Path:
        from fibrelmp.outputs import work_folder

        return work_folder(out or Path(path).resolve().parent, Path(path).stem, work)


def _announce(step: "ScriptStep", say: Say, warn: Warn, rank0: bool) -> list[Path]:
    warn(step.model.warnings)
    say(f"job {step.job.index}: simulating {step.job.source_file} to t = {step.model.plan.t_end:g} s")
    return []


def _simulation(step: "ScriptStep", work: Path, spools: dict, outputs: "Outputs",
                also: tuple[str, ...]):
    """A SIMULATOR job: its frames go to a spool (exported later) and/or its MUSEN result
    (and to the ``--also`` formats, named after its RESULT_FILE: ``fibrelmp.also``)."""
    from fibrelmp.granular_run.request import granular_request
    from fibrelmp.granular_run.spool import FrameSpool
    from fibrelmp.also import granular_writers

    extra = granular_writers(also, step.model, outputs, Path(step.written or step.handle).with_suffix(""))

    def writers() -> list:
        made: list = []
        if step.spool:
            spools[step.handle] = FrameSpool(work / "frames")
            made.append(spools[step.handle])
        if step.written is not None:
            made.append(musen_result_writer(step.model, step.written))
        return made + extra()
    return granular_request(step.model, work, writers)


def _import(step: "ScriptStep", spools: dict, say: Say, rank0: bool) -> list[Path]:
    """IMPORT_FROM_TEXT: the text scene as a ``.mdem`` (MUSEN's import)."""
    from fibrelmp.translate.musen.mdem.convert import MdemDocumentWriter, MusenTextDocument

    job = step.job
    written: list[Path] = []
    if rank0:
        with MdemDocumentWriter(step.written) as out:
            out.add(MusenTextDocument.open(step.source))
        written = [step.written]
    say(f"job {job.index}: imported {job.source_file} ({step.model.spheres.count} spheres) as "
        f"{step.written.name}")
    return written


def _generated(step: "ScriptStep", say: Say, rank0: bool) -> list[Path]:
    """PACKAGE_GENERATOR / BONDS_GENERATOR: the scene generated while planning, written."""
    from fibrelmp.translate.musen.generators.steps import write_generated

    written = [write_generated(step.handle, step.written, step.generated)] if rank0 else []
    say(f"job {step.job.index}: {step.job.component} wrote {step.written.name} "
        f"({step.model.spheres.count} spheres, "
        f"{0 if step.model.bonds is None else step.model.bonds.count} bonds)")
    return written


def _export(step: "ScriptStep", spools: dict, say: Say, rank0: bool) -> list[Path]:
    """EXPORT_TO_TEXT: the spooled frames of an earlier simulation (or, for a scene that was
    never simulated, its start state) as MUSEN text."""
    from fibrelmp.runplan import feed
    from fibrelmp.translate.musen.writer import MusenResultWriter

    job = step.job
    written: list[Path] = []
    if rank0 and step.model is None:          # a .mdem made elsewhere: MUSEN's exporter
        written = [_export_file(step.source, step.written, job)]
    elif rank0:
        spool = spools.get(step.source)
        writer = MusenResultWriter(step.model, step.written, precision=job.precision,
                                   time_interval=job.time_interval, selectors=job.text_export)
        written = feed([writer])(iter(spool if spool is not None else [_initial_frame(step.model)]))
    say(f"job {job.index}: exported {job.source_file} as {step.written.name}")
    return written


def _export_file(source: Path, target: Path, job) -> Path:
    from fibrelmp.translate.musen.mdem.convert import MusenTextWriter
    from fibrelmp.translate.musen.mdem.document import MdemFile
    from fibrelmp.translate.musen.mdem.text_export import export

    class _Export(MusenTextWriter):
        def write(self, mdem) -> None:
            export(mdem, self.open(self.target, "w", newline="\n"), self.precision,
                   time_interval=job.time_interval, spool_dir=self.target.parent,
                   selectors=job.text_export)

    with MdemFile(source) as mdem, _Export(target, job.precision) as out:
        out.add(mdem)
    return target


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
    return _read_scene(source, job, "SOURCE_FILE")


def _read_scene(source: Path, job, key: str) -> GranularModel:
    """A scene named by a script line (MUSEN text or ``.mdem``): a missing file is reported
    at that line."""
    from fibrelmp.translate.musen import scene as musen
    from fibrelmp.translate.musen.mdem.model import read_scene

    if not source.exists():
        raise InputError(job.path, job.where(key), f"{key} {source}: file not found")
    return read_scene(source) if is_mdem(source) else musen.read(source)


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
    kind: str                            # "import" | "simulate" | "export" | "generate"
    handle: Path | None = None           # the .mdem name it makes (import/simulate)
    source: Path | None = None           # what it reads (import: the text; export: the handle or file)
    model: GranularModel | None = None   # import: the scene; simulate: scene + settings;
    #                                      export: the handle's (None: a .mdem file made elsewhere)
    written: Path | None = None          # the file it writes, if any
    spool: bool = False                  # simulate: keep the frames for a later export
    notes: list[str] = field(default_factory=list)
    generated: object = None             # generate: the GeneratedFiles holding its .mdem


@dataclass
class ScriptPlan:
    script: Path
    steps: list[ScriptStep]
    inputs: list[Path]                   # the script and every scene or file it reads


def plan_musen_script(path: str | Path, out: str | Path | None = None) -> ScriptPlan:
    """Check every job of a cmusen script before any of them runs: scenes read, settings
    applied, the LAMMPS job of every simulation built (in memory), every result located.

    Results go where RESULT_FILE says (relative to the script), or with ``out`` into that
    folder under their relative RESULT_FILE names (an absolute or ``..`` name is refused)."""
    from fibrelmp.translate.musen.script import read_script

    jobs = read_script(Path(path))          # messages name the script as the user did
    planner = _Planner(Path(path).resolve(), jobs, out)
    steps = [planner.step(job) for job in jobs]
    inputs = list(dict.fromkeys(planner.inputs))
    for step in steps:
        if step.written is not None and step.written in inputs:
            raise InputError(step.job.path, step.job.where("RESULT_FILE"), f"RESULT_FILE "
                             f"{step.job.result_file} is an input of this script ({step.written}): "
                             "the result would overwrite it; choose another name")
    return ScriptPlan(planner.script, steps, inputs)


class _Planner:
    """Plans the jobs of one script in order; ``handles`` are the .mdem names made so far."""

    def __init__(self, script: Path, jobs: list, out: str | Path | None):
        self.script = script
        self.path_of = _path_resolver(script)
        self.out = Path(out).resolve() if out is not None else None
        self.exported = {self.path_of(j.source_file, j, "SOURCE_FILE") for j in jobs
                         if j.component == "EXPORT_TO_TEXT" and j.source_file}
        self.handles: dict[Path, tuple[str, GranularModel]] = {}
        self.inputs: list[Path] = [script]
        self.generated = None                 # generators.steps.GeneratedFiles, when needed
        self.imported: dict[Path, Path] = {}  # handle -> text scene it was imported from

    def step(self, job) -> ScriptStep:
        if job.component == "IMPORT_FROM_TEXT":
            return self.import_(job)
        if job.component == "SIMULATOR":
            return self.simulate(job)
        if job.component == "EXPORT_TO_TEXT":
            return self.export(job)
        if job.component in ("PACKAGE_GENERATOR", "BONDS_GENERATOR", "SNAPSHOT_GENERATOR"):
            return self.generate(job)
        raise InputError(job.path, job.where("COMPONENT"), f"COMPONENT {job.component} is "
                         "not supported (fibrelmp runs SIMULATOR, IMPORT_FROM_TEXT and "
                         "EXPORT_TO_TEXT jobs)")

    def import_(self, job) -> ScriptStep:
        source = self.path_of(job.source_file, job, "SOURCE_FILE")
        model = _read_scene(source, job, "SOURCE_FILE")
        self.inputs.append(source)
        handle = self.path_of(job.result_file, job, "RESULT_FILE")
        self.handles[handle] = ("scene", model)
        self.imported[handle] = source
        if self.generated is not None:
            from fibrelmp.translate.musen.generators.steps import remember_import

            remember_import(handle, source, self.generated)
        step = ScriptStep(job, "import", handle=handle, source=source, model=model)
        self.result(step)
        return step

    def generate(self, job) -> ScriptStep:
        """A generator job: run now (pre-processing), its scene handed on like an import's."""
        from fibrelmp.translate.musen.generators import steps

        if self.generated is None:
            self.generated = steps.GeneratedFiles()
            for handle, (kind, _) in self.handles.items():
                if kind == "scene" and handle in self.imported:
                    steps.remember_import(handle, self.imported[handle], self.generated)
        source = self.path_of(job.source_file, job, "SOURCE_FILE")
        mdem = steps.source_mdem(job, source, self.handles, self.generated)
        if source not in self.handles and source not in self.generated.files:
            self.inputs.append(source)
        handle = self.path_of(job.result_file, job, "RESULT_FILE")
        notes: list[str] = []
        model = steps.run_generator(job, mdem, handle, self.generated, notes.append)
        self.handles[handle] = ("scene", model)
        step = ScriptStep(job, "generate", handle=handle, source=mdem, model=model,
                          notes=[f"job {job.index} ({job.component}): {n.strip()}" for n in notes]
                          + [message for _, message in job.warnings])
        step.generated = self.generated
        self.result(step)
        return step

    def simulate(self, job) -> ScriptStep:
        from fibrelmp.textio import patched_reading
        from fibrelmp.translate.granular_job import build_granular_job
        from fibrelmp.translate.musen.script import apply_simulator_settings

        source = self.path_of(job.source_file, job, "SOURCE_FILE")
        if source not in self.handles:
            self.inputs.append(source)
        model = _script_model(job, self.handles, self.path_of)
        if any(i.makes_agglomerates for i in model.plan.inlets):
            self._agglomerates(job, model)
        apply_simulator_settings(model, job)
        check_musen_runnable(model)
        if not patched_reading():        # (check re-reading with placeholder values)
            build_granular_job(model, self.script.parent)  # translation errors now, not mid-script
        handle = self.path_of(job.result_file, job, "RESULT_FILE")
        step = ScriptStep(job, "simulate", handle=handle, model=model, spool=handle in self.exported)
        self.result(step)
        self.handles[handle] = ("result", model)
        return step

    def _agglomerates(self, job, model: GranularModel) -> None:
        """The generators of agglomerates get theirs from the job's AGGLOMERATES_DB."""
        from fibrelmp.translate.musen.mdem.generators import attach_agglomerates

        db = None
        if job.agglomerates_db:
            db = self.path_of(job.agglomerates_db, job, "AGGLOMERATES_DB")
            self.inputs.append(db)
        materials = {m.key: m.density for m in model.materials}
        model.plan.inlets = attach_agglomerates(model.plan.inlets, db, materials, job.path,
                                                job.where("AGGLOMERATES_DB"))

    def export(self, job) -> ScriptStep:
        source = self.path_of(job.source_file, job, "SOURCE_FILE")
        if self.generated is not None and source in self.generated.files and source not in self.imported:
            model, source = None, self.generated.files[source]     # MUSEN's exporter on it
        elif source in self.handles:
            model = self.handles[source][1]
        elif is_mdem(source) and source.exists():
            from fibrelmp.translate.musen.mdem.document import MdemFile

            MdemFile(source).close()                   # checked now, not mid-script
            self.inputs.append(source)
            model = None
        else:
            raise InputError(job.path, job.where("SOURCE_FILE"),
                             f"{job.source_file}: no earlier job of this script produced it"
                             + ("" if source.exists() else " and there is no such file")
                             + ("" if is_mdem(source) else
                                " (EXPORT_TO_TEXT exports a .mdem file)"))
        step = ScriptStep(job, "export", source=source, model=model)
        self.result(step)
        return step

    def result(self, step: ScriptStep) -> None:
        """Where the job's result goes."""
        job = step.job
        name = job.result_file
        if self.out is None:
            step.written = self.path_of(name, job, "RESULT_FILE")
        else:
            if not name:
                self.path_of(name, job, "RESULT_FILE")       # the usual message
            rel = Path(name)
            if rel.is_absolute() or ".." in rel.parts:
                raise InputError(job.path, job.where("RESULT_FILE"), f"RESULT_FILE {name} cannot be "
                                 f"placed in -o {self.out}: use a relative name without '..', or leave out -o")
            step.written = (self.out / rel).resolve()
