"""``fibrelmp post --to musen|demdf``: a LAMMPS granular dump through the neutral granular
model into the same writers ``fibrelmp run`` uses, read back with fibrelmp's own readers."""

from __future__ import annotations

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.translate.demdf.reader import read_snapshot
from fibrelmp.translate.musen.scene import read, read_time_points

from .test_post_roundtrip import dump_frames, granular, post  # noqa: F401  (fixture)


def test_musen_round_trip(granular, tmp_path):  # noqa: F811
    written = post(granular / "atoms.dump", "musen", tmp_path / "result.txt",
                   data=granular / "data.lammps")
    assert written == [tmp_path / "result.txt"]
    frames = dump_frames(granular / "atoms.dump")
    tp = read_time_points(tmp_path / "result.txt", tags=(12, 15, 20))
    assert len(tp.times) == len(frames)
    ids = frames[0].column("id").astype(int)
    np.testing.assert_array_equal(tp.ids, np.sort(ids))
    assert (tp.types == 1).all()
    for k, f in enumerate(frames):
        order = np.argsort(f.column("id"))
        for tag, cols in ((12, ("x", "y", "z")), (15, ("vx", "vy", "vz")), (20, ("fx", "fy", "fz"))):
            want = f.vector(*cols)[order]
            # MUSEN's default 6 significant digits
            np.testing.assert_allclose(tp.fields[tag][k], want, rtol=6e-6, atol=1e-12)
    model = read(tmp_path / "result.txt")          # the whole result as a scene: same spheres
    assert model.spheres.count == len(ids)
    np.testing.assert_allclose(model.spheres.radius, frames[0].column("radius")[np.argsort(ids)],
                               rtol=1e-6)


def test_demdf_round_trip(granular, tmp_path):  # noqa: F811
    written = post(granular / "atoms.dump", "demdf", tmp_path / "snap", data=granular / "data.lammps")
    frames = dump_frames(granular / "atoms.dump")
    assert [p.name for p in written] == [f"snap_{k}.json" for k in range(len(frames))]
    for path, f in zip(written, frames):
        snap = read_snapshot(path)
        order = np.argsort(f.column("id"))
        np.testing.assert_array_equal(snap.spheres.position, f.vector("x", "y", "z")[order])
        np.testing.assert_array_equal(snap.spheres.velocity, f.vector("vx", "vy", "vz")[order])


def test_musen_needs_radii(tmp_path):
    dump = tmp_path / "points.dump"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n"
                    "0 1\n0 1\n0 1\nITEM: ATOMS id type x y z\n1 1 0.1 0.1 0.1\n2 1 0.5 0.5 0.5\n")
    with pytest.raises(InputError, match="radius"):
        post(dump, "musen", tmp_path / "r.txt")
