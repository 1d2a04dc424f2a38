"""``fibrelmp post`` against issue 24's hostile inputs: a gzip line that expands to hundreds
of MB, a gzip dump cut short, inf/nan values, names that need XML escaping, MPI, output
names and ``.pvd`` times.  Hostile files are built here, small; anything bounding memory or
time runs the CLI in a subprocess with RLIMIT_AS and a timeout."""

from __future__ import annotations

import gzip
import os
import resource
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.post.lammps_dump.reader import MAX_LINE
from fibrelmp.translate.fibrenet.writer import read_xyz

from .test_post_robust import ROWS, frame, write
from .test_post_roundtrip import post
from .test_vtk_viewers import vtk_read

CLI = [sys.executable, "-m", "fibrelmp.cli"]


def cli(args: list, cwd: Path, memory_mb: int | None = None, timeout: float = 60.0) -> subprocess.CompletedProcess:
    """The CLI in a subprocess (address space limited to ``memory_mb`` when given)."""
    def limit() -> None:
        if memory_mb is not None:
            resource.setrlimit(resource.RLIMIT_AS, (memory_mb << 20, memory_mb << 20))
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return subprocess.run(CLI + [str(a) for a in args], cwd=cwd, capture_output=True, text=True,
                          preexec_fn=limit, timeout=timeout, env=env)


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# ------------------------------------------------------------- 1. one huge line in a small .gz
LONG_LINE_MB = 600          # what the hostile line expands to
MEMORY_MB = 400             # the CLI's address space: a conversion needs < 150 MB


def long_line_gz(path: Path) -> Path:
    """A 1-atom frame whose atom line is ``LONG_LINE_MB`` MB of digits without a newline:
    gzip members (concatenated, as gzip allows) of 16 MiB each, compressed once (~0.6 MB)."""
    head = frame(0, [(1, 1, 0.5, 0.5, 0.5)]).rsplit("1 1 0.5", 1)[0]
    block = gzip.compress(b"1" * (16 << 20), compresslevel=9)
    with open(path, "wb") as fh:
        fh.write(gzip.compress(head.encode()))
        for _ in range(LONG_LINE_MB // 16):
            fh.write(block)
        fh.write(gzip.compress(b" 1 1 1 1\n"))
    return path


@pytest.mark.parametrize("args", [["--info"], ["--to", "xyz", "-o", "out/net"]])
def test_a_gzip_line_of_hundreds_of_mb_is_refused_within_bounded_memory(tmp_path, args):
    """Was: the whole line read into memory (3 GB resident, exit 1 'out of memory').  Now an
    input error at the line, exit 2, in a process limited to MEMORY_MB of address space."""
    dump = long_line_gz(tmp_path / "long.dump.gz")
    assert dump.stat().st_size < 2 << 20
    proc = cli(["post", dump.name, *args], tmp_path, memory_mb=MEMORY_MB, timeout=60)
    assert proc.returncode == 2, proc.stderr[-2000:]
    line = len(frame(0, ROWS).splitlines()) - len(ROWS) + 1          # the first atom line: 10
    assert proc.stderr.strip().splitlines()[-1] == (
        f"error: long.dump.gz:{line}: line longer than {MAX_LINE >> 20} MiB, the longest a dump "
        "line may be (docs/post.md; not a LAMMPS text dump?)")
    assert "Traceback" not in proc.stderr
    assert listing(tmp_path) == ["long.dump.gz"]        # nothing written, no folder made


def test_a_long_header_line_is_refused_too(tmp_path):
    """A line longer than MAX_LINE where an ITEM line is expected (plain file)."""
    p = write(tmp_path, b"ITEM: TIMESTEP\n" + b"7" * (MAX_LINE + 10) + b"\n")
    from fibrelmp.errors import InputError
    from fibrelmp.post.lammps_dump.reader import iter_frames

    with pytest.raises(InputError, match=r"d\.dump:2: line longer than 1 MiB"):
        list(iter_frames(p))


def test_lines_up_to_the_bound_are_read(tmp_path):
    """An atom line of many columns, just under MAX_LINE, is an ordinary line."""
    from fibrelmp.post.lammps_dump.reader import iter_frames

    ncol = 5 + (MAX_LINE - 1000) // 13          # "1.00000000e0 " is 13 characters
    names = "id type x y z " + " ".join(f"c_{k}" for k in range(ncol - 5))
    row = " ".join(["1", "1", "0.5", "0.5", "0.5"] + ["1.00000000e0"] * (ncol - 5))
    assert MAX_LINE - 2000 < len(row) < MAX_LINE
    p = write(tmp_path, frame(0, [(row,)], cols=names))
    (got,) = list(iter_frames(p))
    assert got.count == 1 and len(got.columns) == ncol and got.columns[f"c_{ncol - 6}"][0] == 1.0


# ------------------------------------------------------------- 5. a gzip dump cut short
@pytest.mark.parametrize("keep", [0.6, 0.95])
def test_a_gzip_dump_cut_short_keeps_its_complete_frames_like_a_plain_one(tmp_path, keep):
    """Was: 'cannot read the dump: Compressed file ended before the end-of-stream marker'
    (exit 2, nothing).  Now the frames before the cut, with a warning, as for a plain dump
    cut at the same place of the text."""
    rng = np.random.default_rng(5)          # random digits: gzip cannot shrink them much
    frames = [frame(s, [(k, 1, *rng.random(3)) for k in range(1, 21)], time=s / 10)
              for s in range(0, 50, 10)]
    packed = gzip.compress("".join(frames).encode())
    cut = packed[:int(keep * len(packed))]
    gz = write(tmp_path, cut, "cut.dump.gz")
    seen = zlib.decompressobj(31).decompress(cut)                  # what the cut file holds
    plain = write(tmp_path, seen, "cut.dump")
    complete = sum(len("".join(frames[:k + 1])) <= len(seen) for k in range(5))
    assert 1 <= complete < 5
    for dump, name in ((gz, "gz"), (plain, "plain")):
        proc = cli(["post", dump.name, "--to", "xyz", "-o", name], tmp_path, timeout=60)
        assert proc.returncode == 0, proc.stderr
        assert "warning [truncated dump]" in proc.stderr
        steps = [f.step for f in read_xyz(tmp_path / f"{name}_coord.xyz")]
        assert steps == list(range(0, 10 * complete, 10)), name
    assert "gzip stream ends early" in cli(["post", gz.name, "--info"], tmp_path).stderr


# ------------------------------------------------------------- 2. inf and nan in the values
VEL_FORCE = "id type x y z vx vy vz fx fy fz radius mass"


def blown_up(tmp_path: Path, column: str, token: str) -> tuple[Path, int]:
    """Two frames; in the second, atom id 3 (its third atom line) has ``token`` in ``column``.
    Returns the dump and that atom line's number."""
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    second = frame(10, rows, cols=VEL_FORCE, time=0.1)
    lines = second.splitlines()
    words = lines[-1].split()
    assert words[0] == "3"
    words[VEL_FORCE.split().index(column)] = token
    lines[-1] = " ".join(words)
    first = frame(0, rows, cols=VEL_FORCE, time=0.0)
    p = write(tmp_path, first + "\n".join(lines) + "\n")
    return p, len(first.splitlines()) + len(lines)


@pytest.mark.parametrize("to,column,token,shown", [
    (to, column, token, shown) for to in ("xyz", "res", "musen", "demdf")
    for column, token, shown in (("vx", "inf", "inf"), ("fz", "1e400", "inf"), ("vy", "-nan", "nan"),
                                 ("radius", "nan", "nan"))
    if not (to in ("xyz", "res") and column == "radius")])          # FibreNet files hold no radius
def test_inf_or_nan_is_refused_by_targets_that_cannot_hold_it(tmp_path, to, column, token, shown):
    """Was: ``inf`` written into FibreNet's xyz files, exit 0.  Now exit 2 naming the atom's
    line, the frame, the atom and the column, and nothing written."""
    p, line = blown_up(tmp_path, column, token)
    proc = cli(["post", p.name, "--to", to, "-o", "out/r"], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines()[-1] == (
        f"error: d.dump:{line}: frame 1 (step 10), atom id 3: {column} is {shown}: --to {to} "
        "cannot write inf or nan (did the simulation blow up?); nothing written")
    assert listing(tmp_path) == ["d.dump"]


def test_inf_in_a_column_the_target_does_not_write_is_no_error(tmp_path):
    """xyz writes positions, velocities and forces: an inf elsewhere is not in its files."""
    rows = [r + (0.5, 0.25, 0.0, "inf") for r in ROWS]
    p = write(tmp_path, frame(0, rows, cols="id type x y z vx vy vz c_energy", time=0.0))
    post(p, "xyz", tmp_path / "o")
    assert [f.step for f in read_xyz(tmp_path / "o_coord.xyz")] == [0]


def test_inf_in_atoms_that_types_leaves_out_is_no_error(tmp_path):
    """Only the atoms written are checked: ``--types 2`` leaves out the blown-up atom 3."""
    p, _ = blown_up(tmp_path, "vx", "inf")
    written = post(p, "xyz", tmp_path / "o", types=["2"])
    assert [len(f.values) for f in read_xyz(written[0])] == [1, 1]


def test_vtk_writes_inf_as_is_with_a_warning_and_vtk_reads_it(tmp_path):
    """VTK's Float64 arrays hold inf/nan (a viewer of a blown-up run shows them): written,
    never silently (a warning names the first)."""
    p, _ = blown_up(tmp_path, "vx", "inf")
    proc = cli(["post", p.name, "--to", "vtk", "-o", "v"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert ("warning [inf/nan]: d.dump: frame 1 (step 10), atom id 3: vx is inf; written as is"
            in proc.stderr)
    points = vtk_read(tmp_path / "v_000001.vtp").GetPointData()
    ids, velocity = vtk_array(points, "id"), vtk_array(points, "Velocity")
    assert velocity[list(ids).index(3), 0] == np.inf and np.isfinite(velocity[ids != 3]).all()


def test_an_id_of_nan_is_refused_by_vtk_too(tmp_path):
    p = write(tmp_path, frame(0, [(1, 1, 0.5, 0.5, 0.5), ("nan", 1, 1, 1, 1)]))
    proc = cli(["post", p.name, "--to", "vtk", "-o", "v"], tmp_path)
    assert proc.returncode == 2 and "d.dump:11: frame 0 (step 0), atom 2: id is nan" in proc.stderr


# ------------------------------------------------------------- 3. names in VTK's XML files
def vtk_array(data, name: str) -> np.ndarray:
    from vtkmodules.util.numpy_support import vtk_to_numpy

    array = data.GetArray(name)
    assert array is not None, f"no array {name!r}"
    return vtk_to_numpy(array)


def pvd_entries(path: Path) -> list[tuple[str, str]]:
    """(timestep, file) of a .pvd as VTK's XML parser (the one ParaView's PVD reader is
    built on) reads them."""
    parser_module = pytest.importorskip("vtkmodules.vtkIOXMLParser")
    parser = parser_module.vtkXMLDataParser()
    parser.SetFileName(str(path))
    assert parser.Parse() == 1, f"VTK cannot parse {path}"
    collection = parser.GetRootElement().FindNestedElementWithName("Collection")
    sets = [collection.GetNestedElement(k) for k in range(collection.GetNumberOfNestedElements())]
    return [(s.GetAttribute("timestep"), s.GetAttribute("file")) for s in sets]


def read_every_file(pvd: Path) -> list:
    """Every frame of a .pvd read by VTK (a .vtm's blocks included); the frames' data."""
    out = []
    for _, name in pvd_entries(pvd):
        data = vtk_read(pvd.parent / name)
        if name.endswith(".vtm"):
            blocks = [data.GetBlock(k) for k in range(data.GetNumberOfBlocks())]
            assert blocks[0] is not None and blocks[0].GetNumberOfPoints() > 0
            data = blocks[0]
        out.append(data)
    return out


HOSTILE = 'a&b"<c'
COLUMN = 'c_a"&<b'
DATA = """LAMMPS data file

3 atoms
1 bonds
2 atom types
1 bond types

0 10 xlo xhi
0 10 ylo yhi
0 10 zlo zhi

Masses

1 1.0
2 1.0

Atoms # atomic

1 2 0.25 9.75 5.0
2 1 1.5 2.5 3.5
3 1 4.0 4.0 4.0

Bonds

1 1 1 2
"""


@pytest.mark.parametrize("bonds", [False, True])
def test_vtk_output_and_column_names_that_need_escaping_survive(tmp_path, bonds):
    """Was: ``-o 'out/a&b"<c'`` and a column ``c_a"&<b`` gave files VTK cannot parse, exit
    0.  Now every file parses with VTK's readers and the names read back as given."""
    rows = [r + (k + 0.5,) for k, r in enumerate(ROWS)]
    p = write(tmp_path, frame(0, rows, cols=f"id type x y z {COLUMN}", time=0.0)
              + frame(10, rows, cols=f"id type x y z {COLUMN}", time=0.1))
    data = ["--data", write(tmp_path, DATA, "data.lammps").name] if bonds else []
    proc = cli(["post", p.name, "--to", "vtk", "-o", f"out/{HOSTILE}", *data], tmp_path)
    assert proc.returncode == 0, proc.stderr
    pvd = tmp_path / "out" / f"{HOSTILE}.pvd"
    suffix = ".vtm" if bonds else ".vtp"
    assert pvd_entries(pvd) == [("0.0", f"{HOSTILE}_000000{suffix}"), ("0.1", f"{HOSTILE}_000001{suffix}")]
    value_of = {r[0]: r[-1] for r in rows}
    for particles in read_every_file(pvd):
        ids = vtk_array(particles.GetPointData(), "id")
        np.testing.assert_array_equal(vtk_array(particles.GetPointData(), COLUMN),
                                      [value_of[i] for i in ids])
    if bonds:       # bond 1-2 crosses the periodic y face: two pieces, each with the bond's ids
        lines = vtk_read(tmp_path / "out" / f"{HOSTILE}_000000_bonds.vtp").GetCellData()
        assert vtk_array(lines, "id1").tolist() == [1, 1] and vtk_array(lines, "id2").tolist() == [2, 2]


def fibrenet_case(folder: Path, output_file: str) -> None:
    """The example network, 100 steps, a frame every 50, written as ``output_file``."""
    from .conftest import REPO

    src = REPO / "examples" / "fibre_network"
    (folder / "model.txt").write_bytes((src / "model.txt").read_bytes())
    text = (src / "input.txt").read_text()
    for old, new in (("output_file\tfibre_network", f"output_file\t{output_file}"),
                     ("run\t2000", "run\t100"), ("output_freq\t400", "output_freq\t50")):
        assert old in text
        text = text.replace(old, new)
    (folder / "input.txt").write_text(text)


def test_fibrenet_output_file_that_needs_escaping_with_vtk(tmp_path):
    """Was: FibreNet ``output_file net&a"b<c`` with ``--vtk`` wrote a .pvd/.vtm VTK cannot
    parse.  A short run of the example network (3 frames, bonds: .vtm frames)."""
    name = 'net&a"b<c'
    fibrenet_case(tmp_path, name)
    proc = cli(["-q", "run", "input.txt", "--also", "vtk"], tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    pvd = tmp_path / f"{name}.pvd"
    assert [t for t, _ in pvd_entries(pvd)] == ["0.0", "0.025", "0.05"]       # 50 x 0.0005 per frame
    frames = read_every_file(pvd)
    assert [f.GetNumberOfPoints() for f in frames] == [len(read_xyz(tmp_path / f"{name}_coord.xyz")[0].values)] * 3


@pytest.mark.parametrize("where", ["output", "column"])
def test_names_xml_cannot_hold_are_refused_before_writing(tmp_path, where):
    """A control character cannot be in an XML file at all (not even escaped)."""
    column = "c_a\x01b" if where == "column" else "c_ok"
    out = "out/r\x02un" if where == "output" else "out/run"
    p = write(tmp_path, frame(0, [r + (1.0,) for r in ROWS], cols=f"id type x y z {column}"))
    proc = cli(["post", p.name, "--to", "vtk", "-o", out], tmp_path)
    assert proc.returncode == 2, proc.stderr
    what = "output name 'r\\x02un'" if where == "output" else "array name 'c_a\\x01b'"
    assert f"{what} has a character a VTK XML file cannot hold" in proc.stderr
    assert listing(tmp_path) == ["d.dump"]


def test_run_vtk_output_name_xml_cannot_hold_is_refused_before_the_run(tmp_path):
    """Was refused only when the writer was made, after the work folder was written."""
    fibrenet_case(tmp_path, "net\x01x")
    proc = cli(["-q", "run", "input.txt", "--also", "vtk"], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "output name 'net\\x01x' has a character a VTK XML file cannot hold" in proc.stderr
    assert listing(tmp_path) == ["input.txt", "model.txt"]


# ------------------------------------------------------------- 7. .pvd times
def test_pvd_times_are_the_shortest_decimals(tmp_path):
    """Was: ``0.7999999999999999`` (LAMMPS's running sum of 8 x 0.1, or step x dt).  The
    times, rounded to 15 significant digits, are written in their shortest form, in the .pvd
    and as each frame's TimeValue."""
    times = [8 * 0.1 - 1e-16, 0.1 + 0.2, 1.23456789012345e-7, 7.0]
    assert repr(times[0]) == "0.7999999999999999" and repr(times[1]) == "0.30000000000000004"
    p = write(tmp_path, "".join(frame(s, ROWS, time=repr(t)) for s, t in enumerate(times)))
    proc = cli(["post", p.name, "--to", "vtk", "-o", "t"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    expected = ["0.8", "0.3", "1.23456789012345e-07", "7.0"]
    assert [t for t, _ in pvd_entries(tmp_path / "t.pvd")] == expected
    for k, particles in enumerate(read_every_file(tmp_path / "t.pvd")):
        assert vtk_array(particles.GetFieldData(), "TimeValue")[0] == float(expected[k])


# ------------------------------------------------------------- 6. output names
@pytest.mark.parametrize("to,out,written", [("musen", "run", "run.txt"), ("musen", "run.res", "run.res"),
                                            ("mdem", "run", "run.mdem"), ("mdem", "r.mdem", "r.mdem")])
def test_musen_results_get_their_usual_suffix(tmp_path, to, out, written):
    """Was: ``-o run`` wrote a file ``run``; MUSEN's text results are ``.txt`` files, its
    binary ones ``.mdem``; a name with a suffix is kept."""
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    p = write(tmp_path, frame(0, rows, cols=VEL_FORCE, time=0.0) + frame(10, rows, cols=VEL_FORCE, time=0.1))
    proc = cli(["post", p.name, "--to", to, "-o", out], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert f"wrote {written}" in proc.stdout
    assert listing(tmp_path) == sorted(["d.dump", written])
    again = cli(["post", p.name, "--to", to, "-o", out], tmp_path)     # --force guards that name
    assert again.returncode == 2 and f"error: {written}: output exists" in again.stderr


@pytest.mark.parametrize("to,out,written", [
    ("xyz", "m1", ["m1_coord.xyz", "m1_force.xyz", "m1_vel.xyz"]),
    ("xyz", "m1.xyz", ["m1_coord.xyz", "m1_force.xyz", "m1_vel.xyz"]),
    ("xyz", "m1_coord.xyz", ["m1_coord.xyz", "m1_force.xyz", "m1_vel.xyz"]),
    ("res", "m1.res", ["m1_restart.res"]), ("res", "m1_restart.res", ["m1_restart.res"])])
def test_fibrenet_names_given_with_their_own_suffix_are_the_base(tmp_path, to, out, written):
    """Was: ``-o m1.xyz`` wrote ``m1.xyz_coord.xyz``."""
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    p = write(tmp_path, frame(0, rows, cols=VEL_FORCE, time=0.0) + frame(10, rows, cols=VEL_FORCE, time=0.1))
    proc = cli(["post", p.name, "--to", to, "-o", out], tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert listing(tmp_path) == sorted(["d.dump", *written])


@pytest.mark.parametrize("args,message", [
    (["--to", "pdb", "-o", "x"], "--to 'pdb': unknown format (choose from "),
    (["-o", "x"], "choose an output with --to"),
    (["--to", "musen", "-o", "x", "--precision", "0"], "--precision must be 1..17, got 0")])
def test_option_errors_name_the_dump(tmp_path, args, message):
    """Was: ``error: <input>: --to 'pdb': unknown format``."""
    p = write(tmp_path, frame(0, ROWS))
    proc = cli(["post", p.name, *args], tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: d.dump: {message}"), proc.stderr


# ------------------------------------------------------------- 4. mpiexec -n 2 fibrelmp post
MPIEXEC = Path(sys.executable).parent / "mpiexec"
needs_mpi = pytest.mark.skipif(not MPIEXEC.exists(), reason="mpiexec not found (pip install mpich)")


def mpi_post(args: list, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, OMP_NUM_THREADS="1")
    return subprocess.run([str(MPIEXEC), "-n", "2", *CLI, "post", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=60, env=env, start_new_session=True)


def mpi_dump(tmp_path: Path) -> Path:
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    return write(tmp_path, "".join(frame(s, rows, cols=VEL_FORCE, time=s / 10) for s in range(0, 30, 10)))


@needs_mpi
def test_post_under_mpi_writes_once_on_rank_0(tmp_path):
    """Was: both ranks wrote (under load 8 of 8 ended 'output exists', half of them with only
    'Abort(2) on node 1'), and ``--info`` was printed by every rank.  Now rank 0 converts and
    writes, the other ranks wait: the serial conversion's files, said once."""
    p = mpi_dump(tmp_path)
    serial = post(p, "xyz", tmp_path / "serial" / "net")
    done = mpi_post([p.name, "--to", "xyz", "-o", "out/net"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert listing(tmp_path / "out") == sorted(f.name for f in serial)
    for f in serial:
        assert (tmp_path / "out" / f.name).read_bytes() == f.read_bytes()
    assert done.stdout.count("wrote out/net_coord.xyz") == 1
    info = mpi_post([p.name, "--info"], tmp_path)
    assert info.returncode == 0 and info.stdout.count("frames     3") == 1, info.stdout


@needs_mpi
def test_post_error_under_mpi_ends_every_rank_with_its_message(tmp_path):
    p = mpi_dump(tmp_path)
    written = post(p, "xyz", tmp_path / "out" / "net")
    before = {f: f.stat().st_mtime_ns for f in written}
    again = mpi_post([p.name, "--to", "xyz", "-o", "out/net"], tmp_path)
    assert again.returncode == 2, again.stderr
    assert again.stderr.count("error: out/net_coord.xyz: output exists; use --force to overwrite") == 1
    assert {f: f.stat().st_mtime_ns for f in written} == before


def test_the_mdanalysis_view_of_a_dump_bounds_its_lines_too(tmp_path):
    """``RunResult.universe()`` indexes a dump with its own line reader: same bound."""
    pytest.importorskip("MDAnalysis")
    from fibrelmp.errors import InputError
    from fibrelmp.post.lammps_dump.universe import dump_universe

    good = frame(0, ROWS, time=0.0) + frame(10, ROWS, time=0.5)
    universe = dump_universe(write(tmp_path, good, "good.dump"))
    assert [ts.time for ts in universe.trajectory] == [0.0, 0.5]
    long_line = "1 1 0.5 0.5 " + "5" * (MAX_LINE + 10) + "\n"
    third = frame(20, ROWS[:2]).replace("ITEM: NUMBER OF ATOMS\n2", "ITEM: NUMBER OF ATOMS\n3")
    p = write(tmp_path, good + third + long_line, "long.dump")
    line = len((good + third).splitlines()) + 1
    with pytest.raises(InputError, match=rf"long\.dump:{line}: line longer than 1 MiB"):
        dump_universe(p).trajectory.n_frames


def test_data_may_name_the_work_folder(tmp_path):
    """README: 'a run's frames.dump with --data of its work folder'.  Was: a folder given to
    --data was refused ('is a directory'); now its data.lammps is read."""
    work = tmp_path / "w"
    work.mkdir()
    (work / "data.lammps").write_text(
        "LAMMPS data\n\n5 atoms\n2 atom types\n\n0 10 xlo xhi\n0 10 ylo yhi\n0 10 zlo zhi\n\n"
        "Masses\n\n1 1.5\n2 2.5\n\nAtoms # atomic\n\n"
        + "".join(f"{i} {1 + i % 2} 0 0 0\n" for i in range(1, 6)))
    rows = [r + (0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 1.0) for r in ROWS]
    p = write(tmp_path, frame(0, rows, cols=VEL_FORCE, time=0.0) + frame(10, rows, cols=VEL_FORCE, time=0.1))
    by_file = cli(["post", p.name, "--to", "xyz", "-o", "a/n", "--data", "w/data.lammps"], tmp_path)
    by_folder = cli(["post", p.name, "--to", "xyz", "-o", "b/n", "--data", "w"], tmp_path)
    assert by_file.returncode == 0 == by_folder.returncode, by_folder.stderr
    assert listing(tmp_path / "a") == listing(tmp_path / "b")
    for name in listing(tmp_path / "a"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
