"""Where the C fast path of fibrelmp.post comes from: built at install time (setup.py), else
compiled at first use (once, even for concurrent processes), else numpy -- and how
fastparse.active_path() / ``fibrelmp --version`` report the path in use."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import sysconfig
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

from fibrelmp.numtext import fast as fastparse

# the folder holding the fibrelmp package these tests import (a checkout or site-packages)
PKG_ROOT = Path(fastparse.__file__).resolve().parents[2]


def _cc() -> list[str]:
    """The compiler fastparse would run on first use."""
    return (os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc").split()


def _have_cc() -> bool:
    cc = _cc()
    if shutil.which(cc[0]) is None:
        return False
    return subprocess.run(cc + ["--version"], capture_output=True).returncode == 0   # CC=false


needs_cc = pytest.mark.skipif(not _have_cc(), reason="no C compiler")


def _env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "FIBRELMP_NO_C"}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(PKG_ROOT), env.get("PYTHONPATH")]))
    env.update(extra)
    return env


def _installed_libraries() -> list[Path]:
    """Libraries built at install time: next to the imported fastparse (editable installs) and
    in the installed distribution (pip install ., where the tests may import a checkout)."""
    found = [fastparse._INSTALLED] if fastparse._INSTALLED.exists() else []
    # every fibrelmp on sys.path: a checkout's fibrelmp.egg-info (left by pip's in-tree build)
    # may come before the installed dist-info
    files = [f for dist in metadata.distributions(name="fibrelmp") for f in dist.files or []]
    for f in files:
        if f.name == fastparse._INSTALLED.name:
            path = Path(f.locate()).resolve()
            if path.exists() and path not in found:
                found.append(path)
    return found


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    """fastparse as in a new process (nothing loaded, an empty cache); restored afterwards."""
    monkeypatch.setattr(fastparse, "_lib", None)
    monkeypatch.setattr(fastparse, "_tried", False)
    monkeypatch.setattr(fastparse, "_path", "not loaded yet")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("FIBRELMP_NO_C", raising=False)
    return monkeypatch


def _works_like_numpy(lib) -> None:
    rows = ["%d %r %.17g %e" % (k, float(x), -x / 3, x * 1e-300) for k, x in
            enumerate(np.random.default_rng(1).standard_normal(500) * 1e5)]
    block = ("\n".join(rows) + "\n").encode()
    assert fastparse.library() is lib
    got = fastparse.parse_numbers(block, 500, 4)
    assert got is not None and got.tobytes() == np.loadtxt(rows, ndmin=2).tobytes()
    x = np.array([[0.000005, -2.500005, 1e10 + 0.000005], [-0.0, 1.0 / 3.0, 99999.999995]])
    ref = "".join("%s\t%.5f\t%.5f\t%.5f\n" % ("A", *r) for r in x).encode()
    assert fastparse.format_xyz(np.zeros(2, np.int64), ["A"], x) == ref


def test_no_c_environment_variable_reports_numpy():
    out = subprocess.run(
        [sys.executable, "-c", "from fibrelmp.numtext import fast as f; "
                               "print(f.active_path()); print(f.library())"],
        env=_env(FIBRELMP_NO_C="1"), capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["numpy (FIBRELMP_NO_C=1)", "None"]


def test_active_path_agrees_with_the_loaded_library():
    path = fastparse.active_path()
    if os.environ.get("FIBRELMP_NO_C"):
        assert path == f"numpy (FIBRELMP_NO_C={os.environ['FIBRELMP_NO_C']})"
    elif fastparse._INSTALLED.exists():        # built at install time: must be the one in use
        assert path == f"C (installed: {fastparse._INSTALLED})"
    assert (fastparse.library() is None) == path.startswith("numpy (")
    assert re.fullmatch(r"C \((installed|compiled at first use): .+\)|numpy \(.+\)", path), path


def test_library_built_at_install_time_is_used_first(fresh, tmp_path):
    libs = _installed_libraries()
    if not libs:
        pytest.skip("fibrelmp was installed without building its C library (no compiler then?)")
    fresh.setenv("CC", str(tmp_path / "no-such-compiler"))      # nothing may be compiled
    for lib in libs:
        fresh.setattr(fastparse, "_INSTALLED", lib)
        fresh.setattr(fastparse, "_tried", False)
        assert fastparse.active_path() == f"C (installed: {lib})"
        _works_like_numpy(fastparse.library())
    assert not (tmp_path / "cache").exists()


@needs_cc
def test_compiled_at_first_use_without_an_installed_library(fresh, tmp_path):
    fresh.setattr(fastparse, "_INSTALLED", tmp_path / "not-installed.so")     # a source checkout
    path = fastparse.active_path()
    cache = tmp_path / "cache" / "fibrelmp"
    assert re.fullmatch(rf"C \(compiled at first use: {re.escape(str(cache))}/fastparse-[0-9a-f]{{16}}\.so; "
                        r"not built at install time\)", path), path
    _works_like_numpy(fastparse.library())


def test_no_compiler_and_no_installed_library_is_numpy(fresh, tmp_path):
    fresh.setattr(fastparse, "_INSTALLED", tmp_path / "not-installed.so")
    fresh.setenv("CC", str(tmp_path / "no-such-cc"))
    assert fastparse.library() is None
    assert fastparse.active_path() == \
        f"numpy (no C compiler: '{tmp_path / 'no-such-cc'}' not found; not built at install time)"
    fresh.setattr(fastparse, "_tried", False)
    fresh.setenv("CC", "false")                                 # a compiler that fails
    assert fastparse.active_path() == "numpy (no C compiler: false failed: exit status 1; " \
                                      "not built at install time)"


def test_unusable_installed_library_falls_back(fresh, tmp_path):
    bad = tmp_path / fastparse._INSTALLED.name
    bad.write_bytes(b"not a shared library")                   # e.g. copied from another machine
    fresh.setattr(fastparse, "_INSTALLED", bad)
    fresh.setenv("CC", str(tmp_path / "no-such-cc"))
    path = fastparse.active_path()
    assert fastparse.library() is None
    assert path.startswith("numpy (no C compiler: ") and "; installed library unusable: cannot load: " in path


@needs_cc
def test_concurrent_first_use_compiles_once(tmp_path):
    """MPI ranks starting together: one compiler run, the others wait for it and load its result."""
    log = tmp_path / "cc.log"
    wrapper = tmp_path / "cc-wrapper"
    real = _cc()
    wrapper.write_text(f"#!/bin/sh\necho run >> '{log}'\nsleep 1\nexec {' '.join(real)} \"$@\"\n")
    wrapper.chmod(0o755)
    code = ("from pathlib import Path; from fibrelmp.numtext import fast as f; "
            f"f._INSTALLED = Path({str(tmp_path / 'none.so')!r}); print(f.active_path())")
    env = _env(XDG_CACHE_HOME=str(tmp_path / "cache"), CC=str(wrapper))
    procs = [subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(3)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), outs
    paths = {out.strip() for out, _ in outs}
    assert len(paths) == 1 and paths.pop().startswith("C (compiled at first use: "), outs
    assert log.read_text().splitlines() == ["run"]
    assert sorted(p.suffix for p in (tmp_path / "cache" / "fibrelmp").iterdir()) == [".lock", ".so"]


@pytest.mark.parametrize("no_c", [False, True])
def test_version_prints_the_post_fast_path(no_c):
    env = _env(FIBRELMP_NO_C="1") if no_c else _env()
    proc = subprocess.run([sys.executable, "-m", "fibrelmp.cli", "--version"], env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    line = proc.stdout.splitlines()[-1]
    if no_c:
        assert line == "post fast path: numpy (FIBRELMP_NO_C=1)"
    elif fastparse._INSTALLED.exists():
        assert line == f"post fast path: C (installed: {fastparse._INSTALLED})"
    else:
        assert re.fullmatch(r"post fast path: (C \(compiled at first use: .+\)|numpy \(.+\))", line), line
