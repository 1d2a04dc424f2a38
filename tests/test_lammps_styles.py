"""fibrelmp's LAMMPS styles plugin: what is registered, the LAMMPS-version guard, the stock
fallback and how jobs load it (the styles' physics: tests/test_style_*.py)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from fibrelmp import lammps_styles
from fibrelmp._lammps import new_lammps
from fibrelmp.errors import RunError
from fibrelmp.lammps_styles import build
from tests.conftest import styles_or_skip
from fibrelmp.lammps_text import lammps_path

ROOT = Path(__file__).resolve().parents[1]
SCENE_JOB = ROOT / "examples" / "musen" / "single_particle_job.txt"


def _lammps(log: Path):
    return new_lammps(["-log", "none", "-screen", str(log), "-nocite"])


def test_plugin_registers_its_styles(tmp_path):
    path = styles_or_skip()
    lmp = _lammps(tmp_path / "screen.txt")
    try:
        lmp.command(f"plugin load {path}")
        lmp.command("plugin list")
    finally:
        lmp.close()
    listing = (tmp_path / "screen.txt").read_text()
    assert "fix style plugin MUSEN/HISTORY" in listing
    expected = {"pair_musen_hm": "pair style plugin musen/hm",
                "bond_musen_elastic": "bond style plugin musen/elastic",
                "fix_musen_wall_mesh": "fix style plugin musen/wall/mesh",
                "angle_fibrenet": "angle style plugin fibrenet",
                "fix_fibrenet_output": "fix style plugin fibrenet/output",
                "fix_musen_verlet": "fix style plugin musen/verlet"}
    for stem, line in expected.items():
        assert (line in listing) == (build.SRC / f"{stem}.cpp").exists(), line
    assert "WARNING" not in listing


def test_self_registered_styles_load_in_a_fixed_order(tmp_path):
    """Each style registers itself from its own .cpp (src/style_registry.h); the plugin hands
    them to LAMMPS sorted by their order number, so log.lammps's "Loading plugin" lines keep
    the order they had when plugin.cpp listed the styles by hand (a new style may add a line)."""
    path = styles_or_skip()
    log = tmp_path / "screen.txt"
    # a fresh process: a plugin already loaded in this one would not print its lines again
    code = f"""
from fibrelmp._lammps import new_lammps
lmp = new_lammps(["-log", "none", "-screen", {str(log)!r}, "-nocite"])
lmp.command("plugin load {path}")
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    loaded = [ln.removeprefix("Loading plugin: ").removesuffix(" by fibrelmp developers")
              for ln in log.read_text().splitlines() if ln.startswith("Loading plugin: ")]
    before = ["per-atom contact/bond history of fibrelmp styles",
              "MUSEN Hertz-Mindlin particle-particle contact",
              "MUSEN linear elastic particle-particle contact",
              "MUSEN elastic/Kelvin solid bond with breakage",
              "MUSEN particle-wall contact with triangle walls",
              "FibreNet bending law",
              "FibreNet xyz/res output written by LAMMPS",
              "write a frame of fix fibrenet/output"]
    assert len(loaded) == len(set(loaded)), loaded
    assert [info for info in loaded if info in before] == before, loaded


def test_every_style_class_registers_itself_and_plugin_cpp_names_none():
    """No central list: each LAMMPS style class is created by a registration in its own .cpp
    (style_registry.h); plugin.cpp includes no style header."""
    classes = {}
    for header in build.SRC.glob("*.h"):
        for name in re.findall(r"^class (\w+) : public \w+", header.read_text(), re.M):
            classes[name] = header.with_suffix(".cpp")
    assert {"PairMusenHM", "PairMusenLinear", "FibreNetFrame"} <= set(classes)
    for name, source in classes.items():
        text = source.read_text()
        assert re.search(rf"return new {name}\(lmp", text), f"{source.name} creates no {name}"
        assert "style_registry::Registration" in text, f"{source.name} does not register {name}"
    plugin_cpp = (build.SRC / "plugin.cpp").read_text()
    assert not re.findall(r'#include "(?:pair|bond|angle|fix)_\w+\.h"', plugin_cpp)


def test_plugin_refuses_another_lammps_version(tmp_path):
    """A plugin compiled for another LAMMPS registers nothing and says why; using one of its
    styles then fails with LAMMPS's own 'unrecognized style' error."""
    styles_or_skip()            # needs a working compiler and the headers, as the real build
    wrong = build.build(tmp_path, num_ver=20000101, core_only=True)
    log = tmp_path / "screen.txt"
    # a fresh process: plugins loaded by other tests stay registered in this one
    code = f"""
from fibrelmp._lammps import new_lammps
lmp = new_lammps(["-log", "none", "-screen", {str(log)!r}, "-nocite"])
lmp.command("plugin load {wrong}")
lmp.command("units si")
lmp.command("region box block 0 1 0 1 0 1")
lmp.command("create_box 1 box")
try:
    lmp.command("fix history all MUSEN/HISTORY 3")
except Exception as exc:
    print("REFUSED", exc)
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert "REFUSED" in proc.stdout and "nrecognized fix style" in proc.stdout, proc.stdout + proc.stderr
    text = " ".join(log.read_text().split())
    assert "compiled for LAMMPS version 20000101" in text
    assert "none registered" in text and "rebuild them against this LAMMPS" in text


def test_build_without_compiler_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv("CXX", str(tmp_path / "no-such-compiler"))
    with pytest.raises(build.BuildError, match="no C\\+\\+ compiler"):
        build.build(tmp_path / "out", core_only=True)
    assert not list((tmp_path).glob("out/*.so"))


def test_build_id_changes_with_the_sources(tmp_path, monkeypatch):
    before = build.build_id()
    src = tmp_path / "src"
    src.mkdir()
    for p in build.SRC.iterdir():
        (src / p.name).write_bytes(p.read_bytes())
    (src / "plugin.cpp").write_text((src / "plugin.cpp").read_text() + "\n// edited\n")
    monkeypatch.setattr(build, "SRC", src)
    assert build.build_id() != before


def test_stock_request_and_restore():
    with lammps_styles.stock(True):
        assert not lammps_styles.plugin().available
        assert "--stock-styles" in lammps_styles.plugin().how
    assert lammps_styles.request_stock(False) is False


def _translate(folder: Path, *extra: str, env_stock: bool = False) -> subprocess.CompletedProcess:
    import os

    env = dict(os.environ)
    if env_stock:
        env[lammps_styles.ENV_STOCK] = "1"
    return subprocess.run([sys.executable, "-m", "fibrelmp.cli", "translate", str(SCENE_JOB), "-o",
                           str(folder), *extra], capture_output=True, text=True, env=env, cwd=ROOT)


@pytest.mark.parametrize("how", ["option", "environment"])
def test_stock_styles_job_has_no_plugin_and_warns(tmp_path, how):
    proc = _translate(tmp_path / "job", *(["--stock-styles"] if how == "option" else []),
                      env_stock=how == "environment")
    assert proc.returncode == 0, proc.stderr
    script = (tmp_path / "job" / "in.lammps").read_text()
    assert "plugin" not in script.split("units")[0].replace("# fibrelmp's own styles", "")
    assert "approximate MUSEN physics" in proc.stderr


def test_job_loads_the_plugin(tmp_path):
    path = styles_or_skip()
    proc = _translate(tmp_path / "job")
    assert proc.returncode == 0, proc.stderr
    script = (tmp_path / "job" / "in.lammps").read_text()
    assert f"plugin          load {path}" in script
    assert "approximate MUSEN physics: fibrelmp's LAMMPS styles are not used" not in proc.stderr


@pytest.mark.parametrize("bad", ["/tmp/a$b/x.so", "/tmp/a#b.so", '/tmp/a"b.so', "/tmp/a\nb.so",
                                 "/tmp/a&b.so", "/tmp/\u00e9.so"])
def test_plugin_path_is_escaped(bad):
    with pytest.raises(RunError, match="cannot be used in a LAMMPS script"):
        lammps_path(bad, "plugin")


def test_plugin_path_with_spaces_is_one_word():
    assert lammps_path("/tmp/my plugins/x.so") == '"/tmp/my plugins/x.so"'


def test_checkpoint_hash_counts_the_plugin_by_its_build_name():
    """A resume finds the same plugin build elsewhere (installed vs user cache) and still
    resumes; another build (other sources: other name) is a changed job."""
    from fibrelmp.checkpoint import _sha

    script = "plugin          load /a/fibrelmp_styles-0123abcd.so\nunits si\n"
    assert _sha(script) == _sha(script.replace("/a/", '"/b c/').replace(".so", '.so"'))
    assert _sha(script) != _sha(script.replace("0123abcd", "0123abce"))
    assert _sha(script) != _sha(script.replace("units si", "units lj"))
