"""High-level operations shared by the CLI and by Python users."""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from fibrelmp.errors import InputError
from fibrelmp.model import Model

if TYPE_CHECKING:
    import numpy as np

    from fibrelmp.outputs import Outputs
from fibrelmp.translate.lammps_job import Job, write_job


def read_input(path: str | Path) -> Model:
    """Parse any supported input into the neutral Model."""
    from fibrelmp.translate.fibrenet.reader import read

    return read(path)


def translate(model: Model, folder: str | Path) -> Job:
    """Write ``in.lammps`` and the data file for ``model`` into ``folder``."""
    return write_job(model, folder)


@dataclass
class RunResult:
    job: Job
    outputs: list[Path]


def fibrenet_outputs(model: Model, out: str | Path | None = None,
                     work: str | Path | None = None) -> tuple["Outputs", Path, str]:
    """Where a FibreNet run writes: (outputs, output folder, file name prefix).

    ``output_file`` is a name inside the output folder (``-o``, default the input's folder);
    one that leaves it (``..``) is refused, and an absolute one is honoured only without
    ``-o`` (as FibreNet would write it)."""
    from fibrelmp.outputs import Outputs
    from fibrelmp.translate.fibrenet.writer import RESTART_SUFFIX, XYZ_SUFFIX

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
    work_folder = (Path(work) if work is not None else folder / f"{prefix}_work").resolve()
    files = [folder / f"{prefix}{XYZ_SUFFIX[f]}" for f in spec.fields] + [folder / f"{prefix}{RESTART_SUFFIX}"]
    family = [folder / f"{prefix}{suffix}" for suffix in (*XYZ_SUFFIX.values(), RESTART_SUFFIX)]
    return Outputs(model.source, work_folder, files, family, inputs=list(model.inputs)), folder, prefix


def run(model: Model, out: str | Path | None = None, work: str | Path | None = None,
        progress: bool = True, keep_work: bool = True, checkpoint_every: int | None = None,
        resume: bool = False, force: bool = False) -> RunResult:
    """Translate, run in-process and write the results in the input's own format.

    ``checkpoint_every`` writes a checkpoint every that many steps (and one on SIGTERM or
    Ctrl-C in any case); ``resume`` continues from the checkpoint in the work folder.
    Existing results are replaced (completely) only with ``force``; the output and work
    folders are locked for the run."""
    from fibrelmp.outputs import finish, locked
    from fibrelmp.post.lammps_dump.reader import iter_frames
    from fibrelmp.post.to_fibrenet import write_fibrenet
    from fibrelmp.runner import mpi_rank_size, run_script

    spec = model.plan.output
    outputs, out_folder, prefix = fibrenet_outputs(model, out, work)
    work_folder = outputs.work
    rank, size = mpi_rank_size()
    # resuming continues this run's own (locked) work: its partial results are not "earlier" ones
    with locked(outputs, force or resume, rank):
        # every rank parses and renders identically; only rank 0 writes the job files
        job = write_job(model, work_folder, write_files=rank == 0)
        if size > 1:
            from fibrelmp._lammps import mpi_barrier
            mpi_barrier()        # the data file is complete before any rank hashes it
        checkpoints = prepare_checkpoints(job.folder, job.text, checkpoint_every, resume,
                                          [job.frames.name], rank, [job.data])
        if rank == 0 and job.frames.exists() and not resume:
            job.frames.unlink()
        names = {lt: model.particles.type_names[t] for lt, t in enumerate(job.type_of_ltype) if lt > 0}
        types = None if spec.types is None else {model.particles.type_names[t] for t in spec.types}

        def convert(frames) -> list[Path]:
            return write_fibrenet(_expected_frames(frames, job), prefix, out_folder, spec.fields,
                                  names, model.dynamics.dt, model.box.lengths, types,
                                  warn=model.warn)

        outputs_written: list[Path] = []
        if rank == 0 and size == 1 and (os.cpu_count() or 1) > 1:
            # convert each frame on a second core while LAMMPS computes the next one (the lammps
            # module releases the GIL inside the library)
            outputs_written = _run_with_converter(job, progress, convert, checkpoints)
        else:
            run_script(job.script, job.total_steps, progress=progress, text=job.text,
                       checkpoints=checkpoints)
            if rank == 0:
                outputs_written = convert(iter_frames(job.frames))
        if rank == 0:
            finish(outputs, outputs_written)
            if not keep_work:
                shutil.rmtree(work_folder, ignore_errors=True)
    return RunResult(job, outputs_written)


def _expected_frames(frames, job: Job):
    """``frames``, checked against the job's schedule: a missing, repeated or extra frame is
    a RunError, never a silently wrong output file."""
    from fibrelmp.errors import RunError

    expected = iter(job.output_steps)
    for frame in frames:
        want = next(expected, None)
        if frame.step != want:
            raise RunError(f"{job.frames}: expected the frame of step {want}, found step {frame.step}")
        yield frame
    want = next(expected, None)
    if want is not None:
        raise RunError(f"{job.frames}: the run ended without the frame of step {want}")


def prepare_checkpoints(folder: Path, text: str, every: int | None, resume: bool,
                        appended: list[str], rank: int, inputs: list[Path] = ()):
    """Checkpointing for a job (always on: a SIGTERM/Ctrl-C leaves a checkpoint behind);
    when resuming, load the state (refused when the script or any of ``inputs``, the files
    the job reads, changed) and cut the dumps back to the checkpoint."""
    from fibrelmp.checkpoint import Checkpointing, check_every, load, truncate_outputs

    check_every(every)
    state = load(folder, text, inputs) if resume else None
    if state is not None and rank == 0:
        truncate_outputs(folder, state)
    return Checkpointing(Path(folder), every, state, list(appended), list(inputs))


def _run_with_converter(job: Job, progress: bool, convert, checkpoints=None) -> list[Path]:
    from fibrelmp.post.lammps_dump.reader import iter_frames
    from fibrelmp.runner import run_overlapped

    def consume(tokens) -> list[Path]:
        frames = iter_frames(job.frames)
        return convert(next(frames) for _ in tokens)

    return run_overlapped(job.script, job.total_steps,
                          lambda words: True if words[0] == "write_dump" else None,
                          consume, progress=progress, checkpoints=checkpoints)


@dataclass
class Evaluation:
    forces: "np.ndarray"      # (n,3) total force per particle, model order
    energy: float             # potential energy (pair + bond + angle + walls), LAMMPS thermo pe


def evaluate(model: Model, folder: str | Path) -> Evaluation:
    """Forces and potential energy LAMMPS computes for the model's current state.

    Runs the translated set-up (everything before the first dynamics action) and ``run 0``:
    the forces include drag on the current velocities, gravity and walls, exactly as the
    integrator would see them.
    """
    import numpy as np

    from fibrelmp._lammps import new_lammps
    from fibrelmp.errors import RunError
    from fibrelmp.lammps_text import input_lines
    import os

    job = translate(model, folder)
    lines = input_lines(job.text, job.script)
    stop = next(i for i, ln in enumerate(lines) if ln.startswith(("displace_atoms", "velocity", "write_dump")))
    cwd = os.getcwd()
    lmp = new_lammps(["-nocite", "-log", "none", "-screen", "none"])
    try:
        os.chdir(job.folder)
        for ln in lines[:stop]:
            if ln.strip() and not ln.lstrip().startswith("#"):
                lmp.command(ln)
        lmp.command("thermo_style custom step pe")
        lmp.command("thermo_modify norm no")
        lmp.command("run 0 post no")
        n = model.particles.count
        f = np.array(lmp.numpy.extract_atom("f")[:n], dtype=float)
        ids = np.array(lmp.numpy.extract_atom("id")[:n], dtype=np.int64)
        out = np.empty_like(f)
        out[ids - 1] = f
        return Evaluation(out, float(lmp.get_thermo("pe")))
    except Exception as exc:
        raise RunError(f"LAMMPS error: {exc}") from None
    finally:
        os.chdir(cwd)
        lmp.close()
