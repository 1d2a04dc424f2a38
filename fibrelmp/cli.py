"""Command-line interface: thin adapters; heavy modules are imported inside commands.

Exit codes: 0 success, 2 bad input (InputError), 1 run failure (RunError / LAMMPS).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import typer

from . import __version__

app = typer.Typer(add_completion=True, no_args_is_help=True, rich_markup_mode=None,
                  help="""Run FibreNet, MUSEN and DEMDF inputs on LAMMPS and write the results in
each code's own format; convert LAMMPS dumps into those formats.

\b
Examples:
  fibrelmp check examples/fibre_network/input.txt      # validate, list every error
  fibrelmp run examples/musen/single_particle_job.txt
  fibrelmp translate examples/demdf/head_on.json -o job/
  fibrelmp post frames.dump --to vtk -o run/frames
  fibrelmp --install-completion                        # tab completion for your shell

\b
Exit codes: 0 success, 1 the run failed (LAMMPS error), 2 bad input or
output path (error: path:line: message), 130 interrupted, 128+N stopped by
signal N after writing a checkpoint (resume with run --resume).""")

_state = {"quiet": False, "verbose": False}

# every sub-command takes these too, so "fibrelmp run X --quiet" works as "fibrelmp -q run X"
_QUIET = typer.Option(False, "--quiet", "-q", help="Only warnings and errors.")
_VERBOSE = typer.Option(False, "--verbose", "-v", help="Show every warning and more detail.")


def _set_flags(quiet: bool, verbose: bool) -> None:
    _state["quiet"] = _state["quiet"] or quiet
    _state["verbose"] = _state["verbose"] or verbose


def _rank0() -> bool:
    from .runner import mpi_rank_size

    return mpi_rank_size()[0] == 0


def _say(msg: str) -> None:
    if not _state["quiet"] and _rank0():
        typer.echo(msg, err=True)


def _report_warnings(warnings: list[tuple[str, str]]) -> None:
    if not _rank0():
        return
    groups: dict[str, list[str]] = {}
    for kind, text in warnings:
        groups.setdefault(kind, []).append(text)
    for kind, texts in groups.items():
        count = f" ({len(texts)})" if len(texts) > 1 else ""
        typer.secho(f"warning [{kind}]{count}: {texts[0]}", err=True, fg=typer.colors.YELLOW)
        if _state["verbose"]:
            for t in texts[1:]:
                typer.secho(f"  {t}", err=True, fg=typer.colors.YELLOW)


def _fail(message: str, code: int) -> None:
    """Report and exit; under MPI a failure on any rank aborts all ranks (never a hang)."""
    from ._lammps import mpi_abort
    from .runner import mpi_rank_size

    rank, size = mpi_rank_size()
    # input errors are found identically on every rank (all ranks parse): say them once
    if code != 2 or rank == 0:
        prefix = f"[rank {rank}] " if size > 1 and code != 2 else ""
        typer.secho(prefix + message, err=True, fg=typer.colors.RED)
    if size > 1:
        import time

        sys.stderr.flush()
        # MPI_Abort makes mpiexec kill every rank at once: its stdio proxy may not have
        # forwarded what this rank just wrote.  Give it time (a rank meeting the same input
        # error as rank 0 waits longer, so that rank 0's message is the one shown).
        time.sleep(1.0 if code == 2 and rank != 0 else 0.5)
        mpi_abort(code)
    raise typer.Exit(code)


def _guard(func):
    """Turn fibrelmp's exceptions into messages and exit codes (no traceback)."""
    import functools

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        from .errors import InputError, RunError

        from ._lammps import mpi_finalize, mpi_init
        from .runner import mpi_rank_size

        size = mpi_rank_size()[1]
        if size > 1:
            mpi_init()       # before any rank-specific work: a failure anywhere can abort all
        try:
            result = func(*args, **kwargs)
        except InputError as exc:
            _fail(f"error: {exc}", 2)
        except (RunError, OSError) as exc:
            from .errors import visible

            _fail(f"run failed: {visible(str(exc), keep_newlines=True)}", 1)
        except MemoryError:
            _fail("run failed: out of memory (the input is too large for this machine's memory)", 1)
        except KeyboardInterrupt:
            _fail("interrupted", 130)
        except Exception as exc:
            from .checkpoint import CheckpointStop

            if isinstance(exc, CheckpointStop):
                _fail(str(exc), 128 + exc.signum)
            if size > 1:     # a bug on one rank: show it, then take every rank down
                import traceback

                traceback.print_exc()
                _fail(f"internal error: {exc!r}", 1)
            raise
        if size > 1:
            mpi_finalize()   # rank 0 may still be writing results: nobody leaves before it
        return result
    return wrapper


def _mpi_library_version() -> str:
    """MPI_Get_library_version of the MPI library LAMMPS loaded (callable before MPI_Init)."""
    import ctypes
    import os

    lib = ctypes.CDLL("libmpi.so.12", mode=os.RTLD_NOLOAD | ctypes.RTLD_GLOBAL)
    buf, length = ctypes.create_string_buffer(8192), ctypes.c_int(0)   # MPI_MAX_LIBRARY_VERSION_STRING
    if lib.MPI_Get_library_version(buf, ctypes.byref(length)) != 0:
        raise OSError("MPI_Get_library_version failed")
    major, minor = ctypes.c_int(0), ctypes.c_int(0)
    lib.MPI_Get_version(ctypes.byref(major), ctypes.byref(minor))
    first = buf.value.decode(errors="replace").strip().splitlines()[0]
    return f"{' '.join(first.split())} (MPI standard {major.value}.{minor.value})"


def _version(value: bool) -> None:
    if value:
        typer.echo(f"fibrelmp {__version__}")
        try:
            from ._lammps import load_lammps_module

            lmp = load_lammps_module().lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
            typer.echo(f"LAMMPS {lmp.version()} (MPI support: {bool(lmp.has_mpi_support)})")
            lmp.close()
        except Exception as exc:  # version output must never crash
            typer.echo(f"LAMMPS unavailable: {exc}")
        try:
            typer.echo(f"MPI {_mpi_library_version()}")
        except Exception as exc:  # no MPI library loaded (serial LAMMPS build)
            typer.echo(f"MPI unavailable: {exc}")
        try:
            from .post.fastparse import active_path

            typer.echo(f"post fast path: {active_path()}")
        except Exception as exc:  # version output must never crash
            typer.echo(f"post fast path: unknown ({exc})")
        raise typer.Exit()


@app.callback()
def main_options(
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Only warnings and errors."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Show every warning and more detail."),
    version: Optional[bool] = typer.Option(None, "--version", callback=_version, is_eager=True,
                                           help="Print the fibrelmp, LAMMPS and MPI library versions."),
) -> None:
    _state["quiet"], _state["verbose"] = quiet, verbose


@app.command()
@_guard
def check(input: Path = typer.Argument(..., help="Any supported input file.",
                                       readable=False),    # fibrelmp says why, as path: message
          quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    """Parse and validate INPUT without running LAMMPS; print a summary, the unit system and
    the time step against the fastest spring / contact it has to resolve.

    For FibreNet inputs and models, MUSEN scenes and cmusen scripts every error is listed
    (run stops at the first); for DEMDF files the first.  Exit code 2 on any error.

    \b
    Examples:
      fibrelmp check examples/fibre_network/input.txt
      fibrelmp check examples/musen/single_particle_job.txt
      fibrelmp check examples/demdf/head_on.json --verbose   # every warning
    """
    from .formats import detect

    _set_flags(quiet, verbose)
    kind = detect(input)
    if kind != "fibrenet":
        from .granular_api import model_for_check
        from .granular_check import summary

        model = _read_for_check(lambda: model_for_check(input, kind), kind, input)
        _summary(summary(model) + [f"results      {_granular_results(input, kind, model)}"])
        _report_warnings(model.warnings)
        _summary([f"warnings     {len(model.warnings)}"])
        return
    from .api import read_input
    from .sanity import spring_check, units_line

    model = _read_for_check(lambda: read_input(input), kind, input)
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
    lines += spring_check(model)
    from .api import fibrenet_outputs

    outputs, folder, prefix = fibrenet_outputs(model)
    lines.append(f"results      {', '.join(str(p) for p in outputs.files)} (or in -o DIR)")
    _summary(lines)
    _report_warnings(model.warnings)
    _summary([f"warnings     {len(model.warnings)}"])


def _granular_results(input: Path, kind: str, model) -> str:
    """Where ``run`` would write (without -o), as check reports it."""
    from .granular_api import demdf_outputs, musen_result_path, plan_musen_script, scene_result_path

    if kind == "demdf":
        outputs, folder = demdf_outputs(model)
        return f"{folder / model.passthrough['demdf']['filename']}_<n>.json (or in -o DIR)"
    if kind == "musen-script":
        written = [str(st.written) for st in plan_musen_script(input).steps if st.written is not None]
        return ", ".join(written) or "none (the script exports nothing)"
    return f"{musen_result_path(scene_result_path(input.resolve()))[0]} (or -o FILE)"


def _summary(lines: list[str]) -> None:
    """check's report on stdout (--quiet: warnings and errors only)."""
    if not _state["quiet"]:
        typer.echo("\n".join(lines))


def _read_for_check(read, kind: str, input: Path):
    """``read()``; on an input error in a line-oriented format, every error of the file (the
    readers stop at the first: ``collect_errors`` re-reads with failing lines patched out)."""
    from .errors import InputError
    from .textio import MAX_ERRORS, collect_errors

    try:
        return read()
    except InputError as first:
        if kind == "demdf":
            raise
        if kind == "fibrenet":
            from .translate.fibrenet import check_patch

            patch = check_patch(input)
        else:
            from .translate.musen_script import check_patch as patch
        errors = collect_errors(read, first, patch)
    if len(errors) == 1:
        raise errors[0]
    files = list(dict.fromkeys(e.path for e in errors))          # in the order they were met
    errors.sort(key=lambda e: (files.index(e.path), e.line or 0))
    more = " (the limit: fix these and check again)" if len(errors) >= MAX_ERRORS else ""
    _fail("\n".join(f"error: {e}" for e in errors) + f"\n{len(errors)} errors{more}", 2)


@app.command()
@_guard
def translate(input: Path = typer.Argument(..., help="Any supported input file.", readable=False),
              out: Path = typer.Option(..., "-o", "--out", help="Folder for in.lammps and the data file."),
              quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    """Write a stock-LAMMPS job (in.lammps + data file) for INPUT into a folder.

    \b
    Examples:
      fibrelmp translate input.txt -o job/ && cd job && lmp -in in.lammps
      fibrelmp translate examples/musen/single_particle_job.txt -o job/
      fibrelmp translate examples/demdf/head_on.json -o job/
    """
    from .python_api import write_job

    _set_flags(quiet, verbose)
    job = write_job(input, out, warn=_report_warnings)
    _say(f"wrote {job.script} and {job.data}")


@app.command()
@_guard
def run(input: Path = typer.Argument(..., help="FibreNet input, MUSEN text scene, cmusen job script "
                                     "or DEMDF JSON file.", readable=False),
        out: Optional[Path] = typer.Option(None, "--out", "-o", help="Where results go: a folder "
                                           "(FibreNet, DEMDF) or the result file (MUSEN scene). "
                                           "Default: next to the input."),
        work: Optional[Path] = typer.Option(None, "--work", help="Folder for the rendered LAMMPS job."),
        end_time: Optional[float] = typer.Option(None, "--end-time", "--time-end",
                                                 help="MUSEN scene / DEMDF: simulated end time."),
        step: Optional[float] = typer.Option(None, "--step", help="MUSEN scene: simulation time step."),
        save_step: Optional[float] = typer.Option(None, "--save-step", "--save-every",
                                                  help="MUSEN scene / DEMDF: time between saved states."),
        steps: Optional[int] = typer.Option(None, "--steps", help="DEMDF: number of time steps to run."),
        precision: int = typer.Option(6, "--precision", help="MUSEN result: significant digits "
                                      "(6 as MUSEN; 17 for exact round trips)."),
        checkpoint_every: Optional[int] = typer.Option(None, "--checkpoint-every", help="Write a "
                                                       "checkpoint every N steps (one is always "
                                                       "written on SIGTERM/Ctrl-C)."),
        resume: bool = typer.Option(False, "--resume", help="Continue an interrupted run from the "
                                    "checkpoint in its work folder."),
        force: bool = typer.Option(False, "--force", help="Replace the results of an earlier run "
                                   "(all of them: stale files are removed)."),
        quiet: bool = _QUIET, verbose: bool = _VERBOSE,
        ) -> None:
    """Translate INPUT, run it on LAMMPS and write the results in the input's own format.

    \b
    Examples:
      fibrelmp run examples/fibre_network/input.txt
      fibrelmp run examples/musen/single_particle_job.txt
      fibrelmp run scene.txt --end-time 0.1 --step 1e-6 --save-step 1e-3 -o result.txt
      fibrelmp run examples/demdf/head_on.json --time-end 2

    Results are never overwritten silently: an existing result needs --force.  The output
    and work folders are locked while the run writes them.
    """
    import time

    from .python_api import run as run_any

    _set_flags(quiet, verbose)
    start = time.monotonic()
    result = run_any(input, out, work=work, force=force, checkpoint_every=checkpoint_every,
                     resume=resume, end_time=end_time, step=step, save_step=save_step, steps=steps,
                     precision=precision, progress=not _state["quiet"], say=_say,
                     warn=_report_warnings)
    for note in result.notes:
        _say(note)
    for path in result.outputs:
        _say(f"wrote {path}")
    script = result.scripts[-1] if result.scripts else None
    _say(f"done in {time.monotonic() - start:.1f} s (LAMMPS job: {script})")


@app.command("post")
@_guard
def post(dump: Path = typer.Argument(..., help="LAMMPS text dump (.gz too), or any MDAnalysis trajectory.",
                                     readable=False),
         to: Optional[str] = typer.Option(None, "--to", help="xyz, res, mercury, vtk, musen or demdf."),
         out: Optional[Path] = typer.Option(None, "-o", "--out", help="Output base name (folder/name)."),
         info: bool = typer.Option(False, "--info", help="Describe the dump (frames, atoms, columns, box)."),
         frames: Optional[str] = typer.Option(None, "--frames", help="Frames to convert: i, start:stop:step, "
                                              "or a comma list (default all; res: the last)."),
         types: Optional[list[str]] = typer.Option(None, "--types", help="Only these atom types (numbers "
                                                   "or names; repeat or comma-separate)."),
         data: Optional[Path] = typer.Option(None, "--data", help="LAMMPS data file: type names, radii, "
                                             "masses, bonds the dump lacks."),
         local: Optional[Path] = typer.Option(None, "--local", help="dump local file with per-contact data "
                                              "(mercury .fstat and elastic energy)."),
         gravity: Optional[tuple[float, float, float]] = typer.Option(None, "--gravity", help="gx gy gz for "
                                                                      "the gravitational energy."),
         force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
         topology: Optional[Path] = typer.Option(None, "--topology", help="Topology for MDAnalysis "
                                                 "trajectory formats."),
         quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    """Convert an existing dump into FibreNet, MercuryDPM, ParaView, MUSEN or DEMDF files.

    Outputs are written only when the whole conversion succeeded; existing ones are kept
    unless --force is given.

    \b
    Examples:
      fibrelmp post dump.lammpstrj --info
      fibrelmp post dump.lammpstrj --to vtk -o run --data data.lammps
      fibrelmp post frames.dump.gz --to xyz -o out/fibres --frames 0:100:10 --types F1
      fibrelmp post atoms.dump --to mercury -o run --local contacts.dump --gravity 0 0 -9.81
      fibrelmp post traj.dcd --topology top.pdb --to res -o final
    """
    from .post.cli_post import post_command

    _set_flags(quiet, verbose)
    written = post_command(dump, to, out, info, frames, types, data, local, gravity, force, topology,
                           typer.echo if info else _say, report=_report_warnings)
    for path in written:
        _say(f"wrote {path}")


def main() -> None:
    app()


if __name__ == "__main__":
    main()
