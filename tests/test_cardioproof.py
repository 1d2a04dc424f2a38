"""CardioProof coupling on LAMMPS: the piston-tube case (examples/cardioproof/).

A tube closed by a piston driven by ``.dynpt`` frames, filled with SPH water, outlet at
pressure p(t).  Every expected number is computed here from the mesh, the motion and the case
table with numpy (``fibrelmp.mesh.outflow`` is the numpy reference of the outflow law):

* the outflow force LAMMPS applied at every step equals -p(t) A n to 1e-12;
* the near particles and their weights equal the numpy rule's at every saved frame (a particle
  at half the search distance gets half the weight of one on the opening's plane);
* the moving wall particles are where the moving mesh puts them at every saved frame;
* the steady outflow is the piston area x the piston speed within 5 % (both estimates);
* ``fibrelmp translate`` + the stock ``lmp`` executable replay the run byte for byte
  (tests/test_lmp_replay.py);
* bad case files are ``path: message`` input errors.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.mesh.opencarp.dynpt import DynptReader
from fibrelmp.mesh.opencarp.mesh import OpenCarpMeshReader
from fibrelmp.mesh.outflow import Opening, share, triangles_of
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.registry import detect

from .conftest import REPO

EXAMPLE = REPO / "examples" / "cardioproof"
sys.path.insert(0, str(EXAMPLE))
import make_piston_tube as piston  # noqa: E402

SPEED, RAMP = 0.1, 4.0e-3           # the generator's defaults, which the example uses


def _copy(tmp: Path) -> Path:
    for f in ("piston_tube.json", "piston_tube.pts", "piston_tube.elem", "piston_tube.dynpt"):
        shutil.copy(EXAMPLE / f, tmp)
    return tmp / "piston_tube.json"


@pytest.fixture(scope="module")
def piston_run(tmp_path_factory):
    """The example run with the outflow series at every step."""
    tmp = tmp_path_factory.mktemp("piston")
    case = _copy(tmp)
    doc = json.loads(case.read_text())
    doc["output"]["series_interval"] = 1e-9                  # rounded up to every step
    case.write_text('{"cardioproof": 1,\n' + json.dumps({k: v for k, v in doc.items() if k != "cardioproof"})[1:])
    result = python_api.run(case)
    return tmp, result


def _outlet(tmp: Path) -> tuple[Opening, np.ndarray]:
    """The outlet as the numpy reference sees it: tag-3 triangles of the mesh, in metres,
    turned to face out of the tube (+z); and its pressure table."""
    t = triangles_of(*_tagged(tmp, 3))
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    t[n[:, 2] < 0] = t[n[:, 2] < 0][:, [0, 2, 1]]
    table = np.array(json.loads((tmp / "piston_tube.json").read_text())["openings"][0]["pressure"])
    return Opening(t), table


def _tagged(tmp: Path, tag: int) -> tuple[np.ndarray, list]:
    """(the nodes in metres where the motion starts: the .dynpt's first frame, float32 µm;
    the triangle block of the elements with region ``tag``)."""
    mesh = OpenCarpMeshReader(tmp / "piston_tube.pts").read()
    nodes = np.concatenate([b.nodes[b.tags == tag] for b in mesh.cells if b.kind == "triangle"])
    start = next(iter(DynptReader(tmp / "piston_tube.dynpt"))).points * 1e-6
    return start, [("triangle", nodes)]


def test_detected_as_a_case_not_as_demdf(tmp_path):
    case = _copy(tmp_path)
    assert detect(case).name == "cardioproof"
    other = tmp_path / "other.json"
    other.write_text('{"objects": {"cardioproof": 1}}')
    assert detect(other).name == "demdf"


def test_outflow_force_is_minus_p_a_n_at_every_step(piston_run):
    tmp, result = piston_run
    opening, table = _outlet(tmp)
    rows = np.genfromtxt(tmp / "piston_tube_outlet.csv", delimiter=",", names=True)
    steps = result.summaries[0]["steps"]["total"]
    assert len(rows) == steps + 1                            # step 0 and every step after it
    t = rows["time_s"]
    np.testing.assert_allclose(t, np.arange(steps + 1) * result.summaries[0]["time_step"], rtol=1e-12)
    p = np.interp(t, table[:, 0], table[:, 1])
    np.testing.assert_allclose(rows["pressure_Pa"], p, rtol=1e-12, atol=1e-12 * abs(p).max())
    expected = -p[:, None] * opening.area * opening.normal[None, :]
    got = np.column_stack([rows["force_x_N"], rows["force_y_N"], rows["force_z_N"]])
    scale = abs(expected).max()
    assert np.all(rows["near_particles"] > 0)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * scale)
    np.testing.assert_allclose(rows["force_normal_N"], -p * opening.area, rtol=1e-12, atol=1e-12 * scale)
    # the outlet is the 24-gon inscribed in the tube's radius 1 mm (float32 µm nodes)
    assert abs(opening.area / (12 * (1e-3) ** 2 * math.sin(2 * math.pi / 24)) - 1) < 1e-6


def test_near_particles_and_weights_are_the_numpy_rule(piston_run):
    tmp, _ = piston_run
    opening, _ = _outlet(tmp)
    d = 2 * 1.25e-4
    checked = 0
    for f in iter_frames(tmp / "piston_tube_work" / "frames.dump"):
        x = np.column_stack([f.columns["x"], f.columns["y"], f.columns["z"]])
        lammps = f.columns["v_share_outlet"]
        ref = share(opening, x, d, 1.0)
        assert set(np.flatnonzero(lammps > 0)) <= set(ref.rows.tolist())
        weights = np.zeros(len(x))
        weights[ref.rows] = ref.weight
        np.testing.assert_allclose(lammps, weights, rtol=1e-12, atol=1e-12)
        # half the search distance behind the plane: half the weight of a particle on it
        delta = 2e-3 - x[ref.rows, 2]
        np.testing.assert_allclose(weights[ref.rows], 1 - delta / d, rtol=1e-12, atol=1e-12)
        checked += len(ref.rows)
    assert checked > 1000


def test_moving_wall_particles_follow_the_mesh(piston_run):
    """The piston's wall particles are the piston mesh's points (moved by the frames) at every
    save: the motion from the .dynpt, linear between frames, exactly."""
    tmp, _ = piston_run
    frames = list(DynptReader(tmp / "piston_tube.dynpt"))
    first = frames[0].points * 1e-6
    dz = np.array([(fr.points[:, 2] * 1e-6 - first[:, 2]).max() for fr in frames])
    times = np.arange(len(frames)) * 5e-4
    np.testing.assert_allclose(dz, piston.piston_position(times, SPEED, RAMP), atol=1e-9)   # float32 frames
    walls = list(iter_frames(tmp / "piston_tube_work" / "moving_walls.dump"))
    z0 = walls[0].columns["z"]
    for w in walls:
        shift = np.interp(w.time, times, dz)
        np.testing.assert_allclose(w.columns["z"] - z0, shift, atol=1e-13)
        np.testing.assert_allclose(w.columns["x"], walls[0].columns["x"], atol=1e-15)
    # no fluid behind the piston's face
    for f, w in zip(iter_frames(tmp / "piston_tube_work" / "frames.dump"), walls):
        face = np.interp(f.time, times, dz)
        assert f.columns["z"].min() > face


def test_steady_outflow_is_piston_area_times_speed(piston_run):
    tmp, result = piston_run
    rows = np.genfromtxt(tmp / "piston_tube_outlet.csv", delimiter=",", names=True)
    t = triangles_of(*_tagged(tmp, 2))
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
    q = area * SPEED
    steady = rows["time_s"] >= 5e-3                            # a millisecond after the ramp
    velocity = rows["flux_velocity_m3_s"][steady].mean()
    tt, crossed = rows["time_s"][steady], rows["crossed_particles"][steady]
    per_second = np.polyfit(tt, crossed, 1)[0]
    summary = result.summaries[0]
    volume = summary["openings"]["outlet"]["crossed_volume"] / summary["openings"]["outlet"]["crossed_particles"]
    # the particle volume is the tube's volume over the fluid count
    np.testing.assert_allclose(volume * summary["particles"]["fluid_start"], area * 2e-3, rtol=1e-12)
    crossing = per_second * volume
    # every fluid particle is still in the tube or left by the outlet
    assert summary["particles"]["fluid_start"] == (summary["particles"]["fluid_end"]
                                                   + summary["openings"]["outlet"]["crossed_particles"])
    print(f"steady outflow / (A u): velocity estimate {velocity / q:.4f}, crossing estimate {crossing / q:.4f}")
    assert abs(velocity / q - 1) < 0.05
    assert abs(crossing / q - 1) < 0.05


def test_vtk_frames_open_with_vtk(piston_run):
    """Fluid and walls are PolyData (vertices; triangles as polygons), which VTK, ParaView
    and OVITO read."""
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    tmp, _ = piston_run
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp / "piston_tube_000003.vtp"))
    reader.Update()
    data = reader.GetOutput().GetPointData()
    arrays = {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)) for i in range(data.GetNumberOfArrays())}
    assert {"Velocity", "Density", "Pressure", "outflow_weight_outlet"} <= set(arrays)
    rho = arrays["Density"]
    np.testing.assert_allclose(arrays["Pressure"], 5.0 ** 2 * 1000 / 7 * ((rho / 1000) ** 7 - 1),
                               rtol=1e-12, atol=1e-9)
    walls = vtk.vtkXMLPolyDataReader()
    walls.SetFileName(str(tmp / "piston_tube_000003_walls.vtp"))
    walls.Update()
    mesh = OpenCarpMeshReader(tmp / "piston_tube.pts").read()
    triangles = sum(len(b.nodes) * (2 if b.kind == "quad" else 1) for b in mesh.cells)
    assert walls.GetOutput().GetNumberOfPolys() == triangles
    opening = vtk_to_numpy(walls.GetOutput().GetCellData().GetArray("opening"))
    assert set(np.unique(opening)) == {-1, 0}


def _bad(tmp: Path, edit) -> Path:
    case = _copy(tmp)
    doc = json.loads(case.read_text())
    edit(doc)
    case.write_text('{"cardioproof": 1,\n' + json.dumps({k: v for k, v in doc.items() if k != "cardioproof"})[1:])
    return case


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.update(fluids=1), "fluids: unknown key"),
    (lambda d: d["openings"][0].update(tags=[9]), "selects no shell element"),
    (lambda d: d["run"].update(end_time=1.0), "beyond the last motion frame"),
    (lambda d: d["fluid"].update(viscosity=1e-3), "either viscosity"),
    (lambda d: d["openings"][0].update(name="out let"), "cannot be used in a LAMMPS script"),
    (lambda d: d["openings"].append({"name": "again", "tags": [3]}), "shares elements with an earlier opening"),
    (lambda d: d.update(openings=[{"tags": [1, 2, 3]}]), "there is no wall"),
])
def test_bad_cases_are_input_errors(tmp_path, edit, message):
    case = _bad(tmp_path, edit)
    before = set(tmp_path.rglob("*"))
    with pytest.raises(InputError) as err:
        python_api.run(case)
    assert str(err.value).startswith(str(case)) and message in str(err.value), str(err.value)
    assert set(tmp_path.rglob("*")) == before


def test_fluid_lost_through_a_wall_is_a_warning(piston_run):
    """The summary's balance: fluid at the start = in the cavity + crossed an opening; the rest
    went through a wall (LAMMPS drops it at the box's faces) and is warned about."""
    from fibrelmp.translate.cardioproof.case import read_case
    from fibrelmp.translate.cardioproof.job import plan_job
    from fibrelmp.translate.cardioproof.input import SphRecorder

    tmp, _ = piston_run
    case = read_case(tmp / "piston_tube.json")
    plan = plan_job(case)

    class Job:
        fluid_count, wall_count = len(plan["fluid"]), len(plan["walls"].rows)
        openings = plan["openings"]

    class Lammps:
        def __init__(self, atoms, crossed):
            self.atoms, self.crossed = atoms, crossed

        def extract_global(self, name):
            return 100

        def get_natoms(self):
            return self.atoms

        def extract_variable(self, name):
            return self.crossed if name.startswith("crossed_") else 3.0

    balanced = SphRecorder(case, Job())
    balanced.end(Lammps(Job.wall_count + Job.fluid_count - 40 + 3, 40.0), 100, 0)   # 3 still in front
    assert not [w for w in case.warnings if w[0] == "fluid lost"]
    leaking = SphRecorder(case, Job())
    leaking.end(Lammps(Job.wall_count + Job.fluid_count - 47 + 3, 40.0), 100, 0)
    lost = [text for kind, text in case.warnings if kind == "fluid lost"]
    assert len(lost) == 1 and lost[0].startswith("7 fluid particles went through the wall")


@pytest.fixture(scope="module")
def moving_outlet_run(tmp_path_factory):
    """The piston tube whose outlet (and the tube's last ring) moves out at 0.02 m/s."""
    tmp = tmp_path_factory.mktemp("moving")
    assert piston.main(["--out", str(tmp), "--outlet-speed", "0.02", "--end", "8e-3"]) == 0
    return tmp, python_api.run(tmp / "piston_tube.json")


def test_a_moving_opening_is_placed_where_the_mesh_is_each_interval(moving_outlet_run):
    """Each motion interval the outlet's regions are put where the mesh is halfway through the
    interval: at every saved frame the near particles and weights equal the numpy rule for the
    outlet there; the force stays -p(t) A n; the velocity estimate is relative to the outlet."""
    tmp, result = moving_outlet_run
    frames = [f.points * 1e-6 for f in DynptReader(tmp / "piston_tube.dynpt")]
    _, [(_, nodes)] = _tagged(tmp, 3)
    intervals = len(frames) - 1
    steps_per_frame = round(5e-4 / result.summaries[0]["time_step"])
    checked = 0
    for f in iter_frames(tmp / "piston_tube_work" / "frames.dump"):
        k = min(f.step // steps_per_frame, intervals - 1)
        mid = 0.5 * (frames[k] + frames[k + 1])
        t = triangles_of(mid, [("triangle", nodes)])
        up = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2] < 0
        t[up] = t[up][:, [0, 2, 1]]
        x = np.column_stack([f.columns["x"], f.columns["y"], f.columns["z"]])
        ref = share(Opening(t), x, 2 * 1.25e-4, 1.0)
        weights = np.zeros(len(x))
        weights[ref.rows] = ref.weight
        np.testing.assert_allclose(f.columns["v_share_outlet"], weights, rtol=1e-12, atol=1e-12)
        assert abs(t[:, :, 2].mean() - (2e-3 + 0.02 * (k + 0.5) * 5e-4)) < 1e-9
        checked += len(ref.rows)
    assert checked > 1000
    rows = np.genfromtxt(tmp / "piston_tube_outlet.csv", delimiter=",", names=True)
    opening, table = _outlet(tmp)
    p = np.interp(rows["time_s"], table[:, 0], table[:, 1])
    np.testing.assert_allclose(rows["force_normal_N"], -p * opening.area, rtol=1e-12, atol=1e-18)
    summary = result.summaries[0]
    assert summary["particles"]["fluid_start"] == (summary["particles"]["fluid_end"]
                                                   + summary["openings"]["outlet"]["crossed_particles"])
    # through an outlet receding at 0.02 m/s a full cavity would pass (0.1 - 0.02) x the piston
    # area.  The fluid does not follow the receding outlet: its near slab holds ~12 % fewer
    # particles than the static outlet's, and the volume flux (velocity estimate, sum of the
    # near particles' m/rho v_n / d) is 0.73 of it (the crossing estimate 0.63; with the fill
    # without wall clearance 0.85 and 0.77; A x the mean v_n, the former estimate, said 0.985
    # because it ignored the missing fluid).  A known limit (docs/cardioproof.md): bounded
    # from both sides so a change either way shows
    steady = rows["time_s"] >= 5e-3
    q = opening.area * (SPEED - 0.02)
    velocity = rows["flux_velocity_m3_s"][steady].mean()
    print(f"moving outlet: velocity estimate / (A (u_piston - u_outlet)) = {velocity / q:.4f}")
    assert 0.65 < velocity / q < 0.85
    # the stretch warned about: the last quads' diagonals grow from sqrt(h^2 + c^2) to
    # sqrt((h + 0.02 x 8 ms)^2 + c^2), h = 2 mm / 8 rows, c the 24-gon's chord
    chord, h = 2e-3 * math.sin(math.pi / 24), 2e-3 / 8
    stretch = math.hypot(h + 0.02 * 8e-3, chord) / math.hypot(h, chord)
    assert any(kind == "wall stretch" and f"{stretch:.2f}x" in text for kind, text in result.warnings), \
        (stretch, result.warnings)


# ------------------------------------------------------------------------------------------
# a static cube cavity (VTK mesh, no motion): 1 mm, top face the opening
CUBE_POINTS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1],
                        [0, 1, 1]], float) * 1e-3
CUBE_TRIANGLES = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                  [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]
CUBE_TAGS = [1, 1, 3, 3] + [1] * 8


def _cube(tmp: Path, points=CUBE_POINTS, triangles=CUBE_TRIANGLES, tags=CUBE_TAGS, **case) -> Path:
    import meshio

    meshio.write(tmp / "cube.vtu", meshio.Mesh(points, [("triangle", np.array(triangles))],
                                                cell_data={"region": [np.array(tags)]}))
    doc = {"cardioproof": 1, "mesh": "cube.vtu", "fluid": {"spacing": 1e-4, "sound_speed": 5.0},
           "openings": [{"name": "top", "tags": [3], "pressure": 3.0}],
           "run": {"end_time": 2e-4}, "output": {"interval": 1e-4}}
    for key, value in case.items():
        doc[key] = value
    path = tmp / "cube.json"
    path.write_text('{"cardioproof": 1,\n' + json.dumps({k: v for k, v in doc.items() if k != "cardioproof"})[1:])
    return path


def test_fix_addforce_applies_the_numpy_forces_to_each_particle(tmp_path, monkeypatch):
    """The force each fluid particle gets from the outflow fixes (LAMMPS's forces with them
    minus without them) equals the numpy reference's share, particle by particle."""
    import fibrelmp
    from fibrelmp.translate.cardioproof.case import read_case
    from fibrelmp.translate.cardioproof.job import write_job

    case = read_case(_cube(tmp_path))
    job, text = write_job(case, tmp_path / "job")
    assert job.fluid_count == 1000 and job.moving_count == 0        # a 10 x 10 x 10 lattice, static
    monkeypatch.chdir(tmp_path / "job")
    lmp = fibrelmp.lammps_instance(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for line in text[:text.index("run             0 post no")].splitlines():
            lmp.command(line)
        lmp.command("run 0 post no")
        n = lmp.get_natoms()
        ids = np.array(lmp.gather_atoms("id", 0, 1)[:n])
        x = np.array(lmp.gather_atoms("x", 1, 3)[:3 * n]).reshape(-1, 3)
        with_fix = np.array(lmp.gather_atoms("f", 1, 3)[:3 * n]).reshape(-1, 3)
        lmp.command("unfix out_top")
        lmp.command("run 0 post no")
        without = np.array(lmp.gather_atoms("f", 1, 3)[:3 * n]).reshape(-1, 3)
    finally:
        lmp.close()
    applied = with_fix - without
    top = Opening(CUBE_POINTS[np.array(CUBE_TRIANGLES[2:4])])
    ref = share(top, x, 2e-4, 3.0)
    expected = np.zeros_like(x)
    expected[ref.rows] = ref.force
    assert len(ref.rows) == 200 and np.all(ids[ref.rows] <= 1000)   # two lattice layers under the top
    np.testing.assert_allclose(applied, expected, rtol=0, atol=1e-12 * abs(ref.force).max())
    np.testing.assert_allclose(applied.sum(axis=0), [0, 0, -3.0 * 1e-6], rtol=1e-12)


def test_fluid_beside_an_opening_is_not_removed(tmp_path):
    """An L-shaped cavity whose opening lies beside fluid higher up: only fluid in front of
    the opening itself leaves (with p = 0 and no motion, none does)."""
    import meshio

    voxels = {(0, 0, 0), (1, 0, 0), (1, 0, 1)}
    nodes, faces, tags = {}, [], []
    for v in sorted(voxels):
        for axis in range(3):
            for side in (1, -1):
                nb = list(v)
                nb[axis] += side
                if tuple(nb) in voxels:
                    continue
                b, c = [i for i in range(3) if i != axis]
                base = list(v)
                base[axis] += 1 if side > 0 else 0
                corners = []
                for db, dc in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = list(base)
                    p[b] += db
                    p[c] += dc
                    corners.append(nodes.setdefault(tuple(p), len(nodes)))
                faces.append(corners)
                tags.append(3 if (v == (0, 0, 0) and axis == 2 and side > 0) else 1)
    points = np.array(sorted(nodes, key=nodes.get), float) * 1e-3
    meshio.write(tmp_path / "l.vtu", meshio.Mesh(points, [("quad", np.array(faces))],
                                                  cell_data={"region": [np.array(tags)]}))
    (tmp_path / "l.json").write_text(json.dumps(
        {"cardioproof": 1, "mesh": "l.vtu", "fluid": {"spacing": 1e-4, "sound_speed": 5.0},
         "openings": [{"name": "top", "tags": [3], "pressure": 0.0}], "run": {"end_time": 2e-4}}))
    summary = python_api.run(tmp_path / "l.json").summaries[0]
    assert summary["particles"]["fluid_start"] == 3000 == summary["particles"]["fluid_end"]
    assert summary["openings"]["top"]["crossed_particles"] == 0


@pytest.mark.parametrize("make, message", [
    (lambda tmp: _cube(tmp, triangles=CUBE_TRIANGLES[:-1], tags=CUBE_TAGS[:-1]), "not shared by exactly two"),
    (lambda tmp: _cube(tmp, triangles=CUBE_TRIANGLES + [[4, 5, 5]], tags=CUBE_TAGS + [1]), "has no area"),
    (lambda tmp: _cube(tmp, points=np.where(np.arange(24).reshape(8, 3) == 0, np.nan, CUBE_POINTS)),
     "coordinates must be finite"),
    (lambda tmp: _cube(tmp, triangles=[[0, 2, 99]] + CUBE_TRIANGLES[1:]), "names a point outside"),
    (lambda tmp: _cube(tmp, run={"end_time": 2e-4, "timestep": 1e-7}), "run.timestep: unknown key"),
    (lambda tmp: _cube(tmp, motion={"file": "a.dynpt", "meshes": ["b.vtu"], "frame_interval": 1e-3}),
     "not both"),
])
def test_bad_geometry_is_an_input_error(tmp_path, make, message):
    case = make(tmp_path)
    before = set(tmp_path.rglob("*"))
    with pytest.raises(InputError) as err:
        python_api.run(case)
    assert message in str(err.value), str(err.value)
    assert set(tmp_path.rglob("*")) == before


def test_in_front_of_an_opening():
    from fibrelmp.translate.cardioproof.case import Opening as CaseOpening
    from fibrelmp.translate.cardioproof.job import _opening, in_front

    square = CUBE_POINTS[np.array(CUBE_TRIANGLES[2:4])]                     # z = 1 mm, outward +z
    o = _opening(CaseOpening("top", np.arange(2), np.array([[0.0, 0.0]]), 1e-4), square)
    x = np.array([[0.5e-3, 0.5e-3, 1.1e-3], [0.5e-3, 0.5e-3, 1.25e-3], [0.5e-3, 0.5e-3, 0.95e-3],
                  [1.2e-3, 0.5e-3, 1.1e-3], [1.0e-3 + 0.9 * 0.03 * 1e-3, 0.5e-3, 1.05e-3]])
    # over it 0.1 mm out: yes; 0.25 mm out (> 2d): no; behind it: no; beside it: no; within the margin: yes
    assert in_front(o, x).tolist() == [True, False, False, False, True]


def test_motion_from_a_series_of_meshes(tmp_path):
    """``motion.meshes``: one VTK mesh per frame; the cube's floor rises 20 µm per 0.1 ms and
    pushes fluid out of the top.  The floor's wall particles (below z = 0) end 100 µm higher;
    on the side walls, whose triangles stretch affinely, a particle at height z rises
    100 µm x (1 - z / 1 mm)."""
    import meshio

    frames = []
    for k in range(6):
        points = CUBE_POINTS.copy()
        points[:4, 2] += 2e-5 * k
        meshio.write(tmp_path / f"frame{k}.vtu", meshio.Mesh(points, [("triangle", np.array(CUBE_TRIANGLES))],
                                                             cell_data={"region": [np.array(CUBE_TAGS)]}))
        frames.append(f"frame{k}.vtu")
    case = _cube(tmp_path, motion={"meshes": frames, "frame_interval": 1e-4}, run={"end_time": 5e-4})
    summary = python_api.run(case).summaries[0]
    walls = list(iter_frames(tmp_path / "cube_work" / "moving_walls.dump"))
    assert [round(w.time, 12) for w in walls] == [0.0, 1e-4, 2e-4, 3e-4, 4e-4, 5e-4]
    z0 = walls[0].columns["z"]
    expected = np.where(z0 < 0, 1e-4, 1e-4 * (1 - z0 / 1e-3))
    assert (z0 < 0).sum() > 200
    np.testing.assert_allclose(walls[-1].columns["z"] - z0, expected, atol=1e-13)
    crossed = summary["openings"]["top"]["crossed_particles"]
    assert crossed > 0
    assert summary["particles"]["fluid_start"] == summary["particles"]["fluid_end"] + crossed


# ------------------------------------------------------------------------------------------
# hostile case files (issue 24): each is `path: message` on the CLI, exit 2, no traceback,
# nothing written, and an InputError (never SystemExit) from the Python API
def _cli(*args):
    from typer.testing import CliRunner

    from fibrelmp.cli import app

    result = CliRunner().invoke(app, [str(a) for a in args])
    return result, result.output + (result.stderr if result.stderr_bytes is not None else "")


def _refused(case: Path, message: str) -> None:
    folder = case.parent
    before = {p: p.stat().st_mtime_ns for p in folder.rglob("*")}
    result, output = _cli("run", case)
    assert result.exit_code == 2, output
    assert "error: " in output and message in output and "Traceback" not in output, output
    assert {p: p.stat().st_mtime_ns for p in folder.rglob("*")} == before
    with pytest.raises(InputError, match=re.escape(message)):
        python_api.check(case)


def _edit_elem(tmp: Path) -> None:
    lines = (tmp / "piston_tube.elem").read_text().splitlines()
    lines[1] = " ".join(lines[1].split()[:-1] + ["1" + "0" * 23])       # an exact integer, 1e23
    (tmp / "piston_tube.elem").write_text("\n".join(lines) + "\n")


def _edit_dynpt(case: Path, old: bytes, new: bytes) -> Path:
    """``case`` with one item of its .dynpt's header replaced (the 1024-byte header kept)."""
    tmp = case.parent
    data = (tmp / "piston_tube.dynpt").read_bytes()
    assert old in data[:1024]
    head = data[:1024].replace(old, new)
    head = head[:1023].ljust(1023) + b"\f" if len(head) >= 1024 else head[:-1].ljust(1023) + b"\f"
    (tmp / "piston_tube.dynpt").write_bytes(head + data[1024:])
    return case


def _lying_vtu(tmp: Path) -> None:
    text = (tmp / "cube.vtu").read_text()
    (tmp / "cube.vtu").write_text(text.replace('NumberOfCells="12"', 'NumberOfCells="999999999"'))


@pytest.mark.parametrize("make, message", [
    (lambda tmp: (_copy(tmp), _edit_elem(tmp))[0], "piston_tube.elem:2: region tag 1" + "0" * 23),
    (lambda tmp: _bad(tmp, lambda d: d["motion"].update(file="piston\0tube.dynpt")),
     "motion.file: a file name cannot contain a NUL character"),
    (lambda tmp: _bad(tmp, lambda d: d["mesh"].update(file="")), "mesh.file: an empty file name"),
    (lambda tmp: _edit_dynpt(_bad(tmp, lambda d: d["motion"].pop("frame_interval")), b"inc_t:0.5", b"inc_t:0.0"),
     "piston_tube.dynpt: inc_t:0: the time between frames must be positive"),
    (lambda tmp: _edit_dynpt(_bad(tmp, lambda d: None), b"x:266 ", b"x:266000000000000 "),
     "the header says 21 frames of 266000000000000 nodes (67032000000001024 bytes) but the file has"),
    (lambda tmp: (_cube(tmp), (tmp / "cube.vtu").write_bytes(np.random.default_rng(1).bytes(4000)))[0],
     "cube.vtu: cannot read as a VTK XML unstructured grid"),
    (lambda tmp: (_cube(tmp), _lying_vtu(tmp))[0], "cube.vtu: cannot read as a VTK XML unstructured grid"),
])
def test_hostile_mesh_and_path_keys_are_input_errors(tmp_path, make, message):
    """An .elem region tag of 1e23 (was OverflowError), a NUL in motion.file (was ValueError:
    embedded null byte), a .vtu of random bytes or a lying NumberOfCells (was meshio's
    sys.exit(1): exit 1 without an error line, SystemExit from fibrelmp.check())."""
    _refused(make(tmp_path), message)


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["fluid"].update(sound_speed=1e12), "fluid.sound_speed: 1e+12 m/s: at most 100000 m/s"),
    (lambda d: d["run"].update(time_step=1e-15), "1e+13 steps; LAMMPS counts a run's steps in 32-bit integers"),
    (lambda d: d["openings"][0].update(search_distance=1e300),
     "openings[0].search_distance: 1e+300 m: must be from fluid.spacing"),
    (lambda d: d["output"].update(name="a" * 300), "over the 255-byte limit"),
    (lambda d: d["fluid"].update(spacing=1e-300), "lattice cells (at most 4,000,000)"),
    (lambda d: (d["run"].update(time_step=1e-9), d["output"].update(interval=1e-9)), "frames: at most 100000"),
    (lambda d: (d["run"].update(time_step=1e-9), d["output"].update(series_interval=1e-9)), "rows per opening"),
    (lambda d: d["openings"][0].update(pressure=1e300), "above the Tait stiffness B = c0^2 rho0 / 7 = 3571.43 Pa"),
    (lambda d: d["fluid"].update(density=1e-300), "fluid.density: 1e-300 kg/m^3: expected 0.001 to 100000"),
    (lambda d: d["fluid"].update(artificial_viscosity=1e300), "fluid.artificial_viscosity: 1e+300: at most 10"),
    (lambda d: d["mesh"].update(unit=1e300), "mesh.unit: the mesh spans 2e+303 m"),
])
def test_impossible_runs_are_refused_before_anything_is_written(tmp_path, edit, message):
    """Were LAMMPS's 'Integer out of range', numpy overflow + 'Bad grid of processors' and
    'File name too long' after the work folder was written (exit 1); a pressure of 1e300 Pa or
    an artificial viscosity of 1e300 ran to exit 0 with most fluid lost, a density of 1e-300
    ended in LAMMPS's 'Non-numeric atom coords' (exit 1)."""
    if "255-byte" in message and os.pathconf(tmp_path, "PC_NAME_MAX") != 255:
        pytest.skip("the folder's file system has another name limit")
    _refused(_bad(tmp_path, edit), message)


def test_relative_mesh_series_runs_from_the_case_folder(tmp_path, monkeypatch):
    """motion.meshes by relative names, run as `fibrelmp run cube.json` from the case's own
    folder: the later frames were opened after the runner changed into the work folder."""
    import meshio

    frames = []
    for k in range(3):
        points = CUBE_POINTS.copy()
        points[:4, 2] += 2e-5 * k
        meshio.write(tmp_path / f"cube_{k}.vtu", meshio.Mesh(points, [("triangle", np.array(CUBE_TRIANGLES))],
                                                            cell_data={"region": [np.array(CUBE_TAGS)]}))
        frames.append(f"cube_{k}.vtu")
    _cube(tmp_path, mesh="cube_0.vtu", motion={"meshes": frames, "frame_interval": 1e-4}, run={"end_time": 2e-4})
    monkeypatch.chdir(tmp_path)
    result, output = _cli("run", "cube.json")
    assert result.exit_code == 0, output
    walls = list(iter_frames(tmp_path / "cube_work" / "moving_walls.dump"))
    z0 = walls[0].columns["z"]
    # the floor's wall particles (below z = 0) are 40 um higher at the end: the last frame was read
    np.testing.assert_allclose((walls[-1].columns["z"] - z0)[z0 < 0], 4e-5, atol=1e-13)


# ------------------------------------------------------------------------------------------
# fluid in the wall layer (issue 24: 36-108 fluid particles per frame up to dx/2 beyond the
# tube's wall, with "warnings none")
def _beyond_side_wall(x: np.ndarray) -> np.ndarray:
    """How far each point is beyond the tube's 24-gon side faces (m; negative: inside), from
    the polygon's geometry: its support function, independent of fibrelmp's geometry code."""
    sector = 2 * np.pi / 24
    face = (np.floor(np.arctan2(x[:, 1], x[:, 0]) / sector) + 0.5) * sector
    return x[:, 0] * np.cos(face) + x[:, 1] * np.sin(face) - 1e-3 * np.cos(sector / 2)


def test_fill_starts_a_quarter_spacing_from_the_walls(tmp_path):
    """The lattice's points nearest the tube's wall were 0.035 dx from it (0.535 dx from the
    first wall sheet): the fill now keeps dx/4; a lattice-aligned wall keeps its dx/2 row."""
    from fibrelmp.translate.cardioproof.case import read_case
    from fibrelmp.translate.cardioproof.job import plan_job

    dx = 1.25e-4
    fluid = plan_job(read_case(_copy(tmp_path)))["fluid"]
    gap = -_beyond_side_wall(fluid)
    assert gap.min() >= 0.25 * dx * (1 - 1e-6)
    assert fluid[:, 2].min() == pytest.approx(0.5 * dx, rel=1e-9)         # the piston's face, z = 0
    # the fluid is exactly the lattice (16 x 16 x 16 cells over the tube's box, centres at
    # (i + 1/2) dx from its corner) with at least dx/4 to the side faces (numpy, independent)
    axis = -1e-3 + (np.arange(16) + 0.5) * dx
    grid = np.stack(np.meshgrid(axis, axis, (np.arange(16) + 0.5) * dx, indexing="ij"), -1).reshape(-1, 3)
    expected = grid[-_beyond_side_wall(grid) >= 0.25 * dx]
    order = lambda a: a[np.lexsort(a.T)]                                  # noqa: E731
    np.testing.assert_allclose(order(fluid), order(expected), rtol=0, atol=1e-15)
    (tmp_path / "cube").mkdir()
    cube = plan_job(read_case(_cube(tmp_path / "cube")))   # 10 x 10 x 10 cells, every one kept
    assert len(cube["fluid"]) == 1000


def test_no_fluid_in_the_wall_layer_at_any_frame(piston_run):
    """An independent count at every saved frame: no fluid particle beyond the tube's side
    faces or behind the piston's face; the run summary counts none and warns of none."""
    tmp, result = piston_run
    frames = list(DynptReader(tmp / "piston_tube.dynpt"))
    dz = np.array([(fr.points[:, 2] - frames[0].points[:, 2]).max() * 1e-6 for fr in frames])
    checked = 0
    for f in iter_frames(tmp / "piston_tube_work" / "frames.dump"):
        x = np.column_stack([f.columns["x"], f.columns["y"], f.columns["z"]])
        tube = x[:, 2] < 2e-3                                  # beyond the outlet: leaving
        assert (_beyond_side_wall(x[tube]) <= 0).all(), f.time
        assert (x[:, 2] > np.interp(f.time, np.arange(len(dz)) * 5e-4, dz)).all()
        checked += 1
    assert checked == 11
    summary = result.summaries[0]["fluid_beyond_walls"]
    assert summary["frames"] == 11 and summary["frames_with"] == 0
    assert not [w for w in result.warnings if w[0] == "fluid in wall"]


def test_fluid_beyond_a_wall_is_counted_and_warned(tmp_path):
    """The run's counter (results.BeyondWalls) against particles put at known places in the
    static cube: 0.3 dx beyond the side wall x = 0 and 0.2 dx below the floor count; inside,
    or over the top opening (leaving), they do not."""
    from fibrelmp.translate.cardioproof.case import read_case
    from fibrelmp.translate.cardioproof.job import write_job
    from fibrelmp.translate.cardioproof.results import BeyondWalls, SphFrame

    case = read_case(_cube(tmp_path))
    job, _ = write_job(case, tmp_path / "job", write_files=False)
    dx = 1e-4
    x = np.array([[0.5e-3, 0.5e-3, 0.5e-3], [-0.3 * dx, 0.5e-3, 0.5e-3], [0.4e-3, 0.6e-3, -0.2 * dx],
                  [0.5e-3, 0.5e-3, 1e-3 + 0.5 * dx], [-0.3 * dx, 0.2e-3, 0.3e-3]])
    counter = BeyondWalls(case, job)
    for t, rows in ((0.0, [0, 3]), (1e-4, [0, 1, 2, 3, 4])):
        n = len(rows)
        counter.add(SphFrame(0, t, np.arange(n), x[rows], np.zeros((n, 3)), np.full(n, 1000.0), np.zeros(n),
                             nodes=CUBE_POINTS))
    assert counter.summary() == {"frames": 2, "frames_with": 1, "most_particles": 3,
                                 "deepest_m": pytest.approx(0.3 * dx, rel=1e-12), "first_time": 1e-4}
    counter.warn()
    [(kind, text)] = case.warnings
    assert kind == "fluid in wall" and "in 1 of 2 frames (up to 3 per frame, up to 0.30 spacings deep" in text


def test_an_output_interval_below_the_time_step_is_warned(tmp_path):
    """Was: output.interval 1e-9 s (below the time step) saved every step without a word."""
    path = _cube(tmp_path, output={"interval": 1e-12, "series_interval": 1e-12})
    result, text = _cli("-v", "check", path)
    assert result.exit_code == 0, text
    assert "warning [output interval] (2): " in text
    assert "output.interval 1e-12 s is below the time step" in text
    assert "output.series_interval 1e-12 s is below the time step" in text
