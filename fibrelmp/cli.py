"""Command-line interface: thin adapters; heavy modules are imported inside commands.

Exit codes: 0 success, 2 bad input (InputError), 1 run failure (RunError / LAMMPS).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import typer

from fibrelmp import __version__

from fibrelmp.registry import ALSO, DOCUMENT, FRAMES, INPUT, RESULT, TARGET, formats, names

_INPUTS = formats(INPUT)
_TITLES = ", ".join(f.title for f in _INPUTS[:-1]) + " or " + _INPUTS[-1].title


def _examples(command: str, tail: str = "", role: str = INPUT) -> str:
    """Example command lines for a help text, one per registered format that has one."""
    return "\n".join(f"  fibrelmp {command} {f.example}{tail}" for f in formats(role) if f.example)


class _Command(typer.core.TyperCommand):
    """Help in the usual form: ``Usage: fibrelmp post [OPTIONS] DUMP``, ``DUMP  help`` and
    ``--to NAME`` (typer writes ``{dump}``, ``dump <path>`` and ``--to <str>``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        for param in self.params:
            if param.param_type_name == "argument":
                name = param.metavar = (param.metavar or param.name).upper()
                param.display_type_rich = lambda ctx: None
                param._usage_display_name = lambda n=name, required=param.required: (
                    n if required else f"[{n}]")
            elif not getattr(param, "is_flag", False) and param.metavar is None:
                param.metavar = param.name.upper()

    def parse_args(self, ctx, args: list[str]) -> list[str]:
        return super().parse_args(ctx, _also_aliases(self, args))


def _also_aliases(command: typer.core.TyperCommand, args: list[str]) -> list[str]:
    """A bare ``--NAME`` of a format ``run --also`` takes is ``--also NAME``, with a note on
    stderr: the form of the one such flag before ``--also`` existed, kept for users' scripts."""
    options = {opt for param in command.params for opt in param.opts}
    if "--also" not in options:
        return args
    out: list[str] = []
    for k, arg in enumerate(args):
        if arg == "--":                        # what follows is no option
            return out + args[k:]
        name = arg[2:] if arg.startswith("--") and arg not in options else None
        if name in names(ALSO):
            if _rank0():
                typer.echo(f"note: --{name} is deprecated, use --also {name}", err=True)
            out += ["--also", name]
        else:
            out.append(arg)
    return out


app = typer.Typer(add_completion=True, no_args_is_help=True, rich_markup_mode=None,
                  help=f"""Run simulation inputs ({_TITLES}) on LAMMPS and write the results in
each code's own format; convert LAMMPS dumps into those formats ({", ".join(names(TARGET))}).

\b
Examples:
{_examples("check")}
  fibrelmp post frames.dump --to {names(TARGET)[-1]} -o run/frames
  fibrelmp --install-completion          # tab completion for your shell

\b
Exit codes: 0 success, 1 the run failed (LAMMPS error), 2 bad input or
output path (error: path:line: message), 130 interrupted, 128+N stopped by
signal N after writing a checkpoint (resume with run --resume).""")

_state = {"quiet": False, "verbose": False}

# every sub-command takes these too, so "fibrelmp run X --quiet" works as "fibrelmp -q run X"
_QUIET = typer.Option(False, "--quiet", "-q", help="Only warnings and errors.")
_VERBOSE = typer.Option(False, "--verbose", "-v", help="Show every warning and more detail.")
_STOCK = typer.Option(False, "--stock-styles", help="Stock LAMMPS styles only (a LAMMPS without the "
                      "PLUGIN package); approximations this brings are printed as warnings.")


def _set_flags(quiet: bool, verbose: bool) -> None:
    _state["quiet"] = _state["quiet"] or quiet
    _state["verbose"] = _state["verbose"] or verbose


def _rank0() -> bool:
    from fibrelmp.runner import mpi_rank_size

    return mpi_rank_size()[0] == 0


def _say(msg: str) -> None:
    """Progress and notes: stderr (as Unix tools do; stdout carries the results)."""
    if not _state["quiet"] and _rank0():
        typer.echo(msg, err=True)


def _result(msg: str) -> None:
    """What a command produced (wrote lines, the run summary, check's report): stdout, so
    ``fibrelmp run ... > log`` keeps it; --quiet leaves only warnings and errors."""
    if not _state["quiet"] and _rank0():
        typer.echo(msg)


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
    from fibrelmp._lammps import mpi_abort
    from fibrelmp.runner import mpi_rank_size

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
        from fibrelmp.errors import InputError, RunError

        from fibrelmp._lammps import mpi_finalize, mpi_init
        from fibrelmp.runner import mpi_rank_size

        size = mpi_rank_size()[1]
        if size > 1:
            mpi_init()       # before any rank-specific work: a failure anywhere can abort all
        try:
            result = func(*args, **kwargs)
        except InputError as exc:
            _fail(f"error: {exc}", 2)
        except (RunError, OSError) as exc:
            from fibrelmp.errors import visible

            _fail(f"run failed: {visible(str(exc), keep_newlines=True)}", 1)
        except MemoryError:
            _fail("run failed: out of memory (the input is too large for this machine's memory)", 1)
        except KeyboardInterrupt:
            _fail("interrupted", 130)
        except Exception as exc:
            from fibrelmp.checkpoint import CheckpointStop

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
            from fibrelmp._lammps import load_lammps_module

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
            from fibrelmp.lammps_styles import plugin

            typer.echo(f"LAMMPS styles: {plugin().describe()}")
        except Exception as exc:  # version output must never crash
            typer.echo(f"LAMMPS styles: unknown ({exc})")
        try:
            from fibrelmp.numtext.fast import active_path

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


@app.command(cls=_Command, help=f"""Parse and validate INPUT without running LAMMPS; print a summary, the unit
system and the time step against the fastest spring / contact it has to resolve.

Every error of a line-oriented input is listed (run stops at the first); exit code 2 on
any error.

\b
Examples:
{_examples("check")}
""")
@_guard
def check(input: Path = typer.Argument(..., help="Any supported input file.",
                                       readable=False),    # fibrelmp says why, as path: message
          stock_styles: bool = _STOCK, quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    from fibrelmp.python_api import check as check_input

    _set_flags(quiet, verbose)
    report = check_input(input, stock_styles=stock_styles)
    _summary(report.lines)
    _report_warnings(report.warnings)
    _summary([f"warnings     {len(report.warnings)}"])


def _summary(lines: list[str]) -> None:
    """check's report on stdout (--quiet: warnings and errors only)."""
    if not _state["quiet"]:
        typer.echo("\n".join(lines))


@app.command(cls=_Command, help=f"""Write a LAMMPS job (in.lammps + data file) for INPUT into a folder
(replay: cd job && lmp -in in.lammps; it loads fibrelmp's styles plugin unless --stock-styles).

\b
Examples:
{_examples("translate", " -o job/")}
""")
@_guard
def translate(input: Path = typer.Argument(..., help="Any supported input file.", readable=False),
              out: Path = typer.Option(..., "-o", "--out", metavar="DIR", help="Folder for in.lammps and the data file."),
              stock_styles: bool = _STOCK, quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    from fibrelmp.python_api import write_job

    _set_flags(quiet, verbose)
    job = write_job(input, out, warn=_report_warnings, stock_styles=stock_styles)
    _result(f"wrote {job.script} and {job.data}")


@app.command(cls=_Command, help=f"""Translate INPUT, run it on LAMMPS and write the results in the input's own
format.

Results are never overwritten silently: an existing result needs --force.  The output and
work folders are locked while the run writes them.

\b
Examples:
{_examples("run")}
""")
@_guard
def run(input: Path = typer.Argument(..., help=f"{_TITLES[0].upper()}{_TITLES[1:]}.", readable=False),
        out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="PATH", help="Where results go: a folder, or "
                                           "the result file for inputs with a single result. "
                                           "Default: next to the input."),
        work: Optional[Path] = typer.Option(None, "--work", metavar="DIR", help="Folder for the rendered LAMMPS job."),
        end_time: Optional[float] = typer.Option(None, "--end-time", "--time-end", metavar="T",
                                                 help="Simulated end time (overrides the input's)."),
        step: Optional[float] = typer.Option(None, "--step", metavar="DT", help="Simulation time step, for inputs "
                                             "that do not set one."),
        save_step: Optional[float] = typer.Option(None, "--save-step", "--save-every", metavar="T",
                                                  help="Time between saved states (overrides the input's)."),
        steps: Optional[int] = typer.Option(None, "--steps", metavar="N", help="Number of time steps to run, "
                                            "for inputs that count steps."),
        precision: Optional[int] = typer.Option(None, "--precision", metavar="DIGITS",
                                                help="Significant digits of text results that take "
                                                "it (default 6, as the source code; 17 for exact "
                                                "round trips); an error for the others."),
        checkpoint_every: Optional[int] = typer.Option(None, "--checkpoint-every", metavar="N", help="Write a "
                                                       "checkpoint every N steps (one is always "
                                                       "written on SIGTERM/Ctrl-C)."),
        resume: bool = typer.Option(False, "--resume", help="Continue an interrupted run from the "
                                    "checkpoint in its work folder."),
        force: bool = typer.Option(False, "--force", help="Replace the results of an earlier run "
                                   "(all of them: stale files are removed)."),
        also: Optional[list[str]] = typer.Option(
            None, "--also", metavar="NAME", autocompletion=lambda: names(ALSO),
            help="Also write every saved frame next to the results as NAME, one of: " + "; ".join(
                f"{f.name}: {f.title}" for f in formats(ALSO)) + ". Repeat or comma-separate."),
        log_every: Optional[str] = typer.Option(None, "--log-every", metavar="WHEN", help="Without a "
                                                "terminal (batch jobs): a progress line on stderr every "
                                                "10% of the steps, 60s/5m/1h, or both (default 10%,5m)."),
        yes_i_mean_it: bool = typer.Option(False, "--yes-i-mean-it", help="Run even when the "
                                           "estimated output exceeds the free disk space or the "
                                           "run would take more than 30 days at any speed."),
        stock_styles: bool = _STOCK, quiet: bool = _QUIET, verbose: bool = _VERBOSE,
        ) -> None:
    import time

    from fibrelmp.python_api import run as run_any

    _set_flags(quiet, verbose)
    start = time.monotonic()
    result = run_any(input, out, work=work, force=force, checkpoint_every=checkpoint_every,
                     resume=resume, end_time=end_time, step=step, save_step=save_step, steps=steps,
                     precision=precision, progress=not _state["quiet"], stock_styles=stock_styles,
                     also=also or (), say=_say,
                     warn=_report_warnings, log_every=log_every, allow_huge=yes_i_mean_it)
    for note in result.notes:
        _say(note)
    for line in _written(result.outputs):
        _result(line)
    from fibrelmp.record import summary_lines

    for summary in result.summaries:
        _result("\n".join(summary_lines(summary)))
    if _state["verbose"] and result.warnings:
        # the summaries count warnings by kind: -v lists every one of them
        _result("every warning:")
        for kind, text in result.warnings:
            _result(f"  [{kind}] {text}")
    script = result.scripts[-1] if result.scripts else None
    _result(f"done in {time.monotonic() - start:.1f} s (LAMMPS job: {script})")


@app.command("post", cls=_Command, help=f"""Convert an existing dump into another code's files ({", ".join(
    f"{f.name}: {f.title}" for f in formats(TARGET))}).

Outputs are written only when the whole conversion succeeded; existing ones are kept unless
--force is given.

\b
Examples:
  fibrelmp post dump.lammpstrj --info
""" + "\n".join(f"  fibrelmp post dump.lammpstrj --to {name} -o out/run" for name in names(TARGET)) + """
  fibrelmp post frames.dump.gz --to NAME -o out/run --frames 0:100:10 --types 1
  fibrelmp post traj.dcd --topology top.pdb --to NAME -o final
""")
@_guard
def post(dump: Path = typer.Argument(..., help=" or ".join(f.title for f in formats(FRAMES)) + ".",
                                     readable=False),
         to: Optional[str] = typer.Option(None, "--to", metavar="NAME", help=f"One of: {', '.join(names(TARGET))}.",
                                          autocompletion=lambda: names(TARGET)),
         out: Optional[Path] = typer.Option(None, "-o", "--out", metavar="PATH", help="Output base name (folder/name)."),
         info: bool = typer.Option(False, "--info", help="Describe the dump (frames, atoms, columns, box)."),
         frames: Optional[str] = typer.Option(None, "--frames", metavar="SPEC", help="Frames to convert: i, start:stop:step, "
                                              "or a comma list (default all; single-frame targets: the last)."),
         types: Optional[list[str]] = typer.Option(None, "--types", metavar="TYPES", help="Only these atom types (numbers "
                                                   "or names; repeat or comma-separate)."),
         data: Optional[Path] = typer.Option(None, "--data", metavar="FILE", help="LAMMPS data file: type names, radii, "
                                             "masses, bonds the dump lacks."),
         local: Optional[Path] = typer.Option(None, "--local", metavar="FILE", help="dump local file with per-contact data "
                                              "(for targets that write contacts)."),
         gravity: Optional[tuple[float, float, float]] = typer.Option(None, "--gravity", metavar="GX GY GZ", help="gx gy gz for "
                                                                      "the gravitational energy."),
         force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
         topology: Optional[Path] = typer.Option(None, "--topology", metavar="FILE", help="Topology file, for "
                                                 "trajectory formats that need one."),
         precision: Optional[int] = typer.Option(None, "--precision", metavar="DIGITS", help="Significant "
                                                 "digits, for targets that write text with a chosen "
                                                 "number of them (default 6); an error for the others."),
         quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    from fibrelmp.python_api import convert, describe

    _set_flags(quiet, verbose)
    if info:
        describe(dump, topology, say=typer.echo, warn=_report_warnings)
        return
    written = convert(dump, to, out, frames=frames, types=types, data=data, local=local,
                      gravity=gravity, force=force, topology=topology, say=_say,
                      warn=_report_warnings, precision=precision)
    for line in _written(written):
        _result(line)


def _written(paths: list[Path]) -> list[str]:
    """``wrote PATH`` lines; a numbered series (``<name>_<n><tail>``: snapshots, viewer
    frames) as one line per name and tail with its first and last file and their count, so
    a run with many frames does not list every file."""
    import re

    series: dict[tuple[Path, str, str], list[tuple[int, Path]]] = {}
    for path in paths:
        m = re.fullmatch(r"(.*_)(\d+)(\D.*)?", path.name)
        key = (path.parent, m[1], m[3] or "") if m else (path, "", "")
        series.setdefault(key, []).append((int(m[2]) if m else 0, path))
    lines = []
    for group in series.values():
        if len(group) == 1:
            lines.append(f"wrote {group[0][1]}")
            continue
        group.sort()
        first, last = group[0][1], group[-1][1]
        lines.append(f"wrote {first} .. {last.name} ({len(group)} files)")
    return lines


def _convert_examples() -> str:
    """``fibrelmp convert A -o B`` for each pair of document formats with examples."""
    docs = [f for f in formats(DOCUMENT) if f.example]
    lines = []
    for a in docs:
        for b in docs:
            if a is not b:
                suffix = b.extensions[0] if b.extensions else Path(b.example).suffix
                lines.append(f"  fibrelmp convert {a.example} -o {Path(a.example).stem}{suffix}")
    return "\n".join(lines)


@app.command("convert", cls=_Command, help=f"""Convert a scene or result file into another form of the same code
({"; ".join(f"{f.name}: {f.title}" for f in formats(DOCUMENT))}), e.g. a binary scene into text
to diff or version-control it, and back.

The output format comes from --to or the output's name; the file is written only when the
whole conversion succeeded; an existing one is kept unless --force is given.

\b
Examples:
{_convert_examples()}
""")
@_guard
def convert_command(source: Path = typer.Argument(..., help="The file to convert.", readable=False),
                    out: Path = typer.Option(..., "-o", "--out", metavar="FILE", help="The file to write."),
                    to: Optional[str] = typer.Option(None, "--to", metavar="NAME", help=f"One of: {', '.join(names(DOCUMENT))} "
                                                     "(default: from the output's name).",
                                                     autocompletion=lambda: names(DOCUMENT)),
                    precision: Optional[int] = typer.Option(None, "--precision", metavar="DIGITS", help="Significant digits of "
                                                            "time-point values in text (default 6, as the code writes; "
                                                            "17 keeps every double)."),
                    force: bool = typer.Option(False, "--force", help="Overwrite an existing output."),
                    quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    from fibrelmp.python_api import convert_file

    _set_flags(quiet, verbose)
    for path in convert_file(source, out, to=to, precision=precision, force=force):
        _result(f"wrote {path}")


_RESULT_HELP = ("A run's work folder, its log.lammps, or a result file ("
                + ", ".join(f.title for f in formats(RESULT) + formats(FRAMES)[:1]) + ").")


def _result_examples(command: str, tail: str) -> str:
    """``fibrelmp COMMAND out/result.EXT`` for each result format with an extension."""
    return "\n".join(f"  fibrelmp {command} out/result{f.extensions[0]}{tail}"
                     for f in formats(RESULT) if f.extensions)


_SIZE = typer.Option(None, "--size", metavar="WxH", help="Picture size in pixels (default 800x600).")
_PNG_FORCE = typer.Option(False, "--force", help="Overwrite an existing picture.")


@app.command("plot", cls=_Command, help="""Draw the energy and thermo history of a run into a PNG: LAMMPS's thermo
from the run's log.lammps (energies; for granular runs contacts, broken bonds, particles),
else what the result files hold (kinetic energy from masses and velocities, particles,
bonds whose activity ended).  The first line of the output says which source was used.
Needs matplotlib (pip install 'fibrelmp[plot]').

\b
Examples:
  fibrelmp plot out/run_work
  fibrelmp plot out/run_work/log.lammps -o energy.png
""" + _result_examples("plot", " --source result") + """
""")
@_guard
def plot_command(result: Path = typer.Argument(..., help=_RESULT_HELP, readable=False),
                 out: Optional[Path] = typer.Option(None, "-o", "--out", metavar="FILE.png",
                                                    help="The picture (default: RESULT_plot.png "
                                                    "beside it; plot.png in a work folder)."),
                 source: str = typer.Option("auto", "--source", metavar="auto|log|result",
                                            help="Where the numbers come from: LAMMPS's log, the "
                                            "result's frames, or the log when found (auto).",
                                            autocompletion=lambda: ["auto", "log", "result"]),
                 size: Optional[str] = _SIZE, force: bool = _PNG_FORCE,
                 quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    from fibrelmp.python_api import plot

    _set_flags(quiet, verbose)
    drawn = plot(result, out, source=source, size=size, force=force)
    _result(f"plotted {', '.join(drawn.lines)} over {drawn.x_name}, from {drawn.source}")
    for note in drawn.notes:
        _result(f"  {note}")
    _result(f"wrote {drawn.path}")


@app.command("snapshot", cls=_Command, help="""Draw one frame of a result into a PNG: spheres at their radii,
bonds and fibres as lines, walls as translucent faces, the box when there is one.  Needs
matplotlib (pip install 'fibrelmp[plot]').

\b
Examples:
""" + _result_examples("snapshot", " --frame 0 -o start.png") + """
  fibrelmp snapshot out/run_work --frame -2 --size 400x300
""")
@_guard
def snapshot_command(result: Path = typer.Argument(..., help=_RESULT_HELP, readable=False),
                     out: Optional[Path] = typer.Option(None, "-o", "--out", metavar="FILE.png",
                                                        help="The picture (default: "
                                                        "RESULT_snapshot.png beside it)."),
                     frame: Optional[int] = typer.Option(None, "--frame", metavar="N",
                                                         help="Frame index, negative from the end "
                                                         "(default: the last; for a one-file "
                                                         "snapshot, that file's frame)."),
                     size: Optional[str] = _SIZE, force: bool = _PNG_FORCE,
                     quiet: bool = _QUIET, verbose: bool = _VERBOSE) -> None:
    from fibrelmp.python_api import snapshot

    _set_flags(quiet, verbose)
    drawn = snapshot(result, out, frame=frame, size=size, force=force)
    _result(f"frame {drawn.frame} of {drawn.frames}: {drawn.points} particles, {drawn.bonds} bond "
            f"lines, {drawn.walls} wall faces")
    for note in drawn.notes:
        _result(f"  {note}")
    _result(f"wrote {drawn.path}")


def main() -> None:
    app()


if __name__ == "__main__":
    main()
