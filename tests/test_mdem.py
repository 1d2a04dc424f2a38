"""MUSEN .mdem files: the real cmusen's files read exactly as cmusen exports them, written back
byte for byte, MUSEN's example scenes read to the model of their text exports, results
written as .mdem equal the text results, and the time-point codec's two paths agree."""

from __future__ import annotations

import dataclasses
import shutil
import zlib
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen import scene as text_scene
from fibrelmp.translate.musen.mdem import timepoints as tp
from fibrelmp.translate.musen.mdem.container import Container, block_size
from fibrelmp.translate.musen.mdem.document import MdemFile, MdemWriter
from fibrelmp.translate.musen.mdem.model import read_scene
from fibrelmp.translate.musen.text import read_time_points

from .conftest import REPO

BOUNCE = REPO / "tests" / "data" / "real-outputs" / "musen" / "bounce"
INPUTS = REPO / "tests" / "data" / "real-inputs" / "musen"
EXAMPLES = ["SingelParticle.mdem", "SphericalAgglomerate.mdem", "CompressionTest.mdem",
            "PackingGeneration.mdem"]


def test_block_sizes_follow_musen():
    # CMDEMFile::GetBlockSizeByIndex's table: 4, 4, 8, 12, 16, 24, 32, 48, 64, 96, 128 KB
    assert [block_size(i) // 1024 for i in range(11)] == [4, 4, 8, 12, 16, 24, 32, 48, 64, 96, 128]


def test_bounce_result_reads_exactly_as_cmusen_exported_it(tmp_path):
    """Every field of every time point: fibrelmp's text of cmusen's .mdem is cmusen's own
    17-digit export, byte for byte."""
    out = tmp_path / "bounce.txt"
    python_api.convert_file(BOUNCE / "bounce_result.mdem", out, precision=17)
    assert out.read_bytes() == (BOUNCE / "bounce_result_prec17.txt").read_bytes()


@pytest.mark.parametrize("path", [BOUNCE / "bounce_result.mdem"] + [INPUTS / n for n in EXAMPLES],
                         ids=lambda p: p.name)
def test_read_then_write_is_byte_identical(tmp_path, path):
    """Every message decoded and serialized again, every block recompressed (zlib level 1),
    at the block offsets the file had; the unused bytes some files carry (earlier saves' data
    in block slack) are kept too."""
    out = tmp_path / "again.mdem"
    python_api.convert_file(path, out)
    assert out.read_bytes() == path.read_bytes()
    with Container(path) as c:
        stale = c.layout().stale
    # SingelParticle and CompressionTest carry such bytes; without them the files differ only there
    if stale:
        data, again = bytearray(path.read_bytes()), bytearray(path.read_bytes())
        for offset, chunk in stale:
            again[offset:offset + len(chunk)] = bytes(len(chunk))
        with MdemFile(path) as mdem, Container(path) as c:
            assert c.read(0, 0, c.sizes[0]) == zlib.compress(mdem.storage.SerializeToString(), 1)
        assert data != again


def _text_value(x: np.ndarray) -> np.ndarray:
    """What a C++ ostream with precision 6 prints, read back."""
    return np.vectorize(lambda v: float("%g" % v) if np.isfinite(v) else v)(x)


def _same_at_text_precision(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return False
    if a.dtype.kind not in "fc":
        return np.array_equal(a, b)
    return bool(np.all((a == b) | (_text_value(a) == b) | (np.isnan(a) & np.isnan(b))))


@pytest.mark.parametrize("name", ["SingelParticle", "SphericalAgglomerate"])
def test_example_scenes_read_to_the_model_of_their_text_exports(name):
    """MUSEN's example scenes exist as .mdem and as MUSEN's text export: both read to the same
    model, every number equal to the text's digits."""
    binary = read_scene(INPUTS / f"{name}.mdem")
    text = text_scene.read(INPUTS / f"{name}_text.txt")
    for part in ("spheres", "bonds", "triangles"):
        a, b = getattr(binary, part), getattr(text, part)
        assert (a is None) == (b is None), part
        if a is None:
            continue
        for f in dataclasses.fields(a):
            x, y = getattr(a, f.name), getattr(b, f.name)
            assert (x is None) == (y is None), f"{part}.{f.name}"
            if x is not None:
                assert _same_at_text_precision(np.asarray(x), np.asarray(y)), f"{part}.{f.name}"
    # MUSEN's old exporter (these text files) left out heat capacity (1) and thermal
    # conductivity (3): the text reads MUSEN's defaults for them, the .mdem its real values
    for a, b in zip(binary.materials, text.materials, strict=True):
        assert {k: v for k, v in a.props.items() if k not in (1, 3)} == \
               {k: v for k, v in b.props.items() if k not in (1, 3)}
        a.props, b.props = {}, {}
        assert a == b
    assert binary.contacts == text.contacts
    assert [(g.name, g.key, g.mass, g.free, g.motion_type, list(g.triangle_rows))
            for g in binary.geometries] == [(g.name, g.key, g.mass, g.free, g.motion_type,
                                             list(g.triangle_rows)) for g in text.geometries]
    assert all(np.array_equal(x, y) for x, y in zip(binary.plan.domain, text.plan.domain))
    assert binary.source == INPUTS / f"{name}.mdem"


def test_text_to_mdem_and_back_is_the_same_text(tmp_path):
    python_api.convert_file(BOUNCE / "bounce_result_prec17.txt", tmp_path / "r.mdem")
    python_api.convert_file(tmp_path / "r.mdem", tmp_path / "r.txt", precision=17)
    assert (tmp_path / "r.txt").read_bytes() == (BOUNCE / "bounce_result_prec17.txt").read_bytes()


def test_import_from_text_equals_cmusens_import(tmp_path):
    """MUSEN's single-particle scene imported by fibrelmp and by the real cmusen
    (IMPORT_FROM_TEXT, bounce_init_cmusen.mdem): the same scene message (but for the date
    MUSEN stamps on each compound) and the same time point, byte for byte."""
    ours = tmp_path / "init.mdem"
    python_api.convert_file(REPO / "examples" / "musen" / "SingelParticle_text.txt", ours)
    with MdemFile(ours) as a, MdemFile(BOUNCE / "bounce_init_cmusen.mdem") as b:
        for mdem in (a, b):
            for c in mdem.storage.modules_data.materials_database.compound:
                c.ClearField("creationDate")
        assert a.storage.SerializeToString() == b.storage.SerializeToString()
        assert [t.SerializeToString() for t in a.block(0).time_points] == \
               [t.SerializeToString() for t in b.block(0).time_points]


def _run_single_particle(folder: Path, result: str) -> None:
    shutil.copy(REPO / "examples" / "musen" / "SingelParticle_text.txt", folder)
    (folder / "job.txt").write_text(
        "JOB\nSOURCE_FILE SingelParticle_text.txt\nRESULT_FILE init.mdem\nCOMPONENT IMPORT_FROM_TEXT\n"
        f"JOB\nSOURCE_FILE init.mdem\nRESULT_FILE {result}\nCOMPONENT SIMULATOR\n"
        "MODEL_PP ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\nSIMULATION_STEP 1e-7\n"
        "SAVING_STEP 5e-4\nEND_TIME 0.012\nEXT_ACCEL 0 0 -9.81\n"
        f"JOB\nSOURCE_FILE {result}\nRESULT_FILE ./result.txt\nCOMPONENT EXPORT_TO_TEXT\n"
        "TEXT_EXPORT_PRECISION 17\n")
    python_api.run(folder / "job.txt")


def test_result_mdem_equals_the_text_result(tmp_path):
    """A run writes its result as .mdem and (through the same frames) as 17-digit text: MUSEN's
    export of the .mdem has the text result's values in every field (the stress tensor 36,
    stored, and the principal stresses 42 computed from it included), its object lines and
    scene lines.  (The real cmusen's export of such a file is the same, docs/musen.md.)"""
    _run_single_particle(tmp_path, "result.mdem")
    assert (tmp_path / "init.mdem").exists() and (tmp_path / "result.mdem").exists()
    python_api.convert_file(tmp_path / "result.mdem", tmp_path / "export.txt", precision=17)
    ours, text = read_time_points(tmp_path / "export.txt"), read_time_points(tmp_path / "result.txt")
    # cmusen's summed clock reaches END_TIME one step late: 24 saves, then 0.0120001 s
    # (tests/test_musen_clock.py: cmusen's loop)
    assert np.array_equal(ours.times, text.times) and len(ours.times) == 26
    assert np.array_equal(ours.ids, text.ids)
    assert set(ours.fields) == set(text.fields) and {36, 42} <= set(text.fields)
    for tag in text.fields:
        assert np.array_equal(ours.fields[tag], text.fields[tag], equal_nan=True), tag
    lines = [(tmp_path / n).read_text().splitlines() for n in ("export.txt", "result.txt")]
    heads = [[ln.split(" 2 ")[0] for ln in f if ln.startswith("0 ")] for f in lines]
    assert heads[0] == heads[1]
    assert [ln for ln in lines[0] if not ln.startswith("0 ")] == \
           [ln for ln in lines[1] if not ln.startswith("0 ")]
    # the sphere bounced: its saved z velocity changed sign
    vz = ours.fields[15][:, -1, 2]
    assert vz[0] < 0 < vz[-1]


def test_mdem_scene_runs_and_its_result_is_mdem(tmp_path):
    scene = tmp_path / "SingelParticle.mdem"
    shutil.copy(INPUTS / "SingelParticle.mdem", scene)
    result = python_api.run(scene, end_time=2e-3, step=1e-7, save_step=1e-3)
    target = tmp_path / "SingelParticle_result.mdem"
    assert result.outputs == [target]
    with MdemFile(target) as mdem:
        times = [t for t, _, _ in mdem.time_points()]
        # the source's materials, geometry and its GUI data are kept
        with MdemFile(scene) as src:
            assert mdem.storage.modules_data.materials_database == src.storage.modules_data.materials_database
            assert list(mdem.info.real_geometry_v0) == list(src.info.real_geometry_v0)
    np.testing.assert_allclose(times, [0, 1e-3, 2e-3], rtol=1e-9)


def test_script_exports_an_mdem_made_elsewhere(tmp_path):
    shutil.copy(BOUNCE / "bounce_result.mdem", tmp_path)
    (tmp_path / "job.txt").write_text("JOB\nSOURCE_FILE bounce_result.mdem\nRESULT_FILE ./b.txt\n"
                                      "COMPONENT EXPORT_TO_TEXT\nTEXT_EXPORT_PRECISION 17\n")
    python_api.run(tmp_path / "job.txt")
    assert (tmp_path / "b.txt").read_bytes() == (BOUNCE / "bounce_result_prec17.txt").read_bytes()


def _random_time_point(rng, n):
    values = rng.normal(size=(n, tp.NCOLS))
    values[rng.random(values.shape) < 0.3] = 0.0
    values[rng.random(values.shape) < 0.05] = -0.0
    masks = np.zeros(n, np.uint32)
    for name, (number, _, _) in tp.FIELDS.items():
        masks |= np.where(rng.random(n) < 0.6, np.uint32(1 << number), np.uint32(0))
    # fields not on the wire read as zero
    for name, (number, first, k) in tp.FIELDS.items():
        values[(masks >> number & 1) == 0, first:first + k] = 0.0
    return values, masks


def test_time_point_codec_c_and_protobuf_agree():
    from fibrelmp.numtext import fast

    if fast.library() is None:
        pytest.skip("no C helpers here: " + fast.active_path())
    rng = np.random.default_rng(7)
    for n in (0, 1, 37, 500):
        values, masks = _random_time_point(rng, n)
        time = float(rng.random())
        ours, theirs = tp.encode(time, values, masks), tp.encode_py(time, values, masks)
        assert ours == theirs
        # a scalar field equal to +0.0 is not on the wire (proto3), so not in the mask read
        wire = masks.copy()
        for name in ("total_torque", "temperature", "liquid_film_mass"):
            number, first, _ = tp.FIELDS[name]
            zero = values[:, first].view(np.uint64) == 0
            wire[zero] &= ~np.uint32(1 << number)
        for decoded in (tp.decode(ours), tp.decode_py(ours)):
            assert decoded[0] == time
            assert decoded[1].tobytes() == values.tobytes()     # -0.0 kept
            assert np.array_equal(decoded[2], wire)


def test_malformed_time_point_is_an_error():
    with pytest.raises(ValueError):
        tp.decode(b"\x12\x05\x0a\x03\x09\x00")              # a double cut short


def _spoil(tmp_path: Path, edit) -> Path:
    """A small file written by MdemWriter, its scene message edited before it is written."""
    from fibrelmp.translate.musen.mdem.messages import new

    path = tmp_path / "spoilt.mdem"
    with open(path, "w+b") as fh:
        out = MdemWriter(fh)
        out.add(0.0, np.ones((3, tp.NCOLS)), np.full(3, tp.bit("coord"), np.uint32))
        storage = new("ProtoSimulationStorage")
        for _ in range(3):
            storage.info.particles.add(type=1, encoded_properties=b"\0" * 16)
        real = out.finish
        out.finish = lambda s: (real(s), None)[1]
        out.finish(storage)
    if edit is not None:
        with MdemFile(path) as mdem:
            storage = mdem.storage
            blocks = [mdem.block_raw(i) for i in range(len(storage.data_blocks))]
        edit(storage)
        with open(path, "w+b") as fh:
            from fibrelmp.translate.musen.mdem.container import ContainerWriter

            w = ContainerWriter(fh)
            w._block(0, 0)
            w.write(1, 0, blocks[0])
            w.write(0, 0, zlib.compress(storage.SerializeToString(), 1))
            w.finish()
    return path


@pytest.mark.parametrize("edit, message", [
    (lambda s: setattr(s.data_blocks[0], "size", 1 << 30), "lies beyond its end"),
    (lambda s: setattr(s.data_blocks[0], "uncompressed_size", 10), "larger than its descriptor says"),
    (lambda s: setattr(s.data_blocks[0], "format", 9), "storage format 9"),
    (lambda s: s.info.particles.add(type=77), "unsupported MUSEN object type(s) [77]"),
    (lambda s: s.ClearField("data_blocks"), "lists no time-point blocks"),
    (lambda s: setattr(s.data_blocks[0], "uncompressed_size", -5), "uncompressed size -5"),
])
def test_hostile_descriptors_are_input_errors(tmp_path, edit, message):
    path = _spoil(tmp_path, edit)
    with pytest.raises(InputError) as err:
        python_api.convert_file(path, tmp_path / "out.txt")
    assert message in err.value.message and err.value.path == str(path)
    assert not (tmp_path / "out.txt").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spoilt.mdem"]


def test_reader_gives_the_scene_and_frames_of_the_file():
    """MdemReader (the abstract Reader): the scene, then every saved time point as a frame,
    equal to cmusen's 17-digit export of the same file."""
    from fibrelmp.translate.musen.mdem.model import MdemReader

    reader = MdemReader(BOUNCE / "bounce_result.mdem")
    model = reader.read()
    assert model.spheres.count == 1 and model.triangles.count == 12
    frames = list(reader)
    text = read_time_points(BOUNCE / "bounce_result_prec17.txt")
    assert np.array_equal([f.time for f in frames], text.times)
    sphere = list(text.ids).index(12)
    for k, f in enumerate(frames):
        assert np.array_equal(f.position[0], text.fields[12][k, sphere])
        assert np.array_equal(f.velocity[0], text.fields[15][k, sphere])
        assert np.array_equal(f.triangle_vertices.reshape(12, 9), text.fields[44][k, :12])


def test_script_on_musens_compression_example_keeps_what_the_run_changed(tmp_path):
    """MUSEN's Example 7 (scripts/"Example 7 - Modified material parameters.txt": its
    CompressionTest.mdem with density 3000 and sliding friction 0.1), shortened: the file's
    own models (Kelvin bonds), gravity and moving wall are used; the .mdem result carries the
    changed values, the wall's motion in the current geometry list, and exports to the same
    scene lines as fibrelmp's text result of the same run."""
    shutil.copy(INPUTS / "CompressionTest.mdem", tmp_path)
    (tmp_path / "job.txt").write_text(
        "JOB\nSOURCE_FILE CompressionTest.mdem\nRESULT_FILE ./result.mdem\nCOMPONENT SIMULATOR\n"
        "SIMULATION_STEP 2e-8\nSAVING_STEP 5e-7\nEND_TIME 1e-6\n"
        "MATERIAL_PROPERTY DENSITY KF6843H84OPHH3017U3D 3000\n"
        "INTERACTION_PROPERTY SLIDING_FRICTION KF6843H84OPHH3017U3D KF6843H84OPHH3017U3D 0.1\n"
        "JOB\nSOURCE_FILE result.mdem\nRESULT_FILE ./result.txt\nCOMPONENT EXPORT_TO_TEXT\n"
        "TEXT_EXPORT_PRECISION 17\n")
    run = python_api.run(tmp_path / "job.txt")
    kinds = {kind for kind, _ in run.warnings}
    assert "musen-default-settings" not in kinds                 # the file's gravity was used
    python_api.convert_file(tmp_path / "result.mdem", tmp_path / "export.txt", precision=17)
    lines = [(tmp_path / n).read_text().splitlines() for n in ("export.txt", "result.txt")]
    scene = [ln for ln in lines[0] if not ln.startswith("0 ")]
    assert scene == [ln for ln in lines[1] if not ln.startswith("0 ")]
    assert "32 KF6843H84OPHH3017U3D Glass 0 3000 " in "\n".join(scene)
    assert "33 KF6843H84OPHH3017U3D KF6843H84OPHH3017U3D 200 0.9 201 0.1 202 0.05 " in scene
    assert "26 1 1 0 99 0 0 -0.1 0 0 0 0 0 0  " in scene              # UpperWall moves down
    with MdemFile(tmp_path / "result.mdem") as mdem:
        assert mdem.info.version == 1 and len(mdem.info.real_geometry) == 2
        assert [m.path for m in mdem.storage.modules_data.model_manager.models] == \
               ["ModelPPHertzMindlin", "ModelPWHertzMindlin", "ModelSBKelvin"]
        assert list(mdem.storage.modules_data.simulator.external_acceleration.ListFields())
    ours, text = read_time_points(tmp_path / "export.txt"), read_time_points(tmp_path / "result.txt")
    for tag in text.fields:
        assert np.array_equal(ours.fields[tag], text.fields[tag], equal_nan=True), tag


@pytest.mark.parametrize("line, message", [
    ("39 vol", "`39` line cannot be imported: too few values"),
    ("34 MIX", "`34` line cannot be imported: too few values"),
    ("29 abc", "`29` line cannot be imported"),
])
def test_text_import_of_bad_scene_lines_is_an_input_error(tmp_path, line, message):
    text = (REPO / "examples" / "musen" / "SingelParticle_text.txt").read_text() + line + "\n"
    (tmp_path / "s.txt").write_text(text)
    with pytest.raises(InputError) as err:
        python_api.convert_file(tmp_path / "s.txt", tmp_path / "s.mdem")
    assert message in err.value.message and err.value.line == text.count("\n")
    assert not (tmp_path / "s.mdem").exists()


def test_text_import_refuses_ids_far_beyond_the_object_count(tmp_path):
    """.mdem files index objects by id: id 2e7 for one object would be 2e7 empty entries."""
    (tmp_path / "s.txt").write_text("0 20000000 1 1 5 0.001 0.001 23 X 24 0 1e300 2 0 12 0 0 0\n"
                                    "32 X glass 0 1000\n")
    with pytest.raises(InputError, match="far beyond the 1 objects"):
        python_api.convert_file(tmp_path / "s.txt", tmp_path / "s.mdem")


def test_copy_keeps_blocks_another_zlib_compressed(tmp_path):
    """A block compressed by another zlib or level (here 9) is kept as stored: the copy is
    the same file and reads the same, never a block that no longer fits its descriptor."""
    from fibrelmp.translate.musen.mdem.container import ContainerWriter

    with MdemFile(BOUNCE / "bounce_result.mdem") as mdem:
        storage = mdem.storage
        blocks = [zlib.compress(mdem.block_bytes(i), 9) for i in range(len(storage.data_blocks))]
    at = 0
    for d, b in zip(storage.data_blocks, blocks):
        d.offset_in_file, d.size = at, len(b)
        at += len(b)
    with open(tmp_path / "l9.mdem", "w+b") as fh:
        w = ContainerWriter(fh)
        w._block(0, 0)
        w.write(1, 0, b"".join(blocks))
        w.write(0, 0, zlib.compress(storage.SerializeToString(), 9))
        w.finish()
    python_api.convert_file(tmp_path / "l9.mdem", tmp_path / "copy.mdem")
    assert (tmp_path / "copy.mdem").read_bytes() == (tmp_path / "l9.mdem").read_bytes()
    python_api.convert_file(tmp_path / "copy.mdem", tmp_path / "copy.txt", precision=17)
    assert (tmp_path / "copy.txt").read_bytes() == (BOUNCE / "bounce_result_prec17.txt").read_bytes()
