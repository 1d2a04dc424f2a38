"""MUSEN text scenes (and results), run as cmusen runs a scene after IMPORT_FROM_TEXT.

Results are MUSEN text, or a ``.mdem`` file when the result's name ends in ``.mdem``
(``musen_result_writer``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.errors import InputError
from fibrelmp.inputformat import InputFormat, RunSettings, Say, Warn

if TYPE_CHECKING:
    from fibrelmp.granmodel import GranularModel
    from fibrelmp.runplan import RunOptions, RunPlan
    from fibrelmp.textio import Patch
    from fibrelmp.translate.granular_job import GranularJob


class SceneInput(InputFormat):
    name = "musen"

    def read(self, path: Path) -> "GranularModel":
        """The scene with MUSEN's settings for a bare scene (``bare_scene_settings``)."""
        return self.read_with(path, RunSettings())[0]

    def read_with(self, path: Path, settings: RunSettings) -> tuple["GranularModel", list[str]]:
        """The scene with the command line's settings, and what they set (to say)."""
        if settings.steps is not None:
            raise InputError(path, None, "--steps is for DEMDF inputs; a MUSEN scene takes --end-time")
        from fibrelmp.translate.granular.bonds import check_bond_directions
        from fibrelmp.translate.granular.spheres import check_distinct_positions

        model = self.read_scene(path)
        check_bond_directions(model)          # `check` finds these too, not only `run`
        check_distinct_positions(model)       # (a bond's spheres: the bond's line is named)
        return model, bare_scene_settings(model, settings.end_time, settings.step, settings.save_step)

    def read_scene(self, path: Path) -> "GranularModel":
        from fibrelmp.translate.musen import scene as musen

        return musen.read(path)

    def check_patch(self, path: Path) -> "Patch":
        from fibrelmp.translate.musen.script import check_patch

        return check_patch

    def check_lines(self, path: Path, model: "GranularModel") -> list[str]:
        from fibrelmp.granular_check import summary

        where = scene_result_path(Path(path).resolve())
        return summary(model) + [f"results      {where} (or -o FILE)"]

    def write_job(self, model: "GranularModel", folder: Path) -> "GranularJob":
        from fibrelmp.translate.granular_job import write_granular_job

        return write_granular_job(model, folder)

    def plan(self, path: Path, settings: RunSettings, options: "RunOptions", say: Say,
             warn: Warn) -> "RunPlan":
        model, overrides = self.read_with(path, settings)
        for text in overrides:
            say(f"override: {text}")
        warn(model.warnings)
        return scene_plan(model, scene_result_path(path, settings.out), settings.work,
                          settings.precision, options, settings.also)

    def work_folder(self, path: Path, out: Path | None, work: Path | None) -> Path:
        return _work_folder(scene_result_path(path, out), work)

    def precision_unused(self, path: Path, out: Path | None) -> str | None:
        result = scene_result_path(path, out)
        if is_mdem(result):
            return (f"the result {result.name} is a .mdem file, which stores every number exactly "
                    "(a result named .txt is MUSEN text, whose digits --precision sets)")
        return None


def scene_plan(model: "GranularModel", result: str | Path, work: str | Path | None = None,
               precision: int = 6, options: "RunOptions | None" = None,
               also: tuple[str, ...] = ()) -> "RunPlan":
    """The run of a MUSEN scene whose plan (step, end, saves) is set: one simulation, its
    result at ``result`` (MUSEN text, or ``.mdem`` by its name); ``also``: the formats also
    written from the frames beside it (``fibrelmp.also``)."""
    from fibrelmp.outputs import Outputs
    from fibrelmp.granular_run.request import granular_request
    from fibrelmp.runplan import RunOptions, RunPlan
    from fibrelmp.also import granular_writers

    check_musen_runnable(model)
    target = Path(result).resolve()
    outputs = Outputs(Path(model.source), _work_folder(target, work), [target],
                      inputs=[Path(model.source)])
    extra = granular_writers(also, model, outputs, target.with_suffix(""))
    request = granular_request(model, outputs.work,
                               lambda: [musen_result_writer(model, target, precision=precision)] + extra())
    return RunPlan(outputs, [request], options or RunOptions())


def _work_folder(target: Path, work: str | Path | None) -> Path:
    from fibrelmp.outputs import work_folder

    return work_folder(target.resolve().parent, target.stem, work)


def scene_result_path(scene: str | Path, out: str | Path | None = None) -> Path:
    """Where a bare MUSEN scene's result goes: ``out``, else ``<scene>_result`` beside it, in
    the scene's own form (``.mdem`` for a ``.mdem`` scene, else ``.txt``)."""
    scene = Path(scene)
    suffix = ".mdem" if scene.suffix.lower() == ".mdem" else ".txt"
    return Path(out) if out is not None else scene.with_name(f"{scene.stem}_result{suffix}")


def is_mdem(path: str | Path) -> bool:
    return Path(path).suffix.lower() == ".mdem"


def musen_result_writer(model: "GranularModel", target: str | Path, precision: int = 6, **text):
    """The writer of a MUSEN result at ``target``: ``.mdem`` by its name, else MUSEN text
    (``text``: the text writer's ``time_interval``/``selectors``)."""
    if is_mdem(target):
        # the .mdem home (mdem/) imports this module: its writer comes through the registry
        from fibrelmp import registry

        writer = registry.get("mdem").load(registry.RESULT)
        return writer(model, target, time_interval=text.get("time_interval"))
    from fibrelmp.translate.musen.writer import MusenResultWriter

    return MusenResultWriter(model, target, precision=precision, **text)


def check_musen_runnable(model: GranularModel) -> None:
    plan = model.plan
    for name, value in (("simulation step", plan.dt), ("end time", plan.t_end)):
        if not math.isfinite(value) or value <= 0:
            raise InputError(model.source, None, f"no {name}: MUSEN text scenes do not carry one; "
                             "give it in a cmusen job script or with --step/--end-time/--save-step")
    if plan.save_every_time is None and plan.save_every_steps is None:
        raise InputError(model.source, None, "no saving step: give SAVING_STEP in the job script "
                         "or --save-step")
    from fibrelmp.translate.granular.bonds import check_bond_directions
    from fibrelmp.translate.granular.spheres import check_distinct_positions

    check_bond_directions(model)          # before the outputs are locked (nothing written)
    check_distinct_positions(model)


def bare_scene_settings(model: GranularModel, end_time: float | None, step: float | None,
                        save_step: float | None) -> list[str]:
    """Settings for a bare MUSEN scene, as cmusen would simulate it after IMPORT_FROM_TEXT:
    Hertz-Mindlin particle-particle and particle-wall, elastic solid bonds (breakage on),
    gravity (0, 0, -9.81); step, saving step and end time from the command line (MUSEN's
    defaults 1e-6 s, 1e-3 s and 1 s, with a warning, when not given).  A ``.mdem`` scene's own
    models, steps and gravity (what MUSEN loads with the file) take the defaults' place."""
    from fibrelmp.translate.granular.models import default_model
    from fibrelmp.translate.musen.script import (MUSEN_DEFAULTS, MusenJob, MusenModelSpec,
                                         apply_simulator_settings)
    from fibrelmp.translate.musen.scene_record import scene_record

    for name, value in (("end-time", end_time), ("step", step), ("save-step", save_step)):
        if value is not None and not value > 0:
            raise InputError(model.source, None, f"--{name} must be positive, got {value:g}")
    file_set = scene_record(model).gravity_set          # a .mdem's own settings
    job = MusenJob(path=model.source, index=0, line=0, component="SIMULATOR",
                   simulation_step=step or 0.0, saving_step=save_step or 0.0,
                   end_time=end_time or 0.0,
                   ext_accel=None if file_set else tuple(MUSEN_DEFAULTS["gravity"]))
    stored = {spec.kind for spec in scene_record(model).file_models}
    job.models = [MusenModelSpec(name=default_model(kind).name, params="", kind=kind, line=0)
                  for kind, wanted in (("PP", True),
                                       ("PW", model.triangles is not None and model.triangles.count),
                                       ("SB", model.bonds is not None and model.bonds.count))
                  if wanted and kind not in stored]
    apply_simulator_settings(model, job)
    plan = model.plan
    model.warnings = [(kind, f"no --step/--save-step/--end-time given: MUSEN's defaults are used "
                              f"(step {plan.dt:g} s, saving step {plan.save_every_time:g} s, end "
                              f"{plan.t_end:g} s)") if kind == "musen-default-settings" else (kind, text)
                      for kind, text in model.warnings]
    said = []
    if job.models:
        said.append(f"models {', '.join(spec.name for spec in job.models)} (MUSEN's for a bare scene)")
    if stored:
        said.append(f"models {', '.join(s.name for s in scene_record(model).file_models)} (the file's)")
    said.append("gravity 0 0 -9.81 m/s^2 (MUSEN's default)" if not file_set else
                f"gravity {' '.join('%g' % g for g in model.plan.gravity)} m/s^2 (the file's)")
    for name, value in (("end time", end_time), ("simulation step", step), ("saving step", save_step)):
        if value is not None:
            said.append(f"{name} {value:g} s")
    return said
