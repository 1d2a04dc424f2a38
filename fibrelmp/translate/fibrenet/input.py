"""FibreNet inputs (``input.txt`` with a ``model_file`` line): the input hook, and where a
run writes.  Its run plan is built in the home (``plan.fibrenet_plan``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.errors import InputError
from fibrelmp.inputformat import InputFormat, RunSettings, Say, Warn, no_overrides

if TYPE_CHECKING:
    from fibrelmp.model import Model
    from fibrelmp.outputs import Outputs
    from fibrelmp.runplan import RunOptions, RunPlan
    from fibrelmp.textio import Patch
    from fibrelmp.translate.lammps_job import Job


class FibreNetInput(InputFormat):
    name = "fibrenet"

    def read(self, path: Path) -> "Model":
        from fibrelmp.translate.fibrenet.reader import read

        return read(path)

    def check_patch(self, path: Path) -> "Patch":
        from fibrelmp.translate.fibrenet.reader import check_patch

        return check_patch(path)

    def precision_unused(self, path: Path, out: Path | None) -> str | None:
        return ("FibreNet's results have FibreNet's own digits (xyz: 5 decimals, restart: 6 "
                "significant digits)")

    def check_lines(self, path: Path, model: "Model") -> list[str]:
        from fibrelmp.sanity import time_step_check, units_line

        p = model.particles
        lines = [f"input        {model.source}",
                 units_line(model),
                 f"beads        {p.count}",
                 f"springs      {model.bonds.count}",
                 f"angles       {model.angles.count}",
                 f"types        {', '.join(p.type_names)}",
                 "pairs        " + "; ".join(f"{law.kind} {p.type_names[law.type_i]}-{p.type_names[law.type_j]}"
                                             for law in model.pairs),
                 f"box          {' x '.join(f'{x:g}' for x in model.box.lengths)} "
                 f"({'periodic' if all(model.box.periodic) else 'finite, wall k = %g' % model.box.wall_stiffness})",
                 f"time step    {model.dynamics.dt:g}   lambda {model.dynamics.lambda_:g}   damping {model.dynamics.damping:g}"]
        for st in model.plan.stages:
            extra = f" in chunks of {st.chunk}" + (", velocities reset" if st.reset else "") if st.name == "relax" else \
                f", output every {model.plan.output.every}"
            lines.append(f"stage        {st.name}: {st.steps} steps{extra}")
        lines += time_step_check(model)
        outputs = fibrenet_outputs(model)[0]
        lines.append(f"results      {', '.join(str(p) for p in outputs.files)} (or in -o DIR)")
        return lines

    def write_job(self, model: "Model", folder: Path) -> "Job":
        from fibrelmp.translate.lammps_job import write_job

        return write_job(model, folder)

    def plan(self, path: Path, settings: RunSettings, options: "RunOptions", say: Say,
             warn: Warn) -> "RunPlan":
        no_overrides(path, settings, "FibreNet inputs set their own steps: --end-time/--step/"
                     "--save-step/--steps are for MUSEN and DEMDF inputs")
        model = self.read(path)
        warn(model.warnings)
        from fibrelmp.translate.fibrenet.plan import fibrenet_plan

        return fibrenet_plan(model, settings.out, settings.work, options, settings.also)

    def work_folder(self, path: Path, out: Path | None, work: Path | None) -> Path:
        if work is not None:
            return Path(work)
        return fibrenet_outputs(self.read(path), out)[0].work


def fibrenet_outputs(model: "Model", out: str | Path | None = None,
                     work: str | Path | None = None) -> tuple["Outputs", Path, str]:
    """Where a FibreNet run writes: (outputs, output folder, file name prefix).

    ``output_file`` is a name inside the output folder (``-o``, default the input's folder);
    one that leaves it (``..``) is refused, and an absolute one is honoured only without
    ``-o`` (as FibreNet would write it)."""
    from fibrelmp.outputs import Outputs
    from fibrelmp.translate.lammps_job import RESTART_SUFFIX, XYZ_SUFFIX

    spec = model.plan.output
    name = Path(spec.basename)
    if name.is_absolute():
        if out is not None:
            raise InputError(model.source, spec.line, f"output_file {spec.basename} is an absolute "
                             "path, which -o cannot place: give a plain name, or leave out -o")
        target = name
    else:
        folder = (Path(out) if out is not None else spec.folder).resolve()
        if ".." in name.parts:
            raise InputError(model.source, spec.line, f"output_file {spec.basename} leaves the "
                             f"output folder {folder}: give a name inside it")
        target = folder / name
    if not target.name or target.name in (".", ".."):
        raise InputError(model.source, spec.line, f"output_file {spec.basename!r} names no file")
    folder, prefix = target.parent, target.name
    from fibrelmp.outputs import work_folder as job_folder

    work_folder = job_folder(folder, prefix, work)
    files = [folder / f"{prefix}{XYZ_SUFFIX[f]}" for f in spec.fields] + [folder / f"{prefix}{RESTART_SUFFIX}"]
    family = [folder / f"{prefix}{suffix}" for suffix in (*XYZ_SUFFIX.values(), RESTART_SUFFIX)]
    return Outputs(model.source, work_folder, files, family, inputs=list(model.inputs)), folder, prefix
