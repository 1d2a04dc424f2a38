"""Issue 24: ``check`` printed two different "fastest approach" contact times for one DEMDF
example, and examples/musen/README.md another than ``check`` for the MUSEN one.  One
definition (``granmodel.contact_time``), one figure, equal to the Hertz contact time
computed here from the example files' own numbers."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from fibrelmp import granmodel
from fibrelmp.cli import app

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _hertz_time(m_eff: float, r_eff: float, e_star: float, speed: float) -> float:
    """2.943 x peak overlap / speed (Johnson 1985), written out here."""
    overlap = (15 * m_eff * speed ** 2 / (16 * e_star * math.sqrt(r_eff))) ** 0.4
    return 2.943 * overlap / speed


def _contact_times(text: str) -> list[float]:
    """Every contact-time figure ``check`` prints (its line and any warning quoting one)."""
    return [float(x) for x in re.findall(r"contact time ([0-9.e+-]+)", text)]


def test_musen_example_contact_time_is_the_sphere_on_plate_impact():
    """single_particle_job.txt: a glass sphere (r 0.5 mm, density 2500, 0.5 m/s down) above a
    steel plate, domain z -2.9375 .. 26.4375 mm, g 9.81: the fastest approach is a
    sphere-wall contact (m* = m, R* = r) at sqrt(0.5^2 + 2 g H); E* from MUSEN's mixing of
    E 50 / 200 GPa, nu 0.22 / 0.3 (scene lines 32)."""
    r, rho = 0.5e-3, 2500.0
    m = 4 / 3 * math.pi * r ** 3 * rho
    e_star = 1 / ((1 - 0.22 ** 2) / 50e9 + (1 - 0.3 ** 2) / 200e9)
    speed = math.sqrt(0.5 ** 2 + 2 * 9.81 * (0.0264375 + 0.0029375))
    expected = _hertz_time(m, r, e_star, speed)
    assert expected == pytest.approx(3.3257e-6, rel=1e-4)

    result = CliRunner().invoke(app, ["check", str(EXAMPLES / "musen" / "single_particle_job.txt")])
    assert result.exit_code == 0, result.output
    times = _contact_times(result.stdout + result.stderr)
    assert len(times) == 1 and times[0] == pytest.approx(expected, rel=2e-3), result.output
    assert "(Hertz, Steel-Glass, fastest approach in the input) = 33.3 time steps" in result.stdout

    from fibrelmp.translate.musen.scene import read

    model = read(EXAMPLES / "musen" / "SingelParticle_text.txt")
    model.plan.gravity[:] = (0.0, 0.0, -9.81)              # the job's EXT_ACCEL
    assert granmodel.contact_time(model) == (pytest.approx(expected, rel=1e-9), "Steel-Glass",
                                                   "Hertz")
    readme = (EXAMPLES / "musen" / "README.md").read_text()
    assert f"{expected * 1e6:.2f} µs" in readme and "3.6 µs" not in readme


def test_demdf_example_prints_one_contact_time():
    """head_on.json: two spheres (r 0.5, mass 1) approaching at 1.5 + 0.5, no body force;
    fibrelmp makes them stiff enough to overlap by 1 % of the radius (fibrelmp.maxOverlap),
    so the contact lasts 2.943 x 0.005 / 2.0 whatever E* that takes; the check line and the
    time-step warning quote that one figure."""
    expected = 2.943 * 0.01 * 0.5 / 2.0
    result = CliRunner().invoke(app, ["check", str(EXAMPLES / "demdf" / "head_on.json")])
    assert result.exit_code == 0, result.output
    times = _contact_times(result.stdout + result.stderr)
    assert len(times) == 2 and times[0] == times[1] == pytest.approx(expected, rel=2e-3), result.output

    from fibrelmp.translate.demdf.reader import read

    model = read(EXAMPLES / "demdf" / "head_on.json")
    law = model.contacts[(0, 0)]
    assert granmodel.contact_time(model)[0] == pytest.approx(expected, rel=1e-9)
    assert _hertz_time(0.5, 0.25, law.youngs_eff, 2.0) == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("name", ["disks_2d.json", "drop_on_wall.json"])
def test_demdf_examples_quote_the_figure_check_prints(name):
    result = CliRunner().invoke(app, ["check", str(EXAMPLES / "demdf" / name)])
    assert result.exit_code == 0, result.output
    times = _contact_times(result.stdout + result.stderr)
    assert len(times) == 2 and times[0] == times[1], result.output
