"""Pictures of results: ``plot`` (the time history) and ``snapshot`` (one frame), as PNG.

Any result fibrelmp writes or reads can be drawn: a run's work folder or its ``log.lammps``,
FibreNet xyz files, MUSEN ``.mdem`` and text results, DEMDF snapshots and LAMMPS dumps
(``locate`` tells which, ``sources`` reads them through each format's reader).  Drawing
is matplotlib's (an optional dependency: ``pip install 'fibrelmp[plot]'``); the PNG is
written through ``formatbase.Writer`` (a temp file renamed into place, ``force`` to replace).
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fibrelmp.errors import InputError
from fibrelmp.formatbase import Writer
from fibrelmp.pictures.locate import WORK, locate

SIZE = (800, 600)           # pixels, the default of both pictures


class PngWriter(Writer):
    """One PNG file: ``add(figure)`` once."""

    format = "png"

    def write(self, fig) -> None:
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=fig.dpi, metadata={"Software": "fibrelmp"},
                    pil_kwargs={"optimize": True})
        self.put(self.target, buffer.getvalue())


@dataclass
class Plot:
    """What ``plot`` drew: the PNG, the data source, and every line as drawn."""
    path: Path
    source: str
    x_name: str
    lines: dict[str, tuple[np.ndarray, np.ndarray]]
    panels: list[str]
    size: tuple[int, int]
    notes: list[str] = field(default_factory=list)


@dataclass
class Snapshot:
    """What ``snapshot`` drew: the PNG, which frame, and the drawn spheres, bonds and walls."""
    path: Path
    frame: int
    frames: int
    time: float | None
    positions: np.ndarray          # (n,3) sphere centres as drawn
    sizes: np.ndarray              # marker areas [pt²] (2D: diameters in data units)
    bonds: int
    walls: int
    size: tuple[int, int]
    notes: list[str] = field(default_factory=list)
    liquid_bonds: int = 0          # line segments drawn for MUSEN liquid bonds

    @property
    def points(self) -> int:
        return len(self.positions)


def _size(size: tuple[int, int] | str | None) -> tuple[int, int]:
    if size is None:
        return SIZE
    if isinstance(size, str):
        try:
            w, h = (int(v) for v in size.lower().split("x"))
        except ValueError:
            raise InputError(None, None, f"--size {size!r}: expected WIDTHxHEIGHT in pixels, e.g. "
                             "800x600") from None
        size = (w, h)
    w, h = size
    if not (50 <= w <= 8000 and 50 <= h <= 8000):
        raise InputError(None, None, f"--size {w}x{h}: each side must be 50..8000 pixels")
    return int(w), int(h)


def _default_out(result: Path, kind: str, tail: str) -> Path:
    if kind == WORK:
        return result / f"{tail}.png"
    return result.with_name(f"{result.stem}_{tail}.png")


def _check_png_name(out: Path) -> None:
    if out.suffix.lower() != ".png":
        raise InputError(out, None, "the picture is a PNG file: give a name ending in .png")
    if out.is_dir():
        raise InputError(out, None, "is a folder: give the picture's file name (….png)")


def _save(fig, out: Path, force: bool) -> None:
    with PngWriter(out, force=force) as writer:
        writer.add(fig)


def plot(result: str | Path, out: str | Path | None = None, *, source: str = "auto",
         size: tuple[int, int] | str | None = None, force: bool = False) -> Plot:
    """Draw the time history of ``result`` into a PNG (default ``<result>_plot.png`` beside
    it, ``plot.png`` in a work folder).  ``source``: "log" (LAMMPS's thermo), "result" (the
    result's own frames) or "auto" (the log when the run's is found)."""
    from fibrelmp.pictures.draw import draw_history, figure
    from fibrelmp.pictures.history import history

    if source not in ("auto", "log", "result"):
        raise InputError(None, None, f"--source {source!r}: choose auto, log or result")
    width, height = _size(size)
    figure(10, 10)                       # matplotlib missing: say so before reading anything
    located = locate(Path(result))
    target = Path(out) if out is not None else _default_out(located.path, located.kind, "plot")
    _check_png_name(target)
    hist = history(located, source)
    fig, drawn = draw_history(hist, width, height)
    _save(fig, target, force)
    return Plot(target, hist.source, hist.x_name, drawn.lines, drawn.panels, (width, height),
                hist.notes)


def snapshot(result: str | Path, out: str | Path | None = None, *, frame: int | None = None,
             size: tuple[int, int] | str | None = None, force: bool = False) -> Snapshot:
    """Draw frame ``frame`` of ``result`` (negative: from the end; default the last, or the
    snapshot file given) into a PNG (default ``<result>_snapshot.png`` beside it)."""
    from fibrelmp.pictures.draw import draw_frame, figure
    from fibrelmp.pictures.sources import open_source

    width, height = _size(size)
    figure(10, 10)
    located = locate(Path(result))
    target = Path(out) if out is not None else _default_out(located.path, located.kind, "snapshot")
    _check_png_name(target)
    src = open_source(located)
    total = src.count()
    scene = src.frame(frame)
    _check_finite(located.path, scene)
    fig, drawn = draw_frame(scene, width, height, _title(located.path, scene, total, src.time_unit))
    _save(fig, target, force)
    return Snapshot(target, scene.index, total, scene.time, drawn.positions, drawn.sizes,
                    drawn.bonds, drawn.triangles, (width, height), src.notes + drawn.notes,
                    drawn.liquid_bonds)


def _check_finite(path: Path, scene) -> None:
    """A frame with nan/inf positions (a run that blew up) has no picture: an input error that
    says which frame and how many particles, not matplotlib's ValueError."""
    bad = ~np.isfinite(np.asarray(scene.position, float)).all(axis=1)
    if bad.any():
        raise InputError(path, None, f"frame {scene.index}: {int(bad.sum())} of {scene.count} "
                         "particle positions are nan or inf (the run blew up?): nothing to draw; "
                         "choose an earlier --frame")


def _title(path: Path, scene, total: int, unit: str) -> str:
    when = f"t = {scene.time:.6g}{(' ' + unit) if unit else ''}" if scene.time is not None \
        else f"step {scene.step}" if scene.step is not None else ""
    parts = [path.name, f"frame {scene.index} of 0..{total - 1}", when, f"{scene.count} particle{'s' if scene.count != 1 else ''}"]
    if len(scene.bonds):
        parts.append(f"{len(scene.bonds)} bonds")
    if scene.broken_bonds:
        parts.append(f"{scene.broken_bonds} broken")
    if len(scene.liquid_bonds):
        parts.append(f"{len(scene.liquid_bonds)} liquid bonds")
    return "  ·  ".join(p for p in parts if p)
