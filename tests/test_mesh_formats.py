"""Finite-element mesh formats (CardioProof): openCARP text/binary and VTK round trips, the
openCARP layouts checked byte by byte against hand-made files, .dynpt frames.  The checks
every mesh/motion format gets are in tests/conformance/ (test_opencarp, test_vtk_mesh, test_dynpt)."""

from __future__ import annotations

import re
import struct
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.errors import InputError
from fibrelmp.mesh.opencarp.dynpt import HEADER, DynptReader, DynptWriter, igb_header
from fibrelmp.mesh.opencarp.mesh import OpenCarpMeshReader, OpenCarpMeshWriter

from .conformance.base import mixed_mesh as _mesh      # a tetra, a prism and two triangles, in µm


@pytest.mark.parametrize("binary", [False, True], ids=["text", "binary"])
def test_opencarp_round_trip(tmp_path, binary):
    mesh = _mesh()
    with OpenCarpMeshWriter(tmp_path / "heart", binary=binary) as w:
        w.add(mesh)
    again = OpenCarpMeshReader(tmp_path / ("heart.belem" if binary else "heart.elem")).read()
    assert again.equals(mesh) and again.unit == 1e-6
    # written again: the same bytes
    with OpenCarpMeshWriter(tmp_path / "again", binary=binary) as w:
        w.add(again)
    ext = (".bpts", ".belem") if binary else (".pts", ".elem")
    for e in ext:
        assert (tmp_path / f"again{e}").read_bytes() == (tmp_path / f"heart{e}").read_bytes()


def test_opencarp_text_layout_and_units(tmp_path):
    (tmp_path / "m.pts").write_text("4\n0 0 0\n1000 0 0\n0 2000.5 0\n0 0 3000\n")
    (tmp_path / "m.elem").write_text("3\nTt 0 1 2 3 7\nTr 0 1 2\nCx 2 3 1\n")
    mesh = OpenCarpMeshReader(tmp_path / "m.pts").read()
    np.testing.assert_array_equal(mesh.points_m[2], [0.0, 2000.5e-6, 0.0])
    assert [(b.kind, b.nodes.tolist(), b.tags.tolist()) for b in mesh.cells] == \
           [("tetra", [[0, 1, 2, 3]], [7]), ("triangle", [[0, 1, 2]], [0]), ("line", [[2, 3]], [1])]


def test_opencarp_binary_layout(tmp_path):
    """meshtool's layout, built by hand: header "count 0 666" NUL-padded to 1024 bytes,
    float32 points, per element int32 type code, nodes, region."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], "<f4") * 1000
    (tmp_path / "m.bpts").write_bytes(b"4 0 666".ljust(1024, b"\0") + pts.tobytes())
    elems = struct.pack("<6i", 0, 0, 1, 2, 3, 5) + struct.pack("<5i", 6, 0, 1, 2, 9)
    (tmp_path / "m.belem").write_bytes(b"2 0 666".ljust(1024, b"\0") + elems)
    mesh = OpenCarpMeshReader(tmp_path / "m").read()           # a base name: binary preferred
    assert [(b.kind, b.nodes.tolist(), b.tags.tolist()) for b in mesh.cells] == \
           [("tetra", [[0, 1, 2, 3]], [5]), ("triangle", [[0, 1, 2]], [9])]
    with OpenCarpMeshWriter(tmp_path / "w", binary=True) as w:
        w.add(mesh)
    assert (tmp_path / "w.bpts").read_bytes() == (tmp_path / "m.bpts").read_bytes()
    assert (tmp_path / "w.belem").read_bytes() == (tmp_path / "m.belem").read_bytes()


@pytest.mark.parametrize("files, message", [
    ({"m.pts": "3\n0 0 0\n1 1 1\n", "m.elem": "0\n"}, "says 3 entries but has 2 lines"),
    ({"m.pts": "1\n0 0 x\n", "m.elem": "0\n"}, "expected x y z"),
    ({"m.pts": "1\n0 0 0\n", "m.elem": "1\nZz 0 0 0\n"}, "unknown element type 'Zz'"),
    ({"m.pts": "1\n0 0 0\n", "m.elem": "1\nTr 0 0 5\n"}, "node index outside 0..0"),
    ({"m.pts": "1\n0 0 0\n", "m.elem": "1\nTr 0 0\n"}, "Tr needs 3 node indices"),
])
def test_bad_opencarp_files_are_input_errors(tmp_path, files, message):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    with pytest.raises(InputError) as err:
        OpenCarpMeshReader(tmp_path / "m.pts").read()
    assert message in err.value.message and err.value.line is not None


def test_truncated_binary_mesh(tmp_path):
    (tmp_path / "m.bpts").write_bytes(b"4 0 666".ljust(1024, b"\0") + bytes(12 * 3))
    (tmp_path / "m.belem").write_bytes(b"0 0 666".ljust(1024, b"\0"))
    with pytest.raises(InputError, match="header says 4 points"):
        OpenCarpMeshReader(tmp_path / "m").read()


def test_vtk_mesh_round_trip(tmp_path):
    pytest.importorskip("meshio")
    from fibrelmp.mesh.vtkmesh.mesh import VtkMeshReader, VtkMeshWriter

    mesh = _mesh()
    for name in ("m.vtu", "m.vtk"):
        with VtkMeshWriter(tmp_path / name) as w:             # written in metres
            w.add(mesh)
        again = VtkMeshReader(tmp_path / name).read()
        np.testing.assert_allclose(again.points_m, mesh.points_m, rtol=1e-15)
        assert [(b.kind, b.nodes.tolist(), b.tags.tolist()) for b in again.cells] == \
               [(b.kind, b.nodes.tolist(), b.tags.tolist()) for b in mesh.cells]
        with VtkMeshWriter(tmp_path / f"again_{name}") as w:
            w.add(again)
        assert VtkMeshReader(tmp_path / f"again_{name}").read().equals(again)


def test_dynpt_frames_and_header(tmp_path):
    rng = np.random.default_rng(5)
    frames = [(rng.random((7, 3)) * 1e3).astype(np.float32).astype(np.float64) for _ in range(4)]
    with DynptWriter(tmp_path / "move.dynpt", inc_t=2.5, org_t=1.0) as w:
        for f in frames:
            w.add(f)
    data = (tmp_path / "move.dynpt").read_bytes()
    assert len(data) == HEADER + 4 * 7 * 12 and data[HEADER - 1:HEADER] == b"\f"
    assert data.startswith(b"x:7 y:1 z:1 t:4 type:vec3f systeme:little_endian ")
    reader = DynptReader(tmp_path / "move.dynpt")
    read = list(reader)
    assert reader.count == len(read) == 4 and reader.nodes == 7       # the header's t
    assert [f.time for f in read] == [1.0, 3.5, 6.0, 8.5]
    for a, b in zip(read, frames):
        assert np.array_equal(a.points, b)


def test_dynpt_written_by_another_tool(tmp_path):
    """A header as meshalyzer writes it (items on CRLF lines, space padding, form feed)."""
    head = (b"x:2 y:1 z:1 t:3 type:vec3f systeme:little_endian \r\norg_t:0 dim_t:2 inc_t:1 "
            b"unites_t:ms \r\n")
    head = head + b" " * (HEADER - len(head) - 1) + b"\f"
    values = np.arange(18, dtype="<f4")
    (tmp_path / "a.dynpt").write_bytes(head + values.tobytes())
    read = list(DynptReader(tmp_path / "a.dynpt"))
    assert len(read) == 3 and np.array_equal(read[2].points, values[12:].reshape(2, 3))


@pytest.mark.parametrize("edit, message", [
    (lambda d: d[:HEADER + 10], "header says 3 frames"),
    (lambda d: d.replace(b"vec3f", b"float"), "a .dynpt holds positions"),
    (lambda d: d.replace(b"t:3", b"t:x"), "integer x, y, z and t"),
    (lambda d: d[:500], "shorter than the IGB header"),
])
def test_bad_dynpt_files(tmp_path, edit, message):
    good = igb_header(2, 3, 1.0, 0.0, "ms") + np.zeros(18, "<f4").tobytes()
    (tmp_path / "b.dynpt").write_bytes(edit(good))
    with pytest.raises(InputError, match=message):
        list(DynptReader(tmp_path / "b.dynpt"))


# -- hostile files (issue 24): every problem an InputError, no traceback, no huge allocation --
def test_text_region_tag_beyond_32_bits_is_an_input_error(tmp_path):
    """A tag of 1e23 (an exact integer) overflowed the int64 tag array (OverflowError)."""
    (tmp_path / "m.pts").write_text("3\n0 0 0\n1 0 0\n0 1 0\n")
    (tmp_path / "m.elem").write_text("1\nTr 0 1 2 " + "1" + "0" * 23 + "\n")
    with pytest.raises(InputError) as err:
        OpenCarpMeshReader(tmp_path / "m.pts").read()
    assert err.value.line == 2 and "region tag" in err.value.message


@pytest.mark.parametrize("points, x, elements, message", [
    (b"-1 0 666", 0.0, b"0 0 666", "says -1 entries (negative)"),
    (b"1 0 666", 0.0, b"-3 0 666", "says -3 entries (negative)"),
    (b"1 0 666", np.nan, b"0 0 666", "point 0: coordinates must be finite"),
])
def test_bad_binary_headers_and_values(tmp_path, points, x, elements, message):
    point = np.array([x, 0, 0], "<f4").tobytes() if points.startswith(b"1 ") else b""
    (tmp_path / "m.bpts").write_bytes(points.ljust(1024, b"\0") + point)
    (tmp_path / "m.belem").write_bytes(elements.ljust(1024, b"\0"))
    with pytest.raises(InputError, match=re.escape(message)):
        OpenCarpMeshReader(tmp_path / "m").read()


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.replace(b"inc_t:1.0", b"inc_t:inf"), "must be finite"),
    (lambda d: d.replace(b"org_t:0.0", b"org_t:nan"), "must be finite"),
    (lambda d: d.replace(b"x:2 ", b"x:" + b"9" * 30 + b" "), "header says 3 frames of 9999"),
    (lambda d: d[:HEADER] + np.full(18, np.nan, "<f4").tobytes(), "frame 0: positions must be finite"),
])
def test_hostile_dynpt_headers_and_values(tmp_path, edit, message):
    good = igb_header(2, 3, 1.0, 0.0, "ms") + np.zeros(18, "<f4").tobytes()
    bad = edit(good)
    if len(bad[:HEADER]) != HEADER:              # an edit that changed the header's length
        bad = bad[:HEADER - 1].ljust(HEADER - 1) + b"\f" + bad[HEADER:]
    (tmp_path / "b.dynpt").write_bytes(bad)
    with pytest.raises(InputError, match=message):
        list(DynptReader(tmp_path / "b.dynpt"))


def _vtu_text(tmp: Path, binary: bool) -> str:
    meshio = pytest.importorskip("meshio")
    mesh = _mesh()
    meshio.write(tmp / "good.vtu", meshio.Mesh(mesh.points_m, [(b.kind, b.nodes) for b in mesh.cells],
                                               cell_data={"region": [b.tags for b in mesh.cells]}), binary=binary)
    return (tmp / "good.vtu").read_text()


@pytest.mark.parametrize("make, message", [
    (lambda tmp: bytes(np.random.default_rng(3).integers(0, 256, 3000, np.uint8)), "cannot read as a VTK XML unstructured grid"),
    (lambda tmp: _vtu_text(tmp, True).replace('NumberOfCells="', 'NumberOfCells="99999').encode(), "cannot read"),
    (lambda tmp: _vtu_text(tmp, False).replace('NumberOfPoints="', 'NumberOfPoints="99999').encode(), "cannot read"),
])
def test_hostile_vtu_is_an_input_error_not_a_system_exit(tmp_path, make, message):
    """meshio.read() prints and calls sys.exit(1) on a file it cannot read: the CLI then said
    nothing and fibrelmp.check() raised SystemExit."""
    pytest.importorskip("meshio")
    from fibrelmp.mesh.vtkmesh.mesh import VtkMeshReader

    (tmp_path / "m.vtu").write_bytes(make(tmp_path))
    with pytest.raises(InputError, match=message):
        VtkMeshReader(tmp_path / "m.vtu").read()


def test_structured_vtk_header_cannot_allocate_gigabytes(tmp_path):
    """A legacy STRUCTURED_POINTS header of 1e5^3 points: meshio would generate 1e15 hexahedra
    from three numbers.  Refused from the header, in a subprocess capped at 1.5 GB."""
    import resource
    import subprocess
    import sys

    pytest.importorskip("meshio")
    (tmp_path / "m.vtk").write_text("# vtk DataFile Version 4.2\nhostile\nASCII\nDATASET STRUCTURED_POINTS\n"
                                    "DIMENSIONS 100000 100000 100000\nORIGIN 0 0 0\nSPACING 1 1 1\n")
    code = ("from fibrelmp.mesh.vtkmesh.mesh import VtkMeshReader\n"
            "from fibrelmp.errors import InputError\n"
            f"try:\n    VtkMeshReader({str(tmp_path / 'm.vtk')!r}).read()\n"
            "except InputError as e:\n    print(e)\n")

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (1536 << 20, 1536 << 20))

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         preexec_fn=cap, env={**__import__("os").environ, "OPENBLAS_NUM_THREADS": "1"})
    assert out.returncode == 0, out.stderr
    assert "m.vtk:4: expected DATASET UNSTRUCTURED_GRID or POLYDATA" in out.stdout
