"""The format registry: every file format fibrelmp reads or writes, in one table.

Each ``Format`` record says what a format is (name, extensions, content magic, units), which
roles it has and where its code lives.  The CLI and the Python API take every format choice
from here (``fibrelmp run/check/translate`` detect the input, ``post --to`` lists and loads
targets, help texts list names); no other module names formats.  Code is imported lazily
(``Format.load``): ``fibrelmp check`` on a FibreNet file never imports the DEM code.

Roles
  ``input``   a simulation input ``run``/``check``/``translate`` accept; its hook is an
              ``InputFormat`` (``fibrelmp.inputformat``): read, check, translate, and
              the ``RunPlan`` of a run.  A format home holds its hook and builds its
              plan from the core's plan types (``fibrelmp.runplan``); a home lies below
              the pipeline, which only executes plans.
  ``result``  written by ``run`` as the input's native results (its hook is a ``Writer``).
  ``target``  a ``post --to`` output; its hook is a ``post.target.DumpTarget`` (a ``Writer``
              of LAMMPS dump frames).
  ``frames``  a trajectory ``post`` reads; its hook is a frame ``Reader``.
  ``document`` a whole scene/result file ``fibrelmp convert`` reads and writes; its hook
              has ``open(path)`` (a document) and ``writer(target, precision, force=)``.
  ``mesh``    a finite-element mesh; its hook is a ``mesh.model.MeshFormat`` (reader, writer).
  ``motion``  mesh node positions over time; its hook is a frame ``Reader``.
  ``also``    written from a run's own frames beside the input's results (``run --also
              NAME``, any input); its hook is a ``fibrelmp.also.RunOutput`` (it declares the
              files among the run's outputs and makes the writer the frames are fed to).

A record's ``pictures`` names the source ``fibrelmp plot``/``snapshot`` read its results with
(a ``pictures.sources.Source``).

Adding a format: one module with its Reader/Writer subclass, one ``register_format`` call
below (docs/architecture.md shows an example).  Like meshio's ``register_format`` and ASE's
``ioformats`` table.
"""

from __future__ import annotations

import importlib
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import InputError

INPUT, RESULT, TARGET, FRAMES, DOCUMENT = "input", "result", "target", "frames", "document"
MESH, MOTION, ALSO = "mesh", "motion", "also"
ROLES = (INPUT, RESULT, TARGET, FRAMES, DOCUMENT, MESH, MOTION, ALSO)


@dataclass(frozen=True)
class Format:
    name: str                              # as the CLI and the API spell it
    title: str                             # one line for help texts
    units: str                             # "lj" (LAMMPS reduced), "si", "dimensionless", "any"
    hooks: dict[str, str]                  # role -> "module:attribute"
    extensions: tuple[str, ...] = ()       # lower case, with the dot
    magic: re.Pattern | None = None        # content test on the first MiB (inputs)
    example: str = ""                      # a command line for help texts
    home: str = ""                         # the format's package (docs)
    binary: bool = False                   # detected first (text magics could match its bytes)
    pictures: str = ""                     # "module:Class": its results' frames for plot/snapshot
    roles: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        unknown = set(self.hooks) - set(ROLES)
        if unknown:
            raise ValueError(f"format {self.name}: unknown roles {sorted(unknown)}")
        object.__setattr__(self, "roles", tuple(r for r in ROLES if r in self.hooks))

    def load(self, role: str) -> Any:
        """The class/object implementing ``role`` (imported now, not before)."""
        return _load(self.hooks[role])

    def load_pictures(self) -> Any:
        """The picture source (``pictures.sources.Source``) of this format's results."""
        return _load(self.pictures)


def _load(spec: str) -> Any:
    module, _, attribute = spec.partition(":")
    return getattr(importlib.import_module(module), attribute)


_FORMATS: dict[str, Format] = {}


def register_format(fmt: Format) -> Format:
    """Add (or replace) a format; returns it."""
    _FORMATS[fmt.name] = fmt
    return fmt


def unregister_format(name: str) -> None:
    """Remove a format (tests that register a toy one)."""
    _FORMATS.pop(name, None)


def get(name: str) -> Format:
    return _FORMATS[name]


def formats_by_name() -> dict[str, Format]:
    return dict(_FORMATS)


def formats(role: str | None = None) -> list[Format]:
    """Registered formats (with ``role``), in registration order."""
    return [f for f in _FORMATS.values() if role is None or role in f.roles]


def names(role: str) -> list[str]:
    return [f.name for f in formats(role)]


def choose(role: str, name: str, option: str) -> Format:
    """The format ``name`` given to ``option`` (e.g. ``--to``), or an error listing choices."""
    fmt = _FORMATS.get(name.lower())
    if fmt is None or role not in fmt.roles:
        raise InputError(None, None, f"{option} {name!r}: unknown format (choose from "
                         f"{', '.join(names(role))})")
    return fmt


# -- input detection -------------------------------------------------------------------------
DETECT_BYTES = 1 << 20          # detection reads at most this much of a file


def check_regular_file(path: Path, what: str = "input") -> None:
    """A readable regular file: not missing, not a folder, not a device or FIFO (reading
    /dev/zero never ends, a FIFO blocks for ever)."""
    from .textio import refuse_special_file

    try:
        refuse_special_file(path, what)
    except FileNotFoundError:
        raise InputError(path, None, f"{what} file not found") from None
    except OSError as exc:
        raise InputError(path, None, f"cannot read {what}: {exc.strerror or exc}") from None
    if path.is_dir():
        raise InputError(path, None, f"{what} is a directory, expected a file")


def input_hint() -> str:
    titles = [f.title for f in formats(INPUT)]
    return "expected " + ", ".join(titles[:-1]) + " or " + titles[-1]


def detect(path: str | Path) -> Format:
    """The input format of ``path``: by content first, then by extension (so that format's
    reader explains what is wrong inside)."""
    path = Path(path)
    check_regular_file(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(DETECT_BYTES)
    except OSError as exc:
        raise InputError(path, None, f"cannot read input: {exc.strerror or exc}") from None
    if head.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError(path, None, "the file is UTF-16 encoded; save it as UTF-8 (or ASCII) text")
    if head.startswith(b"\xef\xbb\xbf"):        # UTF-8 byte-order mark: the readers accept it
        head = head[3:]
    inputs = sorted(formats(INPUT), key=lambda f: not f.binary)     # stable: binary ones first
    for fmt in inputs:
        if fmt.magic is not None and fmt.magic.search(head):
            return fmt
    for fmt in inputs:
        if path.suffix.lower() in fmt.extensions:
            return fmt
    raise InputError(path, None, f"cannot tell the input format: {input_hint()}")


# -- the formats ---------------------------------------------------------------------------
register_format(Format(
    "fibrenet", "a FibreNet input (with a 'model_file' line)", "lj",
    {INPUT: "fibrelmp.translate.fibrenet.input:FibreNetInput"},
    magic=re.compile(rb"^[ \t]*model_file\s", re.M),
    example="examples/fibre_network/input.txt", home="fibrelmp.translate.fibrenet"))
register_format(Format(
    "musen-script", "a cmusen job script", "si",
    {INPUT: "fibrelmp.translate.musen.script_input:ScriptInput"},
    magic=re.compile(rb"^[ \t]*(JOB|SOURCE_FILE|COMPONENT)\b", re.M),
    example="examples/musen/single_particle_job.txt", home="fibrelmp.translate.musen"))
register_format(Format(
    # the signature 0x12345678 (little endian); binary: detected before the text formats, so
    # that no text magic can match inside its compressed data
    "mdem", "a MUSEN .mdem scene or result", "si",
    {INPUT: "fibrelmp.translate.musen.mdem.input:MdemSceneInput",
     RESULT: "fibrelmp.translate.musen.mdem.result:MdemResultWriter",
     TARGET: "fibrelmp.translate.musen.mdem.target:MdemTarget",
     DOCUMENT: "fibrelmp.translate.musen.mdem.convert:MdemDocument"},
    pictures="fibrelmp.translate.musen.mdem.pictures:MdemSource",
    extensions=(".mdem",), magic=re.compile(rb"\Ax\x56\x34\x12", re.S), binary=True,
    example="examples/musen/SingelParticle.mdem", home="fibrelmp.translate.musen.mdem"))
register_format(Format(
    # an object line "0 ID 1 TYPE 5 ...", or a scene line (22 domain / 32 material) of an
    # object-less scene; ".txt" is too common to mean MUSEN
    "musen", "a MUSEN text scene or result", "si",
    {INPUT: "fibrelmp.translate.musen.input:SceneInput",
     RESULT: "fibrelmp.translate.musen.writer:MusenResultWriter",
     TARGET: "fibrelmp.translate.musen.target:MusenTarget",
     DOCUMENT: "fibrelmp.translate.musen.mdem.convert:MusenTextDocument"},
    pictures="fibrelmp.translate.musen.pictures:MusenTextSource",
    magic=re.compile(rb"\A\s*(0\s+\d+\s+1\s+\d+\s+5\b|(22|32)\s+\S)"),
    example="examples/musen/SingelParticle_text.txt", home="fibrelmp.translate.musen"))
register_format(Format(
    # JSON whose first key is "cardioproof" (before DEMDF, whose magic is any JSON object)
    "cardioproof", "a CardioProof case (JSON: moving FE wall, SPH water, outflow openings)", "si",
    {INPUT: "fibrelmp.translate.cardioproof.input:CaseInput"},
    magic=re.compile(rb'\A\s*\{\s*"cardioproof"\s*:'),
    example="examples/cardioproof/piston_tube.json", home="fibrelmp.translate.cardioproof"))
register_format(Format(
    "demdf", "a DEMDF JSON file (input or snapshot)", "dimensionless",
    {INPUT: "fibrelmp.translate.demdf.input:DemdfInput",
     RESULT: "fibrelmp.translate.demdf.writer:DemdfSnapshotWriter",
     TARGET: "fibrelmp.translate.demdf.target:DemdfTarget"},
    pictures="fibrelmp.translate.demdf.pictures:DemdfSource",
    extensions=(".json",), magic=re.compile(rb"\A\s*\{"),
    example="examples/demdf/head_on.json", home="fibrelmp.translate.demdf"))
register_format(Format(
    "xyz", "FibreNet trajectories (_coord/_vel/_force.xyz)", "lj",
    {RESULT: "fibrelmp.translate.fibrenet.writer:XyzWriter",
     TARGET: "fibrelmp.translate.fibrenet.target:XyzTarget"},
    pictures="fibrelmp.translate.fibrenet.pictures:FibreNetSource", extensions=(".xyz",), home="fibrelmp.translate.fibrenet"))
register_format(Format(
    "res", "a FibreNet restart (_restart.res)", "lj",
    {RESULT: "fibrelmp.translate.fibrenet.writer:RestartWriter",
     TARGET: "fibrelmp.translate.fibrenet.target:RestartTarget"},
    pictures="fibrelmp.translate.fibrenet.pictures:FibreNetSource", extensions=(".res",), home="fibrelmp.translate.fibrenet"))
register_format(Format(
    "mercury", "MercuryDPM .data/.ene/.fstat/.restart", "any",
    {TARGET: "fibrelmp.post.mercury:MercuryTarget"},
    extensions=(".data", ".ene", ".fstat", ".restart"), home="fibrelmp.post.mercury"))
register_format(Format(
    # also written by ``run --also vtk`` beside the results (fibrelmp.post.vtk.run_output)
    "vtk", "VTK .vtp/.vtm frames with a .pvd index (ParaView, OVITO)", "any",
    {TARGET: "fibrelmp.post.vtk:VtkTarget", ALSO: "fibrelmp.post.vtk.run_output:ViewerOutput"},
    extensions=(".pvd", ".vtp", ".vtm"), home="fibrelmp.post.vtk"))
register_format(Format(
    "lammps-dump", "a LAMMPS text dump (plain or .gz)", "any",
    {FRAMES: "fibrelmp.post.lammps_dump:DumpReader"}, pictures="fibrelmp.pictures.sources:DumpSource",
    extensions=(".dump", ".lammpstrj", ".gz"), magic=re.compile(rb"\A\s*ITEM:"),
    home="fibrelmp.post.lammps_dump"))
register_format(Format(
    "mdanalysis", "any trajectory MDAnalysis reads (with --topology)", "any",
    {FRAMES: "fibrelmp.post.mdanalysis:UniverseReader"},
    home="fibrelmp.post.mdanalysis"))
register_format(Format(
    "opencarp", "an openCARP mesh (.pts/.elem text, .bpts/.belem binary; µm)", "si",
    {MESH: "fibrelmp.mesh.opencarp.mesh:OpenCarpMesh"},
    extensions=(".pts", ".elem", ".bpts", ".belem"), home="fibrelmp.mesh.opencarp"))
register_format(Format(
    "vtk-mesh", "a VTK unstructured-grid mesh (.vtu, .vtk)", "any",
    {MESH: "fibrelmp.mesh.vtkmesh.mesh:VtkMesh"},
    extensions=(".vtu", ".vtk"), home="fibrelmp.mesh.vtkmesh"))
register_format(Format(
    "dynpt", "openCARP node positions over time (.dynpt, IGB vec3f; µm)", "si",
    {MOTION: "fibrelmp.mesh.opencarp.dynpt:DynptReader"},
    extensions=(".dynpt",), home="fibrelmp.mesh.opencarp"))
