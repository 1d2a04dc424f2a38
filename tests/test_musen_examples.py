"""The MUSEN examples run through the CLI, checked from the result files they write."""

from __future__ import annotations

import shutil
import subprocess
import sys

import numpy as np
import pytest

from fibrelmp.translate.musen.scene import read, read_time_points

from .conftest import REPO

EXAMPLES = REPO / "examples" / "musen"


def _cli(args, cwd):
    return subprocess.run([sys.executable, "-m", "fibrelmp.cli", *args], cwd=cwd,
                          capture_output=True, text=True)


def _example(tmp_path, *names):
    for name in names:
        shutil.copy(EXAMPLES / name, tmp_path)
    return tmp_path


def _rebound_restitution(times, z, vz, contact_z, g):
    """Restitution from the free flights either side of the (short) impact: fit the
    ballistic arcs, find when the sphere reaches the plate, compare speeds there."""
    before = np.flatnonzero((vz < 0) & (z > contact_z))
    hit = before[-1]
    after = np.flatnonzero((np.arange(times.size) > hit) & (vz > 0))
    # impact time from the last free-flight sample: z_k + v_k s - g s^2/2 = contact_z
    zk, vk = z[hit], vz[hit]
    s = (vk + np.sqrt(vk * vk + 2 * g * (zk - contact_z))) / g
    t_hit = times[hit] + s
    v_in = vk - g * s
    # outgoing speed: least-squares line through the upward samples, at t_hit
    a = after[:20]
    slope, icpt = np.polyfit(times[a], vz[a], 1)
    assert slope == pytest.approx(-g, rel=1e-3)     # really free flight after the bounce
    v_out = slope * t_hit + icpt
    return -v_out / v_in


def test_single_particle_rebounds_with_line_33_restitution(tmp_path):
    folder = _example(tmp_path, "single_particle_job.txt", "SingelParticle_text.txt")
    done = _cli(["--quiet", "run", "single_particle_job.txt"], folder)
    assert done.returncode == 0, done.stderr
    result = folder / "single_particle_result.txt"
    tp = read_time_points(result, tags=(12, 15))
    sphere = np.flatnonzero(tp.types == 1)[0]
    z = tp.fields[12][:, sphere, 2]
    vz = tp.fields[15][:, sphere, 2]
    scene = read(folder / "SingelParticle_text.txt")
    plate_top = scene.triangles.vertices[..., 2].max()
    radius = scene.spheres.radius[0]
    steel = next(i for i, m in enumerate(scene.materials) if m.name == "Steel")
    glass = next(i for i, m in enumerate(scene.materials) if m.name == "Glass")
    e_line_33 = scene.contact(steel, glass).restitution
    assert e_line_33 == 0.8
    e = _rebound_restitution(tp.times, z, vz, plate_top + radius, 9.81)
    assert e == pytest.approx(e_line_33, rel=0.02)
    # the sphere is not at rest on the plate afterwards: it really left it
    assert z[-1] > plate_top + radius + 1e-4


def test_bare_scene_with_command_line_times(tmp_path):
    folder = _example(tmp_path, "SingelParticle_text.txt")
    done = _cli(["run", "SingelParticle_text.txt", "--end-time", "0.005", "--step", "1e-7",
                 "--save-step", "1e-3", "--precision", "17", "-o", "bare.txt"], folder)
    assert done.returncode == 0, done.stderr
    assert "gravity 0 0 -9.81" in done.stderr
    tp = read_time_points(folder / "bare.txt", tags=(12, 15))
    np.testing.assert_allclose(tp.times[:6], np.arange(6) * 1e-3, atol=1e-12)
    sphere = np.flatnonzero(tp.types == 1)[0]
    # free fall from the start state in MUSEN's leapfrog (prediction half kick, then kick and
    # move): z = z0 + v0 t - g dt^2 (n^2/2 + n) at step n (MUSEN's default gravity)
    t, dt = tp.times, 1e-7
    n = np.rint(t / dt)
    expected = 0.005 - 0.5 * t - 9.81 * dt * dt * (n * n / 2 + n)
    np.testing.assert_allclose(tp.fields[12][:, sphere, 2], expected, rtol=0, atol=1e-12)


def test_mdem_result_name_gives_an_mdem_result(tmp_path):
    from fibrelmp.translate.musen.mdem.document import MdemFile

    folder = _example(tmp_path, "SingelParticle_text.txt")
    (folder / "job.txt").write_text(
        "JOB\nSOURCE_FILE SingelParticle_text.txt\nRESULT_FILE out.mdem\nCOMPONENT SIMULATOR\n"
        "MODEL_PP ModelPPHertzMindlin\nMODEL_PW ModelPWHertzMindlin\nSIMULATION_STEP 1e-7\n"
        "SAVING_STEP 1e-3\nEND_TIME 2e-3\n")
    done = _cli(["run", "job.txt"], folder)
    assert done.returncode == 0, done.stderr
    assert not (folder / "out.txt").exists()
    with MdemFile(folder / "out.mdem") as mdem:
        times = [t for t, _, _ in mdem.time_points()]
        assert mdem.storage.modules_data.simulator.simulation_step == 1e-7
    np.testing.assert_allclose(times, [0, 1e-3, 2e-3], rtol=1e-9)


@pytest.mark.parametrize("script, message", [
    ("JOB\nSOURCE_FILE made_elsewhere.mdem\nRESULT_FILE r.mdem\nCOMPONENT SIMULATOR\n",
     "made_elsewhere.mdem: file not found"),
    ("JOB\nSOURCE_FILE r.mdem\nRESULT_FILE ./r.txt\nCOMPONENT EXPORT_TO_TEXT\n",
     "no earlier job of this script produced it"),
    ("JOB\nSOURCE_FILE SingelParticle_text.txt\nRESULT_FILE r.mdem\nCOMPONENT PACKAGE_GENERATOR\n",
     "IMPORT_FROM_TEXT"),
])
def test_script_errors_exit_2(tmp_path, script, message):
    folder = _example(tmp_path, "SingelParticle_text.txt")
    (folder / "job.txt").write_text(script)
    done = _cli(["run", "job.txt"], folder)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr and "Traceback" not in done.stderr
    assert "job.txt:" in done.stderr


def test_a_binary_that_is_no_mdem_is_an_input_error(tmp_path):
    scene = tmp_path / "scene.mdem"
    scene.write_bytes(b"\x08\x96\x01\x00\x12\x07protobuf\x00")
    done = _cli(["run", str(scene)], tmp_path)
    assert done.returncode == 2
    assert "not a MUSEN .mdem file" in done.stderr and "Traceback" not in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.mdem"]
