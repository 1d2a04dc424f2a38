"""ModelPPJKR and ModelPPPopovJKR (translate/granular/models/pp_jkr.py; pair_style musen/pp
jkr GAMMA / popov/jkr SIGMA, src/musen_pp_jkr.cpp):

* against the real cmusen: two pairs of glass spheres, one approaching slowly (it sticks), one
  faster (it separates, slowed by the pull-off); cmusen's Hertz-Mindlin run of the same scene
  bounces both (tests/data/real-outputs/musen/models/pp_jkr/, pp_popov_jkr/ README.md);
* single contacts against MUSEN's elastic normal force re-written here with numpy (values,
  signs, the contact edge), through LAMMPS's first force evaluation;
* the material property each reads, and the refusal of unequal sphere materials.
"""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, CMUSEN, COORD, VEL, check_reference_is_cmusens_output,
                                 check_refused_without_styles, check_run_is_cmusens, model_job,
                                 needs_cmusen, styles_or_skip)
from .test_pp_hertz_simple_viscoelastic import E_STAR, R, _single_contact

JKR = data_path("real-outputs/musen/models/pp_jkr")
POPOV = data_path("real-outputs/musen/models/pp_popov_jkr")
CASES = [(JKR, "jkr", "musen/pp jkr 1.0"), (POPOV, "popov", "musen/pp popov/jkr 0.7")]
PI = 3.14159265358979323846


def _gaps(points) -> np.ndarray:
    """Surface gap of the slow pair (0, 1) and the fast pair (2, 3) at every saved time."""
    x = points.fields[COORD]
    return np.stack([np.linalg.norm(x[:, 1] - x[:, 0], axis=1) - 2 * R,
                     np.linalg.norm(x[:, 3] - x[:, 2], axis=1) - 2 * R], axis=1)


@pytest.mark.parametrize("data,prefix,style", CASES)
def test_adhesive_impacts_are_cmusens(tmp_path, data, prefix, style):
    styles_or_skip()
    # measured: equal bit for bit; the bar is 1e-6 of each quantity's scale
    check_run_is_cmusens(tmp_path, model_job(tmp_path, data, prefix, ""), data, prefix,
                         f"pair_style      {style}\n", dict.fromkeys((COORD, VEL, ANGVEL)), rel=1e-12)


@pytest.mark.parametrize("data,prefix,style", CASES)
def test_cmusen_sticks_where_hertz_mindlin_bounces(data, prefix, style):
    """What the case shows, in cmusen's own output: the slow pair ends overlapping (stuck) with
    the adhesive law and apart with Hertz-Mindlin; the fast pair separates with both."""
    adhesive = _gaps(read_time_points(data / f"cmusen_{prefix}_result_prec17.txt"))
    plain = _gaps(read_time_points(JKR / "cmusen_hm_result_prec17.txt"))
    assert adhesive[-1, 0] < 0 < plain[-1, 0]
    assert adhesive[-1, 1] > 0 and plain[-1, 1] > 0
    # stuck near the law's equilibrium overlap, not drifting apart
    assert abs(adhesive[-1, 0] - adhesive[-10, 0]) < 0.5 * abs(adhesive[-1, 0])


def _jkr_numpy(overlap: float, gamma: float) -> float:
    """ModelPPJKR.cpp's normContactForceLen (negative: repulsive on src)."""
    a = math.sqrt(R / 2 * overlap)
    return -1 * (4.0 * a ** 3 * E_STAR / (3.0 * (R / 2)) - math.sqrt(8 * PI * E_STAR * gamma * a ** 3))


def _popov_numpy(overlap: float, sigma: float) -> float:
    """ModelPPPopovJKR.cpp's normContactForceLen."""
    adh = 1.5 * sigma * PI * (R / 2)
    s = (0.4626 * (sigma / E_STAR) ** 2 * (R / 2)) ** (1.0 / 3.0)
    return -adh * (-1 + 0.12 * (overlap / s + 1) ** (5.0 / 3.0))


@pytest.mark.parametrize("law,value,reference", [("jkr", 1.0, _jkr_numpy),
                                                 ("jkr", 0.05, _jkr_numpy),
                                                 ("popov/jkr", 0.7, _popov_numpy)])
@pytest.mark.parametrize("overlap", [1e-11, 1e-9, 5e-8, 1e-6])
def test_normal_force_is_musens(law, value, reference, overlap):
    """At rest (no damping, no tangential force): the force on sphere 1 is n * F_el."""
    f1, _, f2 = _single_contact(f"pair_style musen/pp {law} {value!r}", overlap, (0.0, 0.0, 0.0))
    overlap = 2 * R - (2 * R - overlap)        # the overlap the positions hold (rounded)
    expected = reference(overlap, value)
    assert f1[0] == pytest.approx(expected, rel=1e-9, abs=1e-18)
    assert f1[1] == f1[2] == 0.0 and np.array_equal(f2, -f1)


def test_signs_and_the_contact_edge():
    """JKR attracts at small overlap (force on sphere 1 towards sphere 2, +x), repels deeper,
    and vanishes at the edge; Popov's fit attracts with 0.88 Fadh right at the edge (MUSEN's
    law jumps there: it acts only while the spheres overlap)."""
    force = [_single_contact("pair_style musen/pp jkr 1.0", d, (0.0, 0.0, 0.0))[0][0]
             for d in (1e-15, 1e-9, 1e-6)]
    assert 0 < force[0] < 1e-4 * force[1] and force[1] > 0 > force[2]
    edge = _single_contact("pair_style musen/pp popov/jkr 0.7", 1e-18, (0.0, 0.0, 0.0))[0][0]
    assert edge == pytest.approx(0.88 * 1.5 * 0.7 * PI * R / 2, rel=1e-6)


def test_laws_refuse_bad_values():
    with pytest.raises(Exception, match="popov/jkr needs the equivalent surface tension"):
        _single_contact("pair_style musen/pp popov/jkr 0", 1e-9, (0.0, 0.0, 0.0))
    with pytest.raises(Exception, match="jkr needs the equivalent surface energy"):
        _single_contact("pair_style musen/pp jkr -1", 1e-9, (0.0, 0.0, 0.0))


def _with_property(material_line: str, prop: int, value: str) -> str:
    """A scene's ``32`` material line with property ``prop`` set to ``value``."""
    words = material_line.split()
    at = next(k for k in range(3, len(words), 2) if words[k] == str(prop))
    words[at + 1] = value
    return " ".join(words)


def _two_materials(tmp_path: Path, data: Path, prefix: str, prop: int, value: str) -> Path:
    """The case with spheres 2, 3 of a second material differing in property ``prop``."""
    job = model_job(tmp_path, data, prefix, "")
    scene = tmp_path / f"{prefix}_scene.txt"
    lines = scene.read_text().splitlines()
    glass = next(ln for ln in lines if ln.startswith("32 MGLASS"))
    other = _with_property(glass.replace("MGLASS Glass", "MOTHER Other"), prop, value)
    lines = [ln.replace("23 MGLASS", "23 MOTHER") if ln.startswith(("0 2 ", "0 3 ")) else ln
             for ln in lines]
    lines.insert(lines.index(glass) + 1, other)
    lines += ["33 MGLASS MOTHER 200 0.7 201 0.3 202 0.05",
              "33 MOTHER MOTHER 200 0.7 201 0.3 202 0.05"]
    scene.write_text("\n".join(lines) + "\n")
    return job


@pytest.mark.parametrize("data,prefix,model,prop", [(JKR, "jkr", "ModelPPJKR", 11),
                                                    (POPOV, "popov", "ModelPPPopovJKR", 13)])
def test_unequal_sphere_materials_are_refused(tmp_path, data, prefix, model, prop):
    styles_or_skip()
    job = _two_materials(tmp_path, data, prefix, prop, "0.5")
    with pytest.raises(InputError, match=rf"{model}: the sphere materials' surface") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:10: ")


def test_each_reads_its_own_material_property(tmp_path):
    """JKR reads the surface energy (11), Popov the surface tension (13): changing the other
    property leaves the law's value alone."""
    styles_or_skip()
    for data, prefix, prop, other, word in [(JKR, "jkr", 11, 13, "jkr 0.25"),
                                            (POPOV, "popov", 13, 11, "popov/jkr 0.25")]:
        folder = tmp_path / prefix
        folder.mkdir()
        job = model_job(folder, data, prefix, "")
        scene = folder / f"{prefix}_scene.txt"
        scene.write_text("\n".join(_with_property(_with_property(ln, prop, "0.25"), other, "9")
                                   if ln.startswith("32 ") else ln
                                   for ln in scene.read_text().splitlines()) + "\n")
        python_api.run(job, work=folder / "work")
        assert f"musen/pp {word}\n" in (folder / "work/job2/in.lammps").read_text()


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(model_job(tmp_path, JKR, "jkr", ""), "ModelPPJKR", 10,
                                 tmp_path / "jkr_init.mdem")


@needs_cmusen
@pytest.mark.parametrize("data,prefix", [(JKR, "jkr"), (POPOV, "popov")])
def test_reference_is_cmusens_output(tmp_path, data, prefix):
    check_reference_is_cmusens_output(tmp_path, data, prefix)


@needs_cmusen
def test_hertz_mindlin_reference_is_cmusens_output(tmp_path):
    """cmusen_hm_result_prec17.txt: job_hm.txt on the same scene (jkr_scene.txt)."""
    shutil.copy(JKR / "jkr_scene.txt", tmp_path / "hm_scene.txt")
    shutil.copy(JKR / "job_hm.txt", tmp_path)
    subprocess.run([CMUSEN, "-t=1", "-s=job_hm.txt"], cwd=tmp_path, capture_output=True,
                   timeout=300, check=True)
    assert (tmp_path / "hm_result_prec17.txt").read_bytes() == \
        (JKR / "cmusen_hm_result_prec17.txt").read_bytes()
