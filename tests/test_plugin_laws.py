"""A MUSEN law is its own C++ file and nothing else (issue 27): the plugin compiles every
``src/*.cpp`` without a list, and every law a file registers (``musen_pp::add`` /
``musen_pw::add``, the one registry template of musen_law_registry.h) is one the running plugin
knows: no law needs an edit of a shared file to be built or found."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from fibrelmp._lammps import new_lammps
from fibrelmp.lammps_styles import build
from tests.conftest import styles_or_skip

CMAKE = build.HERE / "CMakeLists.txt"


def _registered_in_sources(family: str) -> set[str]:
    """The law names the .cpp files register with ``musen_<family>::add("NAME", ...)``."""
    names = set()
    for source in build.SRC.glob("*.cpp"):
        names |= set(re.findall(rf'musen_{family}::add\("([^"]+)"', source.read_text()))
    return names


def test_every_source_is_compiled_without_a_list():
    """build.py and CMakeLists.txt glob src/*.cpp: a new law file is built by being there."""
    assert build.sources() == sorted(build.SRC.glob("*.cpp"))
    assert re.search(r'file\(GLOB sources CONFIGURE_DEPENDS "\$\{CMAKE_CURRENT_SOURCE_DIR\}/src/\*\.cpp"\)',
                     CMAKE.read_text())
    law_files = [p.name for p in build.SRC.glob("musen_p[pw]_*.cpp")]
    assert law_files
    for shared in [build.HERE / "build.py", CMAKE, build.SRC / "plugin.cpp"]:
        text = shared.read_text()
        assert not [name for name in law_files if name in text], shared


def _unknown_law_message(command: str, tmp_path: Path) -> str:
    plugin = styles_or_skip()
    lmp = new_lammps(["-log", "none", "-screen", str(tmp_path / "screen.txt"), "-nocite"])
    try:
        for c in [f"plugin load {plugin}", "units si", "atom_style sphere",
                  "region box block 0 1 0 1 0 1", "create_box 1 box"]:
            lmp.command(c)
        with pytest.raises(Exception) as raised:
            lmp.command(command)
    finally:
        lmp.close()
    return str(raised.value)


@pytest.mark.parametrize("family,command,kind", [
    ("pp", "pair_style musen/pp no/such", "particle-particle"),
    ("pw", "fix walls all musen/wall/mesh no_file law no/such", "particle-wall")])
def test_the_plugin_knows_every_law_a_file_registers(tmp_path, family, command, kind):
    message = _unknown_law_message(command, tmp_path)
    known = re.search(rf"unknown {kind} law no/such \(known: ([^)]*)\)", message)
    assert known, message
    assert known.group(1).split(", ") == sorted(_registered_in_sources(family))
