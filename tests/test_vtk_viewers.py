"""``fibrelmp run --also vtk`` and ``post --to vtk``: files ParaView and OVITO open.

Checked three ways: fibrelmp's own reader (always), VTK's XML readers (the library ParaView
is built on; the ``vtk`` wheel of the ``test`` extra) and OVITO's Python module (``ovito``,
optional: skipped when absent).  Expected numbers come from the inputs (times, radii,
masses), the work dumps LAMMPS wrote, the runs' own result files, and geometry computed
here, never from the writer.  (meshio reads VTK XML only as UnstructuredGrid, which OVITO
does not read as particles or meshes, so meshio opens none of these files.)
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.post.lammps_data.reader import read_data
from fibrelmp.post.lammps_dump import iter_frames
from fibrelmp.post.vtk import ViewerFrame, VtkWriter, bond_segments, read_frame, read_piece, read_pvd
from fibrelmp.post.vtk.writer import time_text

from .conftest import REPO

FIBRE = REPO / "examples" / "fibre_network"


# -- independent helpers -----------------------------------------------------------------------
def wrapped(x: np.ndarray, lo: np.ndarray, length: np.ndarray) -> np.ndarray:
    return lo + np.mod(x - lo, length)


def pieces_expected(xa, xb, lo, length):
    """Pieces of each bond in an orthogonal periodic box: 1 + the axes along which the
    minimum-image segment from a leaves the box."""
    d = xb - xa
    d -= length * np.round(d / length)
    end = xa + d
    return 1 + ((end < lo) | (end >= lo + length)).sum(axis=1)


def vtk_read(path: Path):
    """A file through VTK's own XML readers; any VTK error or warning fails the test."""
    xml = pytest.importorskip("vtkmodules.vtkIOXML", reason="VTK not installed (pip install vtk)")
    reader = xml.vtkXMLMultiBlockDataReader() if path.suffix == ".vtm" else xml.vtkXMLPolyDataReader()
    events: list[str] = []
    for kind in ("ErrorEvent", "WarningEvent"):
        reader.AddObserver(kind, lambda obj, event: events.append(event))
    reader.SetFileName(str(path))
    reader.Update()
    assert not events, f"VTK reports {events} for {path}"
    return reader.GetOutput()


def vtk_arrays(data) -> dict[str, np.ndarray]:
    from vtkmodules.util.numpy_support import vtk_to_numpy

    return {data.GetArrayName(k): vtk_to_numpy(data.GetArray(k)) for k in range(data.GetNumberOfArrays())}


def ovito_import(path: Path):
    io = pytest.importorskip("ovito.io", reason="OVITO's Python module not installed (pip install ovito)")
    return io.import_file(str(path))


# -- bond geometry ---------------------------------------------------------------------------
def test_bond_crossing_two_faces_is_cut_into_three_pieces():
    """Worked by hand: box 0..10, a = (9.8, 9.9, 5), b = (0.3, 0.2, 5); d = (0.5, 0.3, 0) meets
    y = 10 at t = 1/3 and x = 10 at t = 0.4."""
    seg = bond_segments(np.array([[9.8, 9.9, 5.0]]), np.array([[0.3, 0.2, 5.0]]), np.zeros(3),
                        np.eye(3) * 10, np.array([True, True, True]))
    x13 = 9.8 + 0.5 / 3
    np.testing.assert_allclose(seg.start, [[9.8, 9.9, 5], [x13, 0, 5], [0, 0.02, 5]], atol=1e-12)
    np.testing.assert_allclose(seg.end, [[x13, 10, 5], [10, 0.02, 5], [0.3, 0.2, 5]], atol=1e-12)
    assert seg.end[0, 1] == 10 and seg.start[1, 1] == 0 and seg.end[1, 0] == 10 and seg.start[2, 0] == 0
    assert list(seg.bond) == [0, 0, 0]


@pytest.mark.parametrize("tilt", [None, (1.5, -0.7, 0.4)])
def test_bond_pieces_lie_in_the_box_and_add_up_to_the_minimum_image(tilt):
    """Random bonds, periodic x and y: every piece is inside the cell, pieces end on a face
    or at the atoms, consecutive pieces continue across the face (whole cell vectors), and
    their vectors add up to the minimum-image bond vector."""
    rng = np.random.default_rng(7)
    xy, xz, yz = tilt or (0.0, 0.0, 0.0)
    cell = np.array([[4.0, xy, xz], [0.0, 3.0, yz], [0.0, 0.0, 5.0]])
    origin = np.array([-1.0, 2.0, 0.5])
    periodic = np.array([True, True, False])
    s_a, s_b = rng.random((400, 3)), rng.random((400, 3))
    xa, xb = origin + s_a @ cell.T, origin + s_b @ cell.T
    seg = bond_segments(xa, xb, origin, cell, periodic)
    inv = np.linalg.inv(cell)
    f0, f1 = (seg.start - origin) @ inv.T, (seg.end - origin) @ inv.T
    eps = 1e-9
    assert np.all((f0[:, :2] > -eps) & (f0[:, :2] < 1 + eps) & (f1[:, :2] > -eps) & (f1[:, :2] < 1 + eps))
    ds = s_b - s_a
    ds[:, :2] -= np.round(ds[:, :2])
    leaves = ((s_a + ds)[:, :2] < 0) | ((s_a + ds)[:, :2] >= 1)
    assert np.bincount(seg.bond, minlength=400).tolist() == (1 + leaves.sum(1)).tolist()
    assert leaves.any(1).sum() > 100                     # the case is exercised
    total = np.zeros((400, 3))
    np.add.at(total, seg.bond, f1 - f0)
    np.testing.assert_allclose(total, ds, atol=1e-12)
    first = np.r_[True, seg.bond[1:] != seg.bond[:-1]]
    last = np.r_[seg.bond[1:] != seg.bond[:-1], True]
    np.testing.assert_array_equal(seg.start[first], xa)    # the atoms themselves
    np.testing.assert_array_equal(seg.end[last], xb)
    inner = ~last
    step = f0[1:][inner[:-1]] - f1[:-1][inner[:-1]]       # next piece starts where this one left
    np.testing.assert_allclose(step, np.round(step), atol=1e-12)
    assert np.all(np.abs(np.round(step)).sum(1) >= 1)
    on_face = f1[inner][:, :2]
    assert np.all(np.any(np.isclose(on_face, 0, atol=1e-12) | np.isclose(on_face, 1, atol=1e-12), axis=1))


# -- FibreNet run ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def fibre_run(tmp_path_factory):
    import fibrelmp

    out = tmp_path_factory.mktemp("fibre")
    result = fibrelmp.run(FIBRE / "input.txt", out=out, also=["vtk"])
    return out, result


def test_fibrenet_run_writes_the_files_next_to_the_results(fibre_run):
    out, result = fibre_run
    names = [p.name for p in result.outputs]
    frames = [f"fibre_network_{k:06d}{tail}" for k in range(6) for tail in (".vtp", "_bonds.vtp", ".vtm")]
    assert sorted(names) == sorted(["fibre_network_coord.xyz", "fibre_network_vel.xyz",
                                    "fibre_network_force.xyz", "fibre_network_restart.res",
                                    "fibre_network.pvd", *frames])
    assert all(p.parent == out for p in result.outputs)
    assert not list(out.glob(".*tmp*"))


def test_fibrenet_frames_equal_the_run(fibre_run):
    """Positions (wrapped), ids, types, radii, masses, FibreNet's velocity and force; the .pvd
    times are step x dt (input.txt: output every 400 of 2000 steps, step 0.0005)."""
    out, result = fibre_run
    beads = [ln.split() for ln in (FIBRE / "model.txt").read_text().splitlines() if ln.startswith("BEAD")]
    type_number = {"F1": 1, "F2": 2}                     # input.txt's type lines, in order
    radius = np.array([float(b[4]) for b in beads])
    mass = np.array([float(b[5]) for b in beads])
    types = np.array([type_number[b[1]] for b in beads])
    entries = read_pvd(out / "fibre_network.pvd")
    assert [t for t, _ in entries] == pytest.approx([k * 400 * 0.0005 for k in range(6)], rel=1e-12)
    dumps = list(iter_frames(result.dumps[0]))
    assert len(dumps) == 6
    for (_, vtm), dump in zip(entries, dumps):
        blocks = read_frame(vtm)
        v = blocks["Particles"]
        ids = dump.column("id").astype(np.int64)
        np.testing.assert_array_equal(v.point_data["id"], ids)
        rows = ids - 1
        np.testing.assert_allclose(v.points, wrapped(dump.vector("x", "y", "z"), dump.lo, dump.lengths),
                                   rtol=0, atol=1e-12)
        vel = ("vx", "vy", "vz") if dump.has("vx") else ("v_fn_vx", "v_fn_vy", "v_fn_vz")
        force = ("fx", "fy", "fz") if dump.has("fx") else ("v_fn_fx", "v_fn_fy", "v_fn_fz")
        np.testing.assert_array_equal(v.point_data["Velocity"], dump.vector(*vel))
        np.testing.assert_array_equal(v.point_data["Force"], dump.vector(*force))
        np.testing.assert_array_equal(v.point_data["Radius"], radius[rows])
        np.testing.assert_array_equal(v.point_data["Mass"], mass[rows])
        np.testing.assert_array_equal(v.point_data["type"], types[rows])
        assert v.point_data["Velocity"].shape == (128, 3) and v.point_data["type"].dtype == np.int32
        assert v.attributes["NumberOfVerts"] == "128" and v.step == dump.step


def test_fibrenet_bonds_across_the_periodic_box_are_drawn_in_pieces(fibre_run):
    """Every spring is drawn: its pieces' vectors add up to the minimum-image spring, and the
    number of lines is 120 plus one per face a spring crosses."""
    out, result = fibre_run
    springs = read_data(result.dumps[0].parent / "data.lammps").bonds
    assert len(springs) == 120
    split = []
    for (_, vtm), dump in zip(read_pvd(out / "fibre_network.pvd"), iter_frames(result.dumps[0])):
        lines = read_frame(vtm)["Bonds"]
        lo, length = dump.lo, dump.lengths
        x = wrapped(dump.vector("x", "y", "z"), lo, length)
        row = {int(i): k for k, i in enumerate(dump.column("id"))}
        xa = x[[row[int(i)] for i in springs[:, 0]]]
        xb = x[[row[int(i)] for i in springs[:, 1]]]
        expected = pieces_expected(xa, xb, lo, length)
        assert int(lines.attributes["NumberOfLines"]) == expected.sum()
        split.append(int((expected > 1).sum()))
        pairs = np.column_stack([lines.cell_data["id1"], lines.cell_data["id2"]])
        np.testing.assert_array_equal(np.unique(pairs, axis=0), np.unique(springs, axis=0))
        p = lines.points.reshape(-1, 2, 3)
        assert np.all((p >= lo - 1e-12) & (p <= lo + length + 1e-12))        # inside the box
        d = xb - xa
        d -= length * np.round(d / length)
        total: dict[tuple[int, int], np.ndarray] = {}
        for (a, b), vec in zip(pairs.tolist(), p[:, 1] - p[:, 0]):
            total[(a, b)] = total.get((a, b), 0) + vec
        np.testing.assert_allclose([total[(a, b)] for a, b in springs.tolist()], d, atol=1e-12)
        ends = p.reshape(-1, 3)
        off_atoms = np.linalg.norm(ends[:, None] - x[None], axis=2).min(axis=1) > 1e-9
        on_face = np.any(np.isclose(ends, lo, rtol=0, atol=1e-12) |
                         np.isclose(ends, lo + length, rtol=0, atol=1e-12), axis=1)
        assert np.all(on_face[off_atoms]) and off_atoms.sum() == 2 * (expected.sum() - 120)
    assert max(split) >= 8                               # the example's fibres do cross the box


def test_fibrenet_files_open_in_vtk(fibre_run):
    out, result = fibre_run
    dump = list(iter_frames(result.dumps[0]))[-1]
    vtm = read_pvd(out / "fibre_network.pvd")[-1][1]
    multi = vtk_read(vtm)
    assert multi.GetNumberOfBlocks() == 2
    particles, bonds = multi.GetBlock(0), multi.GetBlock(1)
    assert particles.GetNumberOfPoints() == 128 and particles.GetNumberOfVerts() == 128
    assert particles.GetNumberOfLines() == 0 and bonds.GetNumberOfVerts() == 0
    assert bonds.GetNumberOfLines() == int(read_frame(vtm)["Bonds"].attributes["NumberOfLines"])
    point = vtk_arrays(particles.GetPointData())
    assert {"id", "type", "Radius", "Mass", "Velocity", "Force", "fibre"} <= set(point)
    assert point["Velocity"].shape == (128, 3) and point["id"].dtype == np.int64
    vel = ("vx", "vy", "vz") if dump.has("vx") else ("v_fn_vx", "v_fn_vy", "v_fn_vz")
    np.testing.assert_array_equal(point["Velocity"], dump.vector(*vel))
    from vtkmodules.util.numpy_support import vtk_to_numpy

    np.testing.assert_allclose(vtk_to_numpy(particles.GetPoints().GetData()),
                               wrapped(dump.vector("x", "y", "z"), dump.lo, dump.lengths), atol=1e-12)
    assert vtk_arrays(particles.GetFieldData())["TimeValue"][0] == pytest.approx(2000 * 0.0005)
    cells = vtk_arrays(bonds.GetCellData())
    assert set(cells) == {"id1", "id2"} and len(cells["id1"]) == bonds.GetNumberOfLines()
    single = vtk_read(vtm.with_suffix(".vtp"))                # the particles file alone
    assert single.GetNumberOfVerts() == 128


def test_fibrenet_files_open_in_ovito(fibre_run):
    """OVITO 3.17 takes the .pvd: particles with its standard properties, the bonds as
    lines, the simulation time."""
    out, result = fibre_run
    pipeline = ovito_import(out / "fibre_network.pvd")
    assert pipeline.num_frames == 6
    dumps = list(iter_frames(result.dumps[0]))
    for k in (0, 5):
        data = pipeline.compute(k)
        particles = data.particles
        assert particles.count == 128
        assert data.attributes["Time"] == pytest.approx(k * 400 * 0.0005)
        ids = np.asarray(particles.identifiers)
        order = np.argsort(ids)
        dump = dumps[k]
        vel = ("vx", "vy", "vz") if dump.has("vx") else ("v_fn_vx", "v_fn_vy", "v_fn_vz")
        np.testing.assert_array_equal(ids[order], dump.column("id"))
        np.testing.assert_array_equal(np.asarray(particles.velocities)[order], dump.vector(*vel))
        np.testing.assert_allclose(np.asarray(particles.positions)[order],
                                   wrapped(dump.vector("x", "y", "z"), dump.lo, dump.lengths), atol=1e-12)
        radius = [float(b.split()[4]) for b in (FIBRE / "model.txt").read_text().splitlines()
                  if b.startswith("BEAD")]
        np.testing.assert_allclose(np.asarray(particles["Radius"])[order], radius, rtol=1e-7)  # float32
        lines = [o for o in data.objects if type(o).__name__ == "Lines"]
        assert len(lines) == 1
        bonds = read_frame(read_pvd(out / "fibre_network.pvd")[k][1])["Bonds"]
        np.testing.assert_allclose(np.asarray(lines[0]["Position"]), bonds.points, atol=1e-12)


def test_run_vtk_needs_force_for_earlier_frames_and_removes_them(tmp_path):
    """Frame files of an earlier run are results like the others: refused without --force,
    removed when the new run (with fewer frames) succeeded."""
    from typer.testing import CliRunner

    from fibrelmp.cli import app

    stale = tmp_path / "fibre_network_000009.vtp"
    stale.write_text("earlier run")
    runner = CliRunner()
    args = ["run", str(FIBRE / "input.txt"), "-o", str(tmp_path), "--also", "vtk"]
    refused = runner.invoke(app, args)
    assert refused.exit_code == 2 and "fibre_network_000009.vtp: exists already" in refused.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fibre_network_000009.vtp"]
    done = runner.invoke(app, [*args, "--force"])
    assert done.exit_code == 0, done.output
    assert not stale.exists()
    assert re.search(r"wrote .*fibre_network_000000_bonds\.vtp \.\. fibre_network_000005_bonds\.vtp "
                     r"\(6 files\)", done.stdout)
    assert len(list(tmp_path.glob("fibre_network_*.vtp"))) == 12


# -- granular runs ---------------------------------------------------------------------------
def have(module: str) -> bool:
    from importlib.util import find_spec

    try:
        return find_spec(module) is not None
    except ModuleNotFoundError:
        return False


def test_demdf_run_frames_equal_the_snapshots(tmp_path):
    """head_on.json: no bonds, so the .pvd lists the particle files; every frame equals the
    DEMDF snapshot saved at the same time (time, positions, velocities, type)."""
    import fibrelmp

    spec = json.loads((REPO / "examples" / "demdf" / "head_on.json").read_text())
    shutil.copy(REPO / "examples" / "demdf" / "head_on.json", tmp_path)
    fibrelmp.run(tmp_path / "head_on.json", also=["vtk"])
    entries = read_pvd(tmp_path / "head_on.pvd")
    period = spec["output"]["snapshot"]["savePeriodInTime"]
    assert [t for t, _ in entries] == pytest.approx([k * period for k in range(9)])
    kind = spec["objectTypes"][0]
    for k, (t, path) in enumerate(entries):
        assert path.name == f"head_on_{k:06d}.vtp"
        snap = json.loads((tmp_path / f"head_on_{k}.json").read_text())
        assert snap["time"] == pytest.approx(t)
        rows = np.array(snap["objects"]["particles"])
        v = read_frame(path)["Particles"]
        np.testing.assert_array_equal(v.point_data["id"], [0, 1])       # DEMDF: array index
        np.testing.assert_array_equal(v.points, rows[:, 0:3])
        np.testing.assert_array_equal(v.point_data["Velocity"], rows[:, 3:6])
        np.testing.assert_array_equal(v.point_data["type"], rows[:, 6] + 1)
        np.testing.assert_array_equal(v.point_data["Radius"], [kind["radius"]] * 2)
        np.testing.assert_array_equal(v.point_data["Mass"], [kind["mass"]] * 2)
        np.testing.assert_array_equal(v.point_data["Orientation"], [[0, 0, 0, 1]] * 2)
        assert v.point_data["Angular Velocity"].shape == (2, 3)
        if have("vtkmodules"):
            assert vtk_read(path).GetNumberOfVerts() == 2


@pytest.fixture(scope="module")
def agglomerate_run(tmp_path_factory):
    """The agglomerate cmusen script (5696 spheres, 18800 bonds, 6 frames; about 3 s)."""
    import fibrelmp

    folder = tmp_path_factory.mktemp("agglo")
    for name in ("agglomerate_short_job.txt", "SphericalAgglomerate_text.txt"):
        shutil.copy(REPO / "examples" / "musen" / name, folder)
    result = fibrelmp.run(folder / "agglomerate_short_job.txt", also=["vtk"])
    alive = [f.count for f in iter_frames(result.dumps[-1].parent / "bonds.dump")]
    return folder, read_pvd(folder / "agglomerate_short_result.pvd"), alive


def test_musen_script_bonds_are_the_alive_bonds(agglomerate_run):
    """The SIMULATOR job's files are named after its RESULT_FILE; every frame draws as many
    lines as LAMMPS dumped alive bonds, each from the centre of its id1 sphere to that of
    its id2 sphere (no periodic box)."""
    folder, entries, alive = agglomerate_run
    # cmusen's save times: every 5e-7 s, then the step whose summed time reaches END_TIME
    assert [t for t, _ in entries] == pytest.approx([k * 5e-7 for k in range(5)] + [2.01e-6], rel=1e-9)
    assert len(alive) == 6 and alive[0] > 18000
    for (_, vtm), count in zip(entries, alive):
        assert vtm.name.startswith("agglomerate_short_result_")
        blocks = read_frame(vtm)
        v, lines = blocks["Particles"], blocks["Bonds"]
        assert int(lines.attributes["NumberOfLines"]) == count
        where = {int(i): k for k, i in enumerate(v.point_data["id"])}
        p = lines.points.reshape(-1, 2, 3)
        np.testing.assert_array_equal(p[:, 0], v.points[[where[int(i)] for i in lines.cell_data["id1"]]])
        np.testing.assert_array_equal(p[:, 1], v.points[[where[int(i)] for i in lines.cell_data["id2"]]])
        assert lines.cell_data["Force"].shape == (count, 3)
        q = v.point_data["Orientation"]
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1, rtol=1e-12)


def test_musen_script_files_open_in_vtk(agglomerate_run):
    folder, entries, alive = agglomerate_run
    multi = vtk_read(entries[-1][1])
    assert multi.GetBlock(1).GetNumberOfLines() == alive[-1]
    particles = multi.GetBlock(0)
    assert particles.GetNumberOfVerts() == particles.GetNumberOfPoints() > 5000
    assert vtk_arrays(particles.GetPointData())["Orientation"].shape == (particles.GetNumberOfPoints(), 4)


def test_musen_script_files_open_in_ovito(agglomerate_run):
    folder, entries, alive = agglomerate_run
    pipeline = ovito_import(folder / "agglomerate_short_result.pvd")
    assert pipeline.num_frames == 6
    data = pipeline.compute(5)
    v = read_frame(entries[-1][1])["Particles"]
    assert data.particles.count == len(v.points)
    np.testing.assert_array_equal(np.asarray(data.particles.identifiers), v.point_data["id"])
    np.testing.assert_array_equal(np.asarray(data.particles.orientations), v.point_data["Orientation"])
    assert [o.count for o in data.objects if type(o).__name__ == "Lines"] == [2 * alive[-1]]
    assert data.attributes["Time"] == pytest.approx(4 * 5e-7)


# -- the writer ---------------------------------------------------------------------------------
def test_ascii_and_binary_files_hold_the_same_numbers(tmp_path):
    """A hand-made frame in both encodings: fibrelmp's reader (and VTK, if installed) read
    the same arrays; quaternions keep OVITO's X Y Z W component names."""
    rng = np.random.default_rng(3)
    frame = ViewerFrame(7, 0.125, np.array([5, 2, 9]), rng.random((3, 3)) * 4, np.zeros(3),
                        np.eye(3) * 4, np.array([True, False, True]),
                        {"type": np.array([1, 2, 1], np.int32), "Radius": np.array([0.1, 0.2, 0.3]),
                         "Orientation": rng.random((3, 4))},
                        np.array([[5, 9], [2, 5]]), {"Force": rng.random((2, 3))})
    for ascii_ in (False, True):
        w = VtkWriter(tmp_path / f"f{int(ascii_)}", ascii_=ascii_, bonded=True)
        w.add(frame)
        w.close()
    a, b = read_frame(tmp_path / "f0_000000.vtm"), read_frame(tmp_path / "f1_000000.vtm")
    for block in ("Particles", "Bonds"):
        np.testing.assert_array_equal(a[block].points, b[block].points)
        for name in a[block].point_data:
            np.testing.assert_array_equal(a[block].point_data[name], b[block].point_data[name])
        for name in a[block].cell_data:
            np.testing.assert_array_equal(a[block].cell_data[name], b[block].cell_data[name])
    np.testing.assert_array_equal(a["Particles"].points, frame.positions)
    np.testing.assert_array_equal(a["Bonds"].cell_data["Force"], frame.bond_data["Force"])
    assert a["Particles"].time == 0.125 and b["Particles"].step == 7
    text = (tmp_path / "f0_000000.vtp").read_text()
    assert text.startswith('<?xml version="1.0"?>\n<VTKFile type="PolyData"')
    assert 'Name="Orientation" NumberOfComponents="4" ComponentName0="X" ComponentName1="Y" ' \
           'ComponentName2="Z" ComponentName3="W"' in text
    if not have("vtkmodules"):
        return
    for stem in ("f0", "f1"):
        multi = vtk_read(tmp_path / f"{stem}_000000.vtm")
        np.testing.assert_array_equal(vtk_arrays(multi.GetBlock(0).GetPointData())["Orientation"],
                                      frame.point_data["Orientation"])


def test_a_frame_without_bonds_has_an_empty_bonds_block(tmp_path):
    """All bonds broken (or their atoms gone): the frame's .vtm keeps a Bonds block without a
    file (an empty bonds file would read as zero particles in OVITO); numpy times are
    written as numbers."""
    x = np.array([[1.0, 1, 1], [2, 1, 1]])
    box = (np.zeros(3), np.eye(3) * 10, np.array([True, True, True]))
    w = VtkWriter(tmp_path / "b", bonded=True)
    w.add(ViewerFrame(np.int64(3), np.float64(0.5), np.array([1, 2]), x, *box, {}, None))
    w.add(ViewerFrame(4, 1.5, np.array([1, 2]), x, *box, {}, np.array([[1, 2]])))
    w.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "b.pvd", "b_000000.vtm", "b_000000.vtp", "b_000001.vtm", "b_000001.vtp", "b_000001_bonds.vtp"]
    assert 'timestep="0.5"' in (tmp_path / "b.pvd").read_text()
    assert '<DataSet index="1" name="Bonds"/>' in (tmp_path / "b_000000.vtm").read_text()
    assert set(read_frame(tmp_path / "b_000000.vtm")) == {"Particles"}
    assert set(read_frame(tmp_path / "b_000001.vtm")) == {"Particles", "Bonds"}
    if have("vtkmodules"):
        multi = vtk_read(tmp_path / "b_000000.vtm")
        assert multi.GetNumberOfBlocks() == 2 and multi.GetBlock(1) is None
        assert multi.GetBlock(0).GetNumberOfPoints() == 2
    if have("ovito"):
        pipeline = ovito_import(tmp_path / "b.pvd")
        assert [pipeline.compute(k).particles.count for k in range(2)] == [2, 2]


def test_musen_walls_are_a_polydata_series_vtk_and_ovito_open(tmp_path):
    """A MUSEN run with walls: ``<stem>_walls.pvd`` lists a PolyData file of the wall
    triangles (polygons) per frame, as OVITO reads a surface mesh; read by fibrelmp's reader,
    VTK's PolyData reader and OVITO (when installed); its points are the result's wall
    vertices at the same time, read from the run's own .mdem result."""
    from fibrelmp import python_api
    from fibrelmp.translate.musen.mdem.model import MdemReader

    scene = tmp_path / "SingelParticle.mdem"
    shutil.copy(REPO / "examples" / "musen" / "SingelParticle.mdem", scene)
    python_api.run(scene, end_time=2e-3, step=1e-7, save_step=1e-3, also=["vtk"])
    series = read_pvd(tmp_path / "SingelParticle_result_walls.pvd")
    frames = list(MdemReader(tmp_path / "SingelParticle_result.mdem"))
    # the .pvd writes times to 15 digits (post/vtk/writer.py time_text)
    assert [t for t, _ in series] == [float(time_text(f.time)) for f in frames]
    for (time, path), frame in zip(series, frames):
        assert path.name.endswith("_walls.vtp")
        piece = read_piece(path)
        assert piece.kind == "PolyData" and piece.attributes["NumberOfPolys"] == "12"
        np.testing.assert_array_equal(piece.cells["Polys"]["connectivity"], np.arange(36))
        np.testing.assert_array_equal(piece.cells["Polys"]["offsets"], 3 * np.arange(1, 13))
        np.testing.assert_array_equal(piece.points.reshape(12, 3, 3), frame.triangle_vertices)
        assert piece.cell_data["Velocity"].shape == (12, 3)
        if have("vtkmodules"):
            mesh = vtk_read(path)
            assert mesh.GetNumberOfPolys() == 12 and mesh.GetNumberOfCells() == 12
            assert all(mesh.GetCellType(k) == 5 for k in range(12))       # VTK_TRIANGLE
            np.testing.assert_array_equal(vtk_arrays(mesh.GetCellData())["Velocity"].shape, (12, 3))
    if have("ovito"):
        pipeline = ovito_import(tmp_path / "SingelParticle_result_walls.pvd")
        assert sum(mesh.faces.count for mesh in pipeline.compute(0).surfaces.values()) == 12
