"""fix musen/wall/mesh's particle-wall laws by name (lammps_styles/src/musen_pw_law.h): an
unknown name or wrong parameters stop LAMMPS with a message naming the known laws."""

from __future__ import annotations

import os
import re
import shutil

import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp._lammps import new_lammps

from .conftest import data_path

DATA = data_path("real-outputs/musen/models/pw_simple_viscoelastic")


@pytest.mark.parametrize("law,message", [
    # (other registered laws may stand between them)
    ("law no/such", r"unknown particle-wall law no/such \(known: [^)]*hertz/mindlin, [^)]*simple/viscoelastic"),
    ("law hertz/mindlin 1.0", "law hertz/mindlin takes no parameters"),
    ("law simple/viscoelastic -1.0 0.0", "law simple/viscoelastic needs Kn > 0 and eta >= 0")])
def test_bad_law_stops_lammps(tmp_path, law, message):
    if not lammps_styles.plugin().available:
        pytest.skip("fibrelmp's LAMMPS styles are not available")
    for name in ("sve_scene.txt", "job_sve.txt"):
        shutil.copy(DATA / name, tmp_path)
    python_api.write_job(tmp_path / "job_sve.txt", tmp_path / "work")
    job = next((tmp_path / "work").rglob("in.lammps"))
    text = job.read_text()
    fixed = re.sub(r"(musen/wall/mesh \S+) law simple/viscoelastic \S+ \S+", rf"\1 {law}", text)
    assert fixed != text
    job.write_text(fixed)
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    cwd = os.getcwd()
    os.chdir(job.parent)
    try:
        with pytest.raises(Exception, match=message):
            lmp.file(str(job))
    finally:
        os.chdir(cwd)
        lmp.close()
