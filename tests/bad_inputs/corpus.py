"""The bad-input corpus: every case, how to run it through the CLI, and its normalised result.

Each case is a file in this folder (a FibreNet case is an input file naming its model file),
run as ``fibrelmp check FILE`` unless its ``command`` says otherwise; dumps go through
``fibrelmp post FILE --to xyz -o <tmp>/out``.  Cases that cannot live in git (a directory,
an unreadable file, an unwritable output path) are made by ``make`` in a temporary folder.

A *rejected* case must exit with code 2, print exactly one ``error: path[:line]: message``
line and no traceback, and write nothing.  An *accepted* case is an input some tool writes
that fibrelmp reads on purpose (CRLF, a UTF-8 BOM, tabs, ...): it must check cleanly.

``docs/errors.md`` lists every case with its message; ``make_table.py`` regenerates that
table and ``tests/test_bad_inputs_corpus.py`` checks the two agree.
"""

from __future__ import annotations

import dataclasses

import os
import re
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

CORPUS = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Case:
    name: str
    fmt: str                     # the format the case is about (a docs/errors.md column)
    path: str                    # input, relative to CORPUS ("" for generated cases)
    what: str                    # what is wrong (or unusual), in words
    accept: bool = False         # True: a valid input fibrelmp reads on purpose
    command: str = "check"       # check | post | run
    make: Callable[[Path], list[str]] | None = None   # generated: build in tmp, give CLI args
    needs_unreadable: bool = False                    # cannot be made as root

    def args(self, tmp: Path) -> list[str]:
        if self.make is not None:
            return self.make(tmp)
        if self.command == "post":
            return ["post", self.path, "--to", "xyz", "-o", str(tmp / "out")]
        return [self.command, self.path]


# a UTF-8 BOM is fine (read_text drops it), but format detection matches the first line
# before it is dropped; fixing it belongs to fibrelmp/registry.py
def _c(fmt: str, folder: str, rows: list[tuple], ext: str = ".txt") -> list[Case]:
    out = []
    for row in rows:
        name, what = row[0], row[1]
        accept = len(row) > 2 and row[2] == "accept"
        out.append(Case(f"{folder}/{name}", fmt, f"{folder}/{name}{ext}", what, accept,
                        "post" if folder == "dump" else "check"))
    return out


def _command(cases: list[Case], name: str, command: str) -> list[Case]:
    """``cases`` with case ``name`` run by ``command``: ``check`` lists every error, and some
    inputs have two that share one cause (a bond between coincident spheres: the spheres are
    at one position too), while ``run`` stops at the first."""
    return [dataclasses.replace(case, command=command) if case.name == name else case for case in cases]


FIBRENET = _c("FibreNet input", "fibrenet", [
    ("good", "a valid input (reference)", "accept"),
    ("unknown_keyword", "misspelt keyword 'dampnig'"),
    ("token_count", "box_size with 2 values instead of 3"),
    ("not_a_number", "step 'fast'"),
    ("nan_step", "step nan"),
    ("inf_damping", "damping inf"),
    ("negative_step", "negative time step"),
    ("huge_number", "lambda 1e400 (beyond double range)"),
    ("huge_integer", "run 99999999999999999999 (beyond 64 bits)"),
    ("run_chunk", "output_freq beyond one LAMMPS run command (2^31 - 1 steps)"),
    ("undefined_pair_type", "pair line names an undefined type"),
    ("missing_pair", "no pair line for the type pair A B"),
    ("duplicate_type", "type A defined twice"),
    ("missing_model", "model_file names a file that does not exist"),
    ("missing_keyword", "required keyword lambda missing"),
    ("box_type", "box_type neither pbc nor finite"),
    ("output_freq", "output_freq larger than run"),
    ("modif_bead_id", "modif_bead id out of range"),
    ("minimize_zero", "minimize_substeps 0 with minimize_steps > 0"),
    ("utf16", "input saved as UTF-16"),
    ("crlf", "Windows line ends (CRLF)", "accept"),
    ("bom", "UTF-8 byte-order mark (first line a comment)", "accept"),
    ("bom_first_line", "UTF-8 byte-order mark before the model_file line", "accept"),
    ("tabs", "tabs and spaces mixed between values", "accept"),
])
FIBRENET_MODEL = _c("FibreNet model", "fibrenet_model", [
    ("bead_outside_box", "bead position outside the finite box"),
    ("negative_radius", "negative bead radius"),
    ("negative_mass", "negative bead mass"),
    ("nan_position", "bead position nan"),
    ("bead_token_count", "BEAD line with 17 values instead of 18"),
    ("undefined_bead_type", "bead of an undefined type"),
    ("spring_out_of_range", "spring to bead 7 of 3"),
    ("negative_index", "spring to bead -1"),
    ("self_spring", "spring from a bead to itself"),
    ("zero_length_spring", "spring between two beads at the same position"),
    ("angle_twice", "angle using one bead twice"),
    ("empty", "empty model file"),
    ("binary", "binary model file"),
    ("latin1", "model file in Latin-1 with a non-ASCII type name"),
    ("huge_tag", "bead tag 1e300"),
    ("cyclic_springs", "springs forming a closed loop 0-1-2-0", "accept"),
    ("duplicate_spring", "two springs between the same beads (FibreNet adds them)", "accept"),
    ("crlf", "Windows line ends (CRLF)", "accept"),
])
MUSEN = _command(_c("MUSEN scene", "musen", [
    ("good", "a valid scene (reference)", "accept"),
    ("unknown_tag", "unknown scene tag 99"),
    ("bad_time_point_tag", "unknown per-time-point tag 19"),
    ("duplicate_id", "object id used twice"),
    ("undefined_material", "sphere with an undefined material key"),
    ("bond_missing_particle", "bond to particle 7, which does not exist"),
    ("bond_to_wall", "bond to a wall"),
    ("self_bond", "bond from a sphere to itself"),
    ("negative_radius", "negative sphere radius"),
    ("nan_coordinate", "coordinate nan"),
    ("huge_value", "radius 1e400 (beyond double range)"),
    ("huge_id", "object id 99999999999999999999"),
    ("truncated_line", "time point cut short"),
    ("poisson", "Poisson ratio 0.7"),
    ("negative_density", "negative density"),
    ("zero_length_bond", "solid bond with initial length 0"),
    ("coincident_bond", "solid bond between two spheres at one position"),
    ("coincident_spheres", "two unbonded spheres at one position"),
    ("activity", "activity interval starting after its end"),
    ("domain", "simulation domain with min > max"),
    ("wall_list", "geometry wall list naming a sphere"),
    ("motion_type", "unknown geometry motion type"),
    ("comment", "a '#' comment line (MUSEN has none)"),
    ("utf16", "scene saved as UTF-16"),
    ("crlf", "Windows line ends (CRLF)", "accept"),
    ("tabs", "tabs between values", "accept"),
    ("bom", "UTF-8 byte-order mark", "accept"),
]), "musen/coincident_bond", "run")
MUSEN_SCRIPT = _c("cmusen script", "musen_script", [
    ("good", "a valid job script (reference)", "accept"),
    ("unknown_keyword", "misspelt keyword SIMULATION_STEPP"),
    ("negative_step", "negative simulation step"),
    ("not_a_number", "END_TIME 'abc'"),
    ("nan_step", "SIMULATION_STEP nan"),
    ("huge_end_time", "END_TIME 1e400"),
    ("component", "unsupported component"),
    ("model_typo", "misspelt model name"),
    ("irregular_saves", "saving step not a multiple of the step, 833,334 saves (every 4 steps, as cmusen)", "accept"),
    ("missing_scene", "SOURCE_FILE that does not exist"),
    ("bad_scene", "SOURCE_FILE scene with a bad material"),
    ("step_longer_than_run", "simulation step longer than the run"),
    ("unknown_material", "MATERIAL_PROPERTY for an undefined material"),
    ("token_count", "EXT_ACCEL with 2 values"),
    ("crlf", "Windows line ends (CRLF)", "accept"),
])
DEMDF = _c("DEMDF", "demdf", [
    ("good", "a valid document (reference)", "accept"),
    ("syntax", "JSON syntax error"),
    ("nan", "NaN literal"),
    ("huge", "1e999 (beyond double range)"),
    ("duplicate_key", "key repeated in one object"),
    ("row_length", "particle with 6 entries instead of 7"),
    ("undefined_type", "particle of objectType 5 (one is defined)"),
    ("negative_radius", "negative radius"),
    ("negative_mass", "negative mass"),
    ("outside_domain", "particle outside the domain"),
    ("behind_wall", "particle behind a wall"),
    ("negative_time_step", "negative timeStep"),
    ("string_number", "a number given as a string"),
    ("restitution", "restitution coefficient 1.5"),
    ("dimensionality", "dimensionality 4"),
    ("misspelt_key", "key 'bodyforce' instead of 'bodyForce'"),
    ("missing_particles_file", "particles file that does not exist"),
    ("empty", "empty file"),
    ("utf16", "document saved as UTF-16"),
    ("bom", "UTF-8 byte-order mark", "accept"),
    ("crlf", "Windows line ends (CRLF)", "accept"),
    ("tabs", "tab indentation", "accept"),
], ext=".json")
DUMP = _c("LAMMPS dump", "dump", [
    ("good", "a valid dump (reference)", "accept"),
    ("not_a_dump", "a LAMMPS log, not a dump"),
    ("token_count", "atom line with 4 values for 5 columns"),
    ("not_a_number", "atom value 'abc'"),
    ("nan_position", "atom position nan (a blown-up run)"),
    ("negative_count", "NUMBER OF ATOMS -3"),
    ("bad_timestep", "TIMESTEP 1.5"),
    ("bad_box", "BOX BOUNDS value 'five'"),
    ("binary", "binary file"),
    ("empty", "empty file"),
    ("duplicate_ids", "atom id 1 twice in a frame"),
    ("more_atoms", "more atom lines than NUMBER OF ATOMS"),
    ("repeated_column", "column x named twice"),
    ("utf16", "dump saved as UTF-16"),
    ("crlf", "Windows line ends (CRLF)", "accept"),
    ("tabs", "tabs between values", "accept"),
], ext=".dump")
GENERIC = [
    Case("generic/empty", "any", "generic/empty.txt", "empty file: no format can be recognised"),
    Case("generic/binary", "any", "generic/binary.txt", "binary file"),
    Case("generic/missing", "any", "generic/missing.txt", "file that does not exist"),
]


# ------------------------------------------------------------------ generated at test time
def _directory(tmp: Path) -> list[str]:
    (tmp / "folder.txt").mkdir()
    return ["check", str(tmp / "folder.txt")]


def _model_directory(tmp: Path) -> list[str]:
    (tmp / "model.txt").mkdir()
    (tmp / "input.txt").write_bytes((CORPUS / "fibrenet" / "good.txt").read_bytes())
    return ["check", str(tmp / "input.txt")]


def _unreadable(tmp: Path) -> list[str]:
    path = tmp / "input.txt"
    path.write_bytes((CORPUS / "fibrenet" / "good.txt").read_bytes())
    path.chmod(0)
    return ["check", str(path)]


def _post_unwritable(tmp: Path) -> list[str]:
    (tmp / "file").write_text("a file, not a folder\n")
    return ["post", str(CORPUS / "dump" / "good.dump"), "--to", "xyz", "-o",
            str(tmp / "file" / "sub" / "out")]


def _post_existing(tmp: Path) -> list[str]:
    (tmp / "out_coord.xyz").write_text("an earlier result\n")
    return ["post", str(CORPUS / "dump" / "good.dump"), "--to", "xyz", "-o", str(tmp / "out")]


def _post_new_folder(tmp: Path) -> list[str]:
    return ["post", str(CORPUS / "dump" / "not_a_number.dump"), "--to", "vtk", "-o",
            str(tmp / "new" / "sub" / "out")]


def _dump_long_line(tmp: Path) -> list[str]:
    """A small .gz whose first atom line runs 2 MiB without a newline (docs/post.md: 1 MiB)."""
    import gzip

    text = (CORPUS / "dump" / "good.dump").read_bytes()
    head = text[:text.index(b"\n", text.index(b"ITEM: ATOMS")) + 1]
    (tmp / "long.dump.gz").write_bytes(gzip.compress(head + b"1" * (2 << 20) + b"\n"))
    return ["post", str(tmp / "long.dump.gz"), "--to", "xyz", "-o", str(tmp / "out")]


def _run_unwritable(tmp: Path) -> list[str]:
    (tmp / "file").write_text("a file, not a folder\n")
    return ["run", str(CORPUS / "demdf" / "good.json"), "--out", str(tmp / "file" / "sub")]


def _post_directory(tmp: Path) -> list[str]:
    (tmp / "frames.dump").mkdir()
    return ["post", str(tmp / "frames.dump"), "--to", "xyz", "-o", str(tmp / "out")]


def _fibrenet_copy(tmp: Path, **keys: str) -> Path:
    """The good FibreNet input and its model in ``tmp``, keyword lines replaced."""
    lines = (CORPUS / "fibrenet" / "good.txt").read_text().splitlines()
    for name in ("model.txt",):
        src = CORPUS / "fibrenet" / name
        if src.exists():
            (tmp / name).write_bytes(src.read_bytes())
    lines = [ln for ln in lines if not ln.split() or ln.split()[0] not in keys]
    lines += [f"{k}\t{v}" for k, v in keys.items()]
    (tmp / "input.txt").write_text("\n".join(lines) + "\n")
    return tmp / "input.txt"


def _run_existing(tmp: Path) -> list[str]:
    inp = _fibrenet_copy(tmp)
    (tmp / "out").mkdir()
    prefix = next(ln.split()[1] for ln in inp.read_text().splitlines() if ln.startswith("output_file"))
    (tmp / "out" / f"{prefix}_coord.xyz").write_text("an earlier result\n")
    return ["run", str(inp), "-o", str(tmp / "out")]


_HELD: list[int] = []          # folder locks held for the rest of the test process


def _run_locked(tmp: Path) -> list[str]:
    import fcntl
    import os

    (tmp / "out").mkdir()
    fd = os.open(tmp / "out", os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)      # as a running fibrelmp holds it
    _HELD.append(fd)
    return ["run", str(_fibrenet_copy(tmp)), "-o", str(tmp / "out")]


def _run_escape(tmp: Path) -> list[str]:
    return ["run", str(_fibrenet_copy(tmp, output_file="../../x")), "-o", str(tmp / "out")]


def _script_overwrites_scene(tmp: Path) -> list[str]:
    (tmp / "scene.txt").write_bytes((CORPUS / "musen_script" / "scene.txt").read_bytes())
    text = (CORPUS / "musen_script" / "good.txt").read_text()
    import re
    text = re.sub(r"(?m)^RESULT_FILE.*$", "RESULT_FILE scene.txt", text)
    (tmp / "job.txt").write_text(text)
    return ["run", str(tmp / "job.txt")]


def _mdem(edit: Callable[[bytearray], None], command: str = "check") -> Callable[[Path], list[str]]:
    """A spoilt copy of the example .mdem scene (SingelParticle.mdem, 6431 bytes)."""
    def make(tmp: Path) -> list[str]:
        data = bytearray((CORPUS.parents[1] / "examples" / "musen" / "SingelParticle.mdem").read_bytes())
        edit(data)
        path = tmp / "scene.mdem"
        path.write_bytes(bytes(data))
        return [command, str(path)] + (["--end-time", "1e-3"] if command == "run" else [])
    return make


def _set(offset: int, value: bytes) -> Callable[[bytearray], None]:
    def edit(data: bytearray) -> None:
        data[offset:offset + len(value)] = value
    return edit


def _case(edit: Callable[[str], str], spoil: Callable[[Path], None] | None = None,
          command: str = "check") -> Callable[[Path], list[str]]:
    """A copy of the CardioProof piston-tube example with its case file (and files) spoilt."""
    def make(tmp: Path) -> list[str]:
        example = CORPUS.parents[1] / "examples" / "cardioproof"
        for f in example.glob("piston_tube.*"):
            (tmp / f.name).write_bytes(f.read_bytes())
        case = tmp / "piston_tube.json"
        case.write_text(edit(case.read_text()))
        if spoil is not None:
            spoil(tmp)
        return [command, str(case)]
    return make


def _truncate_dynpt(tmp: Path) -> None:
    path = tmp / "piston_tube.dynpt"
    path.write_bytes(path.read_bytes()[:-100])


def _device(tmp: Path) -> list[str]:
    return ["check", "/dev/zero"]


GENERATED = [
    Case("generated/directory", "any", "", "a directory given as the input", make=_directory),
    Case("generated/model_directory", "FibreNet model", "", "model_file names a directory",
         make=_model_directory),
    Case("generated/unreadable", "any", "", "a file without read permission",
         make=_unreadable, needs_unreadable=True),
    Case("generated/dump_directory", "LAMMPS dump", "", "a directory given as the dump",
         command="post", make=_post_directory),
    Case("generated/post_unwritable", "LAMMPS dump", "", "output folder below a regular file",
         command="post", make=_post_unwritable),
    Case("generated/post_existing", "LAMMPS dump", "", "output exists and --force not given",
         command="post", make=_post_existing),
    Case("generated/post_new_folder", "LAMMPS dump", "", "bad frame 2 with -o in new folders "
         "(none is left behind)", command="post", make=_post_new_folder),
    Case("generated/dump_long_line", "LAMMPS dump", "", "a .gz whose atom line runs 2 MiB "
         "without a newline", command="post", make=_dump_long_line),
    Case("generated/run_unwritable", "DEMDF", "", "run --out below a regular file",
         command="run", make=_run_unwritable),
    Case("generated/run_existing", "FibreNet", "", "an earlier run's result in -o, no --force",
         command="run", make=_run_existing),
    Case("generated/run_locked", "FibreNet", "", "-o folder locked by another run",
         command="run", make=_run_locked),
    Case("generated/run_escape", "FibreNet", "", "output_file ../../x with -o",
         command="run", make=_run_escape),
    Case("generated/script_overwrites_scene", "cmusen script", "", "RESULT_FILE names the "
         "SOURCE_FILE scene", command="run", make=_script_overwrites_scene),
    Case("generated/device", "any", "", "/dev/zero as the input", make=_device),
    Case("generated/mdem_signature", "MUSEN .mdem", "", "a .mdem whose first 4 bytes are not "
         "MUSEN's signature", make=_mdem(_set(0, b"\0\0\0\0"))),
    Case("generated/mdem_version", "MUSEN .mdem", "", "file version 7 in the header",
         make=_mdem(_set(4, b"\x07\0\0\0"))),
    Case("generated/mdem_truncated", "MUSEN .mdem", "", "the file cut inside its scene block",
         make=_mdem(lambda d: d.__delitem__(slice(2500, None)))),
    Case("generated/mdem_hostile_size", "MUSEN .mdem", "", "a thread header claiming 2^60 bytes",
         make=_mdem(_set(64 + 64, (1 << 60).to_bytes(8, "little")))),
    Case("generated/mdem_corrupt", "MUSEN .mdem", "", "bytes of the compressed scene overwritten",
         make=_mdem(_set(2200, b"@" * 100))),
    Case("generated/mdem_run_truncated", "MUSEN .mdem", "", "run of a .mdem cut in its time "
         "points", make=_mdem(lambda d: d.__delitem__(slice(6300, None)), "run")),
    Case("generated/case_syntax", "CardioProof case", "", "a case file that is not valid JSON",
         make=_case(lambda t: t.replace('"run":', '"run"'))),
    Case("generated/case_version", "CardioProof case", "", "case file version 2",
         make=_case(lambda t: t.replace('"cardioproof": 1', '"cardioproof": 2'))),
    Case("generated/case_no_opening_elements", "CardioProof case", "", "an opening whose tags "
         "select no element", make=_case(lambda t: t.replace('"tags": [3]', '"tags": [7]'))),
    Case("generated/case_shared_elements", "CardioProof case", "", "two openings naming the "
         "same elements", make=_case(lambda t: t.replace(
             '"openings": [', '"openings": [{"name": "first", "tags": [3]}, '))),
    Case("generated/case_end_time", "CardioProof case", "", "end time beyond the last motion frame",
         make=_case(lambda t: t.replace('"end_time": 0.01', '"end_time": 0.5'))),
    Case("generated/case_dynpt_truncated", "CardioProof case", "", "a .dynpt shorter than its "
         "header says", make=_case(lambda t: t, _truncate_dynpt)),
    Case("generated/case_mesh_missing", "CardioProof case", "", "the mesh file named is missing",
         make=_case(lambda t: t.replace('"file": "piston_tube.pts"', '"file": "none.pts"'))),
]

CASES: list[Case] = (FIBRENET + FIBRENET_MODEL + MUSEN + MUSEN_SCRIPT + DEMDF + DUMP + GENERIC
                     + GENERATED)


# ------------------------------------------------------------------ running
@dataclass
class Outcome:
    exit_code: int
    errors: list[str]            # "error: " lines, normalised
    stdout: str
    stderr: str
    exception: BaseException | None     # anything but SystemExit escaping the CLI


@contextmanager
def _cwd(path: Path) -> Iterator[None]:
    old = os.getcwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(old)


def normalise(text: str, tmp: Path) -> str:
    """Messages without the machine-specific parts: the corpus folder and the temp folder."""
    for base, name in ((tmp.resolve(), "<tmp>"), (tmp, "<tmp>"), (CORPUS, "<corpus>")):
        text = text.replace(str(base), name)
    return re.sub(r"\s+$", "", text)


def run_case(case: Case, tmp: Path, args: list[str] | None = None) -> Outcome:
    """Run the case through the CLI in this process, from the corpus folder (so messages name
    the corpus-relative path the user typed); ``args`` from ``case.args(tmp)`` if not given."""
    from typer.testing import CliRunner

    from fibrelmp.cli import app

    if args is None:
        args = case.args(tmp)
    with _cwd(CORPUS):
        result = CliRunner().invoke(app, args)
    errors = [normalise(line[len("error: "):], tmp) for line in result.stderr.splitlines()
              if line.startswith("error: ")]
    escaped = None if isinstance(result.exception, (SystemExit, type(None))) else result.exception
    return Outcome(result.exit_code, errors, result.stdout, result.stderr, escaped)


def unreadable_possible(tmp: Path) -> bool:
    """chmod 000 stops reading, unless we run as root (or with CAP_DAC_OVERRIDE)."""
    probe = tmp / "probe"
    probe.write_text("x")
    probe.chmod(0)
    try:
        probe.read_bytes()
        return False
    except OSError:
        return True
    finally:
        probe.chmod(0o600)


# ------------------------------------------------------------------ docs/errors.md table
DOC = CORPUS.parents[1] / "docs" / "errors.md"
START = "<!-- corpus table: generated by tests/bad_inputs/make_table.py -->"
END = "<!-- end of corpus table -->"
HEADER = ("| case | format | input | result | message |\n"
          "|---|---|---|---|---|")


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def row(case: Case, outcome: Outcome) -> str:
    if case.accept:
        result, message = f"accepted (exit {outcome.exit_code})", "—"
    else:
        result = f"exit {outcome.exit_code}"
        message = "<br>".join(f"`{_cell(e)}`" if "`" not in e else _cell(e) for e in outcome.errors)
    return f"| {case.name} | {case.fmt} | {_cell(case.what)} | {result} | {message} |"


def doc_rows(text: str | None = None) -> dict[str, str]:
    """The rows of the generated table in docs/errors.md, by case name."""
    text = DOC.read_text() if text is None else text
    if START not in text or END not in text:
        return {}
    body = text[text.index(START) + len(START): text.index(END)]
    out = {}
    for line in body.splitlines():
        if line.startswith("| ") and not line.startswith(("| case ", "|---")):
            out[line.split(" | ", 1)[0][2:]] = line
    return out
