"""``post --to mercury``: the ``.restart`` MercuryCG reads (species densities, domain, time)
and particle-wall rows in ``.fstat`` from a dump's wall-contact columns.

A small LAMMPS run of two sphere types with different densities settling on a flat floor
(``fix wall/gran ... zplane 0 NULL contacts``: the force on each sphere and the contact
point, dumped as ``wall1_fx .. wall1_cz``).  Expected values come from the LAMMPS input (the
densities), the dump (positions, radii, forces) and the floor's geometry, never from the
writer: for a sphere touching the plane z = 0 the overlap is r - z, the normal from the wall
to the centre is +z (MercuryDPM writes a wall contact once with the normal negated, -z), the
contact point is the middle of the overlap, z = -(r - z) / 2.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.post.convert import post_command
from fibrelmp.post.lammps_dump import iter_frames
from fibrelmp.post.mercury import read_fstat

from .conftest import REPO

DENSITY = {1: 2500.0, 2: 1000.0}          # the LAMMPS types' densities

SCRIPT = """
units si
atom_style sphere
dimension 3
boundary p p f
region box block 0 0.04 0 0.04 0 0.05
create_box 2 box
comm_modify vel yes
region ins block 0.004 0.036 0.004 0.036 0.006 0.03
lattice sc 0.01
create_atoms 1 region ins
set group all type/fraction 2 0.5 4321
set type 1 diameter 0.008
set type 2 diameter 0.006
set type 1 density 2500
set type 2 density 1000
pair_style granular
pair_coeff * * hertz/material 1e6 0.3 0.3 tangential mindlin NULL 1.0 0.4 damping tsuji
fix grav all gravity 9.81 vector 0 0 -1
fix nve all nve/sphere
fix floor all wall/gran granular hertz/material 1e6 0.3 0.3 tangential mindlin NULL 1.0 0.4 damping tsuji zplane 0 NULL contacts
timestep 1e-5
dump d all custom 2000 atoms.dump id type x y z vx vy vz fx fy fz radius mass omegax omegay omegaz f_floor[2] f_floor[3] f_floor[4] f_floor[5] f_floor[6] f_floor[7]
dump_modify d time yes sort id format float %.17g colname f_floor[2] wall1_fx colname f_floor[3] wall1_fy colname f_floor[4] wall1_fz colname f_floor[5] wall1_cx colname f_floor[6] wall1_cy colname f_floor[7] wall1_cz
run 8000
"""


@pytest.fixture(scope="module")
def settled(tmp_path_factory) -> Path:
    from fibrelmp._lammps import new_lammps

    folder = tmp_path_factory.mktemp("floor")
    cwd = os.getcwd()
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        os.chdir(folder)
        for line in SCRIPT.strip().splitlines():
            lmp.command(line)
    finally:
        os.chdir(cwd)
        lmp.close()
    return folder


def post(dump: Path, out: Path, **kw) -> list[Path]:
    args = dict(info=False, frames=None, types=None, data=None, local=None, gravity=(0.0, 0.0, -9.81),
                force=False, topology=None, say=lambda s: None)
    args.update(kw)
    return post_command(dump, "mercury", out, **args)


def read_restart_as_mercury_cg(path: Path) -> dict:
    """The keys MercuryDPM's ``DPMBase::read`` takes from a restart file (version 1.0), in its
    order, up to the particles (MercuryCG reads no interactions): the file lines, domain,
    time step and time, dimensions and gravity, species (each followed by its mixed species
    with the earlier ones), walls, boundaries, particles."""
    lines = iter(path.read_text().splitlines())
    head = next(lines).split()
    assert head[:2] == ["MercuryDPM", "1.0"] and head[2] == "name"
    out: dict = {"name": head[3]}
    for label in ("dataFile", "fStatFile", "eneFile", "restartFile", "statFile", "interactionFile"):
        words = next(lines).split()
        assert words[0] == label and words[1] == "fileType"
        out[label] = words[2]
    words = next(lines).split()
    assert words[0::2] == ["xMin", "xMax", "yMin", "yMax", "zMin", "zMax"]
    v = [float(w) for w in words[1::2]]
    out["min"], out["max"] = np.array(v[0::2]), np.array(v[1::2])
    words = next(lines).split()
    assert words[0::2] == ["timeStep", "time", "ntimeSteps", "timeMax"]
    out["timeStep"], out["time"], out["ntimeSteps"] = float(words[1]), float(words[3]), int(words[5])
    words = next(lines).split()
    assert words[0] == "systemDimensions" and words[2] == "particleDimensions" and words[4] == "gravity"
    out["systemDimensions"], out["particleDimensions"] = int(words[1]), int(words[3])
    out["gravity"] = np.array([float(w) for w in words[5:8]])
    words = next(lines).split()
    assert words[0] == "Species"
    out["density"] = {}
    for k in range(int(words[1])):
        words = next(lines).split()
        assert words[0] == "LinearViscoelasticSpecies" and words[1:3] == ["id", str(k)]
        fields = dict(zip(words[3::2], words[4::2]))
        out["density"][k] = float(fields["density"])
        for other in range(k):
            mixed = next(lines).split()
            assert mixed[0] == "LinearViscoelasticMixedSpecies" and mixed[1:5] == ["idA", str(k), "idB", str(other)]
    for section in ("Walls", "Boundaries"):
        assert next(lines).split() == [section, "0"]
    words = next(lines).split()
    assert words[0] == "Particles"
    rows = []
    for _ in range(int(words[1])):
        words = next(lines).split()
        assert words[0] == "BaseParticle"
        names = ["id", "indSpecies", "position", "orientation", "velocity", "angularVelocity", "force",
                 "torque", "radius", "invMass", "timeStamp"]
        at = {name: words.index(name) for name in names}
        sizes = {"position": 3, "orientation": 4, "velocity": 3, "angularVelocity": 3, "force": 3, "torque": 3}
        rows.append({name: [float(w) for w in words[at[name] + 1: at[name] + 1 + sizes.get(name, 1)]]
                     for name in names})
    out["particles"] = rows
    return out


def test_restart_gives_mercury_cg_the_densities_domain_and_time(settled, tmp_path):
    written = post(settled / "atoms.dump", tmp_path / "run")
    assert sorted(p.name for p in written) == ["run.data", "run.ene", "run.fstat", "run.restart"]
    frames = list(iter_frames(settled / "atoms.dump"))
    last = frames[-1]
    r = read_restart_as_mercury_cg(tmp_path / "run.restart")
    assert r["density"] == pytest.approx({t - 1: rho for t, rho in DENSITY.items()}, rel=1e-12)
    np.testing.assert_allclose(r["min"], last.lo, rtol=1e-14)
    np.testing.assert_allclose(r["max"], last.hi, rtol=1e-14)
    assert r["time"] == pytest.approx(last.time, rel=1e-14) and r["ntimeSteps"] == last.step == 8000
    assert r["timeStep"] == pytest.approx(1e-5, rel=1e-9)
    assert (r["systemDimensions"], r["particleDimensions"]) == (3, 3)
    np.testing.assert_array_equal(r["gravity"], [0, 0, -9.81])
    assert r["fStatFile"] == "ONE_FILE"
    parts = r["particles"]
    assert len(parts) == last.count
    np.testing.assert_array_equal([p["indSpecies"][0] for p in parts], last.column("type") - 1)
    np.testing.assert_allclose([p["position"] for p in parts], last.vector("x", "y", "z"), rtol=1e-14)
    np.testing.assert_allclose([p["radius"][0] for p in parts], last.column("radius"), rtol=1e-14)
    np.testing.assert_allclose([p["invMass"][0] for p in parts], 1 / last.column("mass"), rtol=1e-14)
    # MercuryDPM's mass from the species: density * 4/3 pi r^3 (particleDimensions 3)
    species = last.column("type").astype(int) - 1
    mass = np.array([r["density"][s] for s in species]) * 4 / 3 * np.pi * last.column("radius") ** 3
    np.testing.assert_allclose(mass, last.column("mass"), rtol=1e-12)


def test_wall_contact_rows_from_the_dump_columns(settled, tmp_path):
    post(settled / "atoms.dump", tmp_path / "run")
    frames = list(iter_frames(settled / "atoms.dump"))
    fstat = read_fstat(tmp_path / "run.fstat")
    assert len(fstat) == len(frames)
    touching_seen = 0
    for fs, f in zip(fstat, frames):
        F = f.vector("wall1_fx", "wall1_fy", "wall1_fz")
        rows = np.flatnonzero(np.any(F != 0, axis=1))
        walls = fs.rows[fs.rows[:, 2] < 0]
        assert len(walls) == len(rows)
        touching_seen += len(rows)
        if not len(rows):
            continue
        z, r = f.column("z")[rows], f.column("radius")[rows]
        np.testing.assert_array_equal(walls[:, 1], rows)                 # particle index = row
        np.testing.assert_array_equal(walls[:, 2], -1)                   # wall 0: -(0) - 1
        np.testing.assert_allclose(walls[:, 6], r - z, rtol=1e-8)        # overlap
        assert np.all(walls[:, 6] > 0)
        np.testing.assert_allclose(walls[:, 10:13], np.tile([0, 0, -1], (len(rows), 1)), atol=1e-12)
        np.testing.assert_allclose(walls[:, 8], F[:, 2][rows], rtol=1e-8)  # F . (+z)
        np.testing.assert_allclose(walls[:, 9], np.hypot(F[rows, 0], F[rows, 1]), rtol=1e-8, atol=1e-15)
        np.testing.assert_allclose(walls[:, 3:5], f.vector("x", "y")[rows], rtol=1e-9)
        np.testing.assert_allclose(walls[:, 5], -(r - z) / 2, rtol=1e-8)
        np.testing.assert_allclose(walls[:, 0], f.time, rtol=1e-9)
    assert touching_seen > 0                   # the spheres did reach the floor


def test_incomplete_wall_columns_are_an_error(tmp_path):
    dump = tmp_path / "d.dump"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 1\n"
                    "ITEM: ATOMS id type x y z radius mass wall1_fx wall1_fy wall1_fz\n1 1 0.5 0.5 0.1 0.2 1 0 0 1\n")
    from fibrelmp.errors import InputError

    with pytest.raises(InputError, match="wall 1's contact columns are incomplete"):
        post(dump, tmp_path / "run")
    assert not list(tmp_path.glob("run.*"))


def test_run_keeps_contacts_so_post_to_mercury_gives_fstat(tmp_path):
    """A DEMDF run (stock pair granular) keeps its sphere-sphere contacts in the work
    folder's contacts.dump; ``post --to mercury --local`` of it gives .fstat rows whose
    overlap and normal match the positions and radii of the run's frames.dump, and a
    .restart whose density is the input's mass over the sphere volume."""
    from fibrelmp import python_api

    doc = json.loads((REPO / "examples" / "demdf" / "head_on.json").read_text())
    doc["timeEnd"] = 1.0                      # the collision's first contact frame is t = 1
    case = tmp_path / "head_on.json"
    case.write_text(json.dumps(doc))
    python_api.run(case)
    work = tmp_path / "head_on_work"
    post(work / "frames.dump", tmp_path / "run", data=work / "data.lammps", local=work / "contacts.dump",
         gravity=None)
    frames = list(iter_frames(work / "frames.dump"))
    fstat = read_fstat(tmp_path / "run.fstat")
    assert len(fstat) == len(frames)
    pairs = 0
    for fs, f in zip(fstat, frames):
        x, r = f.vector("x", "y", "z"), f.column("radius")
        for row in fs.rows:
            i, j = int(row[1]), int(row[2])
            d = x[i] - x[j]
            np.testing.assert_allclose(row[6], r[i] + r[j] - np.linalg.norm(d), rtol=1e-6, atol=1e-12)
            np.testing.assert_allclose(row[10:13], d / np.linalg.norm(d), atol=1e-12)
            pairs += 1
    assert pairs == 2                         # one contact frame: the pair written both ways
    particle = next(t for t in doc["objectTypes"] if t["type"] == "particle")
    density = read_restart_as_mercury_cg(tmp_path / "run.restart")["density"][0]
    assert density == pytest.approx(particle["mass"] / (4 / 3 * np.pi * particle["radius"] ** 3), rel=1e-12)


@pytest.mark.parametrize("law", [(1.0, 0.0, 0.0), (0.5, 2e7, 0.3), (0.5, 2e7, 0.002)],
                         ids=["elastic-frictionless", "damped-sticking", "damped-slipping"])
@pytest.mark.parametrize("steps", [0, 40])
def test_musen_pair_single_gives_the_applied_contact_force(tmp_path, law, steps):
    """pair musen/hm's single() (compute pair/local, which run's contacts.dump uses) reports
    the force the pair applied in the step: for an isolated pair it is each sphere's force
    in the atom dump (normal part along x1 - x2, the rest tangential), at step 0 (the setup
    force) and after 40 steps (the stored force of the last step), damped, sticking or
    slipping; for the elastic frictionless law also Hertz's 4/3 E* sqrt(R*) overlap^1.5,
    computed here."""
    from fibrelmp import lammps_styles
    from fibrelmp._lammps import new_lammps

    plugin = lammps_styles.plugin()
    if not plugin.available:
        pytest.skip(f"fibrelmp's LAMMPS styles are not available: {plugin.how}")
    rest, gstar, mu = law
    estar, r1, r2 = 5e7, 1e-3, 7e-4
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    cwd = os.getcwd()
    try:
        os.chdir(tmp_path)
        for c in [f"plugin load {plugin.path}", "units si", "atom_style sphere", "boundary f f f",
                  "newton off", "comm_modify vel yes", "atom_modify map array",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  "create_atoms 1 single 0 0 0 units box", "create_atoms 1 single 0.0016 0.0003 0.0001 units box",
                  f"set atom 1 diameter {2 * r1!r} density 2500", f"set atom 2 diameter {2 * r2!r} density 2500",
                  "set atom 1 vx 0.02 vy 0.01", "set atom 2 vx -0.03 vz 0.01", "set atom 2 omega 0 0 50",
                  "pair_style musen/hm", f"pair_coeff 1 1 {estar!r} {gstar!r} {rest!r} {mu!r} 0.0",
                  "neighbor 0.0005 bin", "neigh_modify every 1 delay 0 check yes", "timestep 1e-7",
                  "fix integrate all nve/sphere",
                  "compute pl all pair/local dist fx fy fz p1 p2 p3 p4 p5 p6 cutoff radius",
                  "compute pp all property/local patom1 patom2 cutoff radius",
                  "run 0 post no" if steps == 0 else f"run {steps} post no",
                  "write_dump all local contacts.dump c_pp[1] c_pp[2] c_pl[1] c_pl[2] c_pl[3] c_pl[4] c_pl[5] "
                  "c_pl[6] c_pl[7] c_pl[8] c_pl[9] c_pl[10] modify format float %.17g",
                  "write_dump all custom atoms.dump id x y z fx fy fz radius modify sort id format float %.17g"]:
            lmp.command(c)
    finally:
        os.chdir(cwd)
        lmp.close()
    pair = next(iter_frames(tmp_path / "contacts.dump")).columns
    atoms = next(iter_frames(tmp_path / "atoms.dump"))
    assert len(pair["c_pp[1]"]) == 1
    first = int(pair["c_pp[1]"][0]) - 1                  # row of the pair's atom 1
    x = atoms.vector("x", "y", "z")
    d = x[first] - x[1 - first]
    dist = np.linalg.norm(d)
    np.testing.assert_allclose([pair[f"c_pl[{k}]"][0] for k in (8, 9, 10)], d, rtol=1e-15)
    np.testing.assert_allclose(pair["c_pl[1]"][0], dist, rtol=1e-15)
    normal = np.array([pair[f"c_pl[{k}]"][0] for k in (2, 3, 4)])
    tangential = np.array([pair[f"c_pl[{k}]"][0] for k in (5, 6, 7)])
    applied = atoms.vector("fx", "fy", "fz")[first]
    scale = np.abs(applied).max()
    np.testing.assert_allclose(normal + tangential, applied, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(normal, (applied @ d) / dist ** 2 * d, rtol=0, atol=1e-12 * scale)
    assert abs(tangential @ d) <= 1e-12 * scale * dist
    if gstar:
        assert np.linalg.norm(tangential) > 1e-3 * scale        # the law has a tangential force here
        slipping = np.isclose(np.linalg.norm(tangential), mu * np.linalg.norm(normal), rtol=1e-12)
        # MUSEN slips when the spring force alone exceeds mu |Fn|: then |Ft| = mu |Fn| (40 steps
        # with mu 0.002); at step 0 the spring is vt dt K_t, far below it
        assert slipping == (mu == 0.002 and steps > 0)
    else:
        overlap = r1 + r2 - dist
        hertz = 4 / 3 * estar * np.sqrt(r1 * r2 / (r1 + r2)) * overlap ** 1.5
        np.testing.assert_allclose(normal, hertz * d / dist, rtol=1e-12)
        assert list(tangential) == [0, 0, 0]


def _warned(dump: Path, out: Path) -> dict[str, str]:
    said: list[str] = []
    post(dump, out, say=said.append)
    return {line.split("]")[0].split("[")[1]: line for line in said if line.startswith("warning [")}


def test_restart_needs_radii_and_says_so(tmp_path):
    """Without radii no density is known: no .restart, and a warning (not density 1)."""
    dump = tmp_path / "d.dump"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
                    "ITEM: ATOMS id type x y z mass\n1 1 0.5 0.5 0.5 2\n")
    warned = _warned(dump, tmp_path / "run")
    assert "no .restart" in warned and not (tmp_path / "run.restart").exists()
    assert (tmp_path / "run.data").exists()


def test_restart_species_with_several_densities_warns_and_takes_the_mean(tmp_path):
    """One LAMMPS type, two densities (1000 and 3000, from mass and radius): MercuryDPM has
    one density per species, so the mean, 2000, with a warning giving the range."""
    v = 4 / 3 * np.pi * 0.1 ** 3
    dump = tmp_path / "d.dump"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
                    f"ITEM: ATOMS id type x y z radius mass\n1 1 0.2 0.5 0.5 0.1 {1000 * v!r}\n"
                    f"2 1 0.7 0.5 0.5 0.1 {3000 * v!r}\n")
    warned = _warned(dump, tmp_path / "run")
    assert "species density" in warned and "1000" in warned["species density"]
    r = read_restart_as_mercury_cg(tmp_path / "run.restart")
    assert r["density"] == {0: pytest.approx(2000, rel=1e-12)}
    assert r["timeStep"] == 0 and "no time step" in warned


def test_demdf_run_plane_wall_contacts_reach_fstat(tmp_path):
    """A DEMDF sphere (r 0.5) placed at z = 0.45 on the floor z = 0, no gravity: the run's
    frames.dump carries the floor's contact columns, and post --to mercury writes the wall
    row of frame 0: overlap 0.05 = r - z, normal -z (MercuryDPM negates a wall's), partner -1,
    fn = the dumped wall force along +z."""
    from fibrelmp import python_api

    doc = json.loads((REPO / "examples" / "demdf" / "drop_on_wall.json").read_text())
    doc["timeEnd"], doc["bodyForce"] = 0.25, [0.0, 0.0, 0.0]
    doc["objects"]["particles"] = [[2.0, 2.0, 0.45, 0.0, 0.0, 0.0, 0]]
    case = tmp_path / "drop_on_wall.json"
    case.write_text(json.dumps(doc))
    python_api.run(case)
    work = tmp_path / "drop_on_wall_work"
    post(work / "frames.dump", tmp_path / "run", data=work / "data.lammps", gravity=None)
    first = next(iter_frames(work / "frames.dump"))
    fz = float(first.column("v_w1_fz")[0])
    assert fz > 0                                            # the floor pushes the sphere up
    walls = read_fstat(tmp_path / "run.fstat")[0].rows
    assert walls.shape == (1, 16)
    np.testing.assert_array_equal(walls[0, 1:3], [0, -1])
    np.testing.assert_allclose(walls[0, 6], 0.5 - 0.45, rtol=1e-9)
    np.testing.assert_allclose(walls[0, 10:13], [0, 0, -1], atol=1e-15)
    np.testing.assert_allclose(walls[0, 8], fz, rtol=1e-9)


def test_post_of_a_musen_run_with_triangle_walls_says_they_are_not_in_fstat(tmp_path):
    """Was: a MUSEN run's triangle walls silently missing from .fstat (fix musen/wall/mesh
    keeps the force per triangle, not per contact): now a 'no wall contacts' warning."""
    import shutil

    from fibrelmp import python_api

    scene = tmp_path / "scene.txt"
    shutil.copyfile(REPO / "examples" / "musen" / "SingelParticle_text.txt", scene)
    python_api.run(scene, tmp_path / "res.mdem", end_time=2e-5, step=1e-6, save_step=1e-5)
    work = tmp_path / "res_work"
    warnings: list[tuple[str, str]] = []
    post(work / "frames.dump", tmp_path / "m", data=work / "data.lammps", local=work / "contacts.dump",
         report=warnings.extend)
    assert [k for k, _ in warnings].count("no wall contacts") == 1, warnings
    assert (tmp_path / "m.fstat").exists()
