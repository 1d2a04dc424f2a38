"""The spheres' temperature (a MUSEN heat model's, d_musen_temperature) in what a run shows
besides its MUSEN results: ``summary.json`` (min, mean, max per saved frame), ``fibrelmp plot``
(LAMMPS's thermo columns TemperatureMin/Mean/Max; from a result's frames: temperature min,
mean, max) and ``--also vtk`` (point data "temperature").  Every figure is compared with the
temperatures of the run's own MUSEN text result (tag 37), reduced here with numpy; a run
without a heat model shows none of them.

Case: models/ef_pp_heat (air heat and contact heat, 3 spheres, 400 steps, 21 frames)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.post.vtk.reader import read_frame, read_pvd
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import model_job, styles_or_skip

TEMPERATURE = 37
MODELS = data_path("real-outputs/musen/models")
pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def heat_run(tmp_path_factory) -> Path:
    styles_or_skip()
    tmp = tmp_path_factory.mktemp("heat")
    python_api.run(model_job(tmp, MODELS / "ef_pp_heat", "efph", ""), work=tmp / "work", also=["vtk"])
    return tmp


def _result_temperatures(folder: Path, prefix: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, sphere ids and (frames, spheres) temperatures of the run's text result."""
    tp = read_time_points(folder / f"{prefix}_result_prec17.txt")
    return tp.times, tp.ids, tp.fields[TEMPERATURE][:, :, 0]


def test_summary_has_min_mean_max_per_frame(heat_run):
    times, _, temp = _result_temperatures(heat_run, "efph")
    summary = json.loads((heat_run / "work" / "job2" / "summary.json").read_text())
    frames = summary["temperature"]["frames"]
    assert summary["temperature"]["unit"] == "K" and len(frames) == len(times) == 21
    np.testing.assert_allclose([f["time"] for f in frames], times, rtol=1e-12, atol=0)
    for name, reduce in (("min", np.min), ("mean", np.mean), ("max", np.max)):
        np.testing.assert_allclose([f[name] for f in frames], reduce(temp, axis=1), rtol=1e-15)
    # the case is what its README says: the temperatures change by tens of K
    assert frames[0]["max"] == 1000.0 and frames[-1]["max"] < 935


def test_vtk_frames_carry_the_temperature(heat_run):
    times, ids, temp = _result_temperatures(heat_run, "efph")
    frames = read_pvd(heat_run / "efph_result.pvd")
    assert len(frames) == len(times)
    for k, (t, path) in enumerate(frames):
        piece = read_frame(path)["Particles"]
        assert t == pytest.approx(times[k], rel=1e-12)
        order = np.searchsorted(ids, piece.point_data["id"])
        np.testing.assert_array_equal(piece.point_data["temperature"], temp[k, order])


def test_plot_draws_the_temperatures(heat_run, tmp_path):
    """From the log (the thermo columns, at the saved steps after the first: LAMMPS's last
    line at step 0 is the state after MUSEN's prediction half step, the energies' too) and
    from the result's frames (every frame)."""
    times, _, temp = _result_temperatures(heat_run, "efph")
    drawn = python_api.plot(heat_run / "work" / "job2", tmp_path / "log.png")
    x, low = drawn.lines["TemperatureMin"]
    at = [int(np.argmin(np.abs(x - t))) for t in times]
    np.testing.assert_allclose(x[at], times, rtol=1e-9, atol=1e-12)
    for name, reduce in (("Min", np.min), ("Mean", np.mean), ("Max", np.max)):
        np.testing.assert_allclose(drawn.lines[f"Temperature{name}"][1][at][1:],
                                   reduce(temp, axis=1)[1:], rtol=1e-7)     # the log's 8 digits
    assert "temperature [K]" in drawn.panels
    for result in ("efph_result_prec17.txt", "efph_result.mdem"):
        drawn = python_api.plot(heat_run / result, tmp_path / f"{result}.png", source="result")
        for name, reduce in (("min", np.min), ("mean", np.mean), ("max", np.max)):
            x, y = drawn.lines[f"temperature {name}"]
            np.testing.assert_allclose(x, times, rtol=1e-12)
            np.testing.assert_allclose(y, reduce(temp, axis=1), rtol=1e-15)


def test_without_a_heat_model_no_temperature_is_shown(tmp_path):
    """Hertz-Mindlin alone: MUSEN writes 0 K for every sphere; nothing of it is shown."""
    styles_or_skip()
    job = model_job(tmp_path, MODELS / "ef_pp_heat", "efph", "")
    text = "\n".join(ln for ln in job.read_text().splitlines()
                     if "HeatConduction" not in ln and "HeatTransfer" not in ln)
    job.write_text(text + "\n")
    python_api.run(job, work=tmp_path / "work", also=["vtk"])
    summary = json.loads((tmp_path / "work" / "job2" / "summary.json").read_text())
    assert "temperature" not in summary
    piece = read_frame(read_pvd(tmp_path / "efph_result.pvd")[-1][1])["Particles"]
    assert "temperature" not in piece.point_data and "Velocity" in piece.point_data
    drawn = python_api.plot(tmp_path / "work" / "job2", tmp_path / "log.png")
    assert not any("emperature" in name for name in drawn.lines)
    drawn = python_api.plot(tmp_path / "efph_result_prec17.txt", tmp_path / "r.png", source="result")
    assert not any("emperature" in name for name in drawn.lines)
