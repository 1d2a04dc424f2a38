"""ModelPWJKR and ModelPWPopovJKR (translate/granular/models/pw_jkr.py, pw_popov_jkr.py;
fix musen/wall/mesh law jkr GAMMA / law popov/jkr SIGMA, src/musen_pw_jkr.cpp) against the
real cmusen: two glass spheres on a steel plate, one arriving slowly (it sticks), one faster
with spin and sideways speed (it leaves, slowed by the pull-off); cmusen's Hertz-Mindlin run
of the same scene bounces both (tests/data/real-outputs/musen/models/pw_jkr/, pw_popov_jkr/)."""

from __future__ import annotations

import math
import os
import shutil
import subprocess

import numpy as np
import pytest

from fibrelmp import python_api
from fibrelmp._lammps import new_lammps
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import read_time_points

from .conftest import data_path
from .musen_model_checks import (ANGVEL, CMUSEN, COORD, VEL, check_reference_is_cmusens_output,
                                 check_refused_without_styles, check_run_is_cmusens, model_job,
                                 needs_cmusen, styles_or_skip)
from .test_pp_jkr import _with_property

JKR = data_path("real-outputs/musen/models/pw_jkr")
POPOV = data_path("real-outputs/musen/models/pw_popov_jkr")
CASES = [(JKR, "pwjkr", "law jkr 1.0"), (POPOV, "pwpopov", "law popov/jkr 0.7")]
SPHERES = slice(0, 2)          # ids 0, 1; 2, 3 are the plate's triangles
R = 1e-3


@pytest.mark.parametrize("data,prefix,law", CASES)
def test_adhesive_wall_contacts_are_cmusens(tmp_path, data, prefix, law):
    styles_or_skip()
    # measured: equal bit for bit; the bar is 1e-6 of each quantity's scale
    check_run_is_cmusens(tmp_path, model_job(tmp_path, data, prefix, ""), data, prefix,
                         f"musen/wall/mesh walls.mesh {law}\n", dict.fromkeys((COORD, VEL, ANGVEL)),
                         rel=1e-12, rows=SPHERES)


@pytest.mark.parametrize("data,prefix,law", CASES)
def test_cmusen_sticks_where_hertz_mindlin_bounces(data, prefix, law):
    adhesive = read_time_points(data / f"cmusen_{prefix}_result_prec17.txt").fields[COORD]
    plain = read_time_points(JKR / "cmusen_pwhm_result_prec17.txt").fields[COORD]
    gap = adhesive[:, SPHERES, 2] - R
    assert gap[-1, 0] < 0 < plain[-1, 0, 2] - R      # stuck on the plate; Hertz-Mindlin bounced
    assert gap[-1, 1] > 0                             # the fast one left
    assert abs(gap[-1, 0] - gap[-5, 0]) < 0.5 * abs(gap[-1, 0])


@pytest.mark.parametrize("data,prefix,model,prop", [(JKR, "pwjkr", "ModelPWJKR", 11),
                                                    (POPOV, "pwpopov", "ModelPWPopovJKR", 13)])
def test_unequal_sphere_wall_values_are_refused(tmp_path, data, prefix, model, prop):
    styles_or_skip()
    job = model_job(tmp_path, data, prefix, "")
    scene = tmp_path / f"{prefix}_scene.txt"
    scene.write_text("\n".join(_with_property(ln, prop, "0.5") if ln.startswith("32 MSTEEL") else ln
                               for ln in scene.read_text().splitlines()) + "\n")
    # glass-glass and glass-steel differ only when two wall materials or sphere materials meet;
    # one plate of steel gives one value: accepted, with sqrt(g_glass g_steel)
    python_api.run(job, work=tmp_path / "work")
    glass_value = 1.0 if prop == 11 else 0.7        # the scene's glass: 11 = 1, 13 = 0.7
    law = "jkr" if prop == 11 else "popov/jkr"
    expected = f"law {law} {math.sqrt(glass_value * 0.5)!r}\n"
    assert expected in (tmp_path / "work/job2/in.lammps").read_text()
    # a second sphere material of another value: two sphere-wall values, refused
    folder = tmp_path / "two"
    folder.mkdir()
    job = model_job(folder, data, prefix, "")
    scene = folder / f"{prefix}_scene.txt"
    lines = scene.read_text().splitlines()
    glass = next(ln for ln in lines if ln.startswith("32 MGLASS"))
    lines.insert(lines.index(glass) + 1,
                 _with_property(glass.replace("MGLASS Glass", "MOTHER Other"), prop, "0.25"))
    lines = [ln.replace("23 MGLASS", "23 MOTHER") if ln.startswith("0 1 ") else ln for ln in lines]
    lines += ["33 MGLASS MOTHER 200 0.7 201 0.3 202 0.05",
              "33 MOTHER MOTHER 200 0.7 201 0.3 202 0.05",
              "33 MOTHER MSTEEL 200 0.8 201 0.2 202 0.01"]
    scene.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=rf"{model}: the sphere and wall materials' surface") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:11: ")


def test_refused_without_fibrelmps_styles(tmp_path):
    check_refused_without_styles(model_job(tmp_path, JKR, "pwjkr", ""), "ModelPWJKR", 11,
                                 tmp_path / "pwjkr_init.mdem")


@needs_cmusen
@pytest.mark.parametrize("data,prefix", [(JKR, "pwjkr"), (POPOV, "pwpopov")])
def test_reference_is_cmusens_output(tmp_path, data, prefix):
    check_reference_is_cmusens_output(tmp_path, data, prefix)


@needs_cmusen
def test_hertz_mindlin_reference_is_cmusens_output(tmp_path):
    shutil.copy(JKR / "pwjkr_scene.txt", tmp_path / "pwhm_scene.txt")
    shutil.copy(JKR / "job_pwhm.txt", tmp_path)
    subprocess.run([CMUSEN, "-t=1", "-s=job_pwhm.txt"], cwd=tmp_path, capture_output=True,
                   timeout=300, check=True)
    assert (tmp_path / "pwhm_result_prec17.txt").read_bytes() == \
        (JKR / "cmusen_pwhm_result_prec17.txt").read_bytes()


# ---------------------------------------------------------------- single contacts, numpy

E_STAR, G_STAR = 4.2e10, 9.3e9
PI = 3.14159265358979323846
MESH = f"""musen/wall/mesh 1
laws 1
1 1 {E_STAR!r} {G_STAR!r} 0.8 0.2 0.01
geometries 1
geometry Plate 0 0 0
triangles 2
0 1 -0.005 -0.005 0.0 0.005 -0.005 0.0 0.005 0.005 0.0
0 1 -0.005 -0.005 0.0 0.005 0.005 0.0 -0.005 0.005 0.0
"""


def _wall_force(tmp_path, law: str, overlap: float) -> tuple[float, float]:
    """(normal force on a sphere resting on the plate, the overlap its position holds) from
    LAMMPS's first force evaluation."""
    (tmp_path / "walls.mesh").write_text(MESH)
    z = R - overlap
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        for c in [f"plugin load {styles_or_skip()}", "units si", "atom_style sphere",
                  "boundary f f f", "comm_modify vel yes",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  f"create_atoms 1 single 0 0 {z!r}", f"set type 1 diameter {2 * R!r} density 2500",
                  "pair_style zero 0.003", "pair_coeff * *", "fix 1 all nve/sphere",
                  f"fix w all musen/wall/mesh walls.mesh law {law}", "run 0 post no"]:
            lmp.command(c)
        f = np.array(lmp.gather_atoms("f", 1, 3))
        return float(f[2]), R - z
    finally:
        os.chdir(cwd)
        lmp.close()


@pytest.mark.parametrize("overlap", [1e-11, 1e-9, 5e-8, 1e-6])
def test_wall_normal_forces_are_musens(tmp_path, overlap):
    """At rest on the plate (rc_n = n, no damping, no tangential force): the force is n F_el
    with ModelPWJKR's / ModelPWPopovJKR's F_el (R* = R), positive away from the wall."""
    styles_or_skip()
    fz, overlap = _wall_force(tmp_path, "jkr 1.0", overlap)
    a = math.sqrt(R * overlap)
    jkr = 4.0 * a ** 3 * E_STAR / (3.0 * R) - math.sqrt(8.0 * PI * E_STAR * 1.0 * a ** 3)
    assert fz == pytest.approx(jkr, rel=1e-9, abs=1e-18)
    fz, overlap = _wall_force(tmp_path, "popov/jkr 0.7", overlap)
    adh = 1.5 * 0.7 * PI * R
    s = (0.4626 * (0.7 / E_STAR) ** 2 * R) ** (1.0 / 3.0)
    assert fz == pytest.approx(adh * (-1 + 0.12 * (overlap / s + 1) ** (5.0 / 3.0)), rel=1e-9)


def test_wall_signs(tmp_path):
    """Adhesive (towards the wall, -z) at small overlap, repulsive deeper; Popov's jumps to
    -0.88 Fadh at the edge."""
    styles_or_skip()
    small, _ = _wall_force(tmp_path, "jkr 1.0", 1e-9)
    deep, _ = _wall_force(tmp_path, "jkr 1.0", 1e-6)
    edge, _ = _wall_force(tmp_path, "popov/jkr 0.7", 1e-18)
    assert small < 0 < deep
    assert edge == pytest.approx(-0.88 * 1.5 * 0.7 * PI * R, rel=1e-6)
