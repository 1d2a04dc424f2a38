"""Metrics of the rotating-drum scenario (shared/real-outputs/musen/scenarios/rotating_drum):
a MUSEN text result of 250 spheres in a drum turning about the y axis, compared with the real
cmusen result.

    python tests/scenarios/drum_metrics.py RESULT [--scene drum_scene.txt] [--reference CMUSEN_RESULT]

(defaults: the scene and the 6-digit cmusen result in tests/data/real-outputs/musen/scenarios/
rotating_drum.)

Averages over the saved times in [0.3, 0.8] s (the README's definitions, checked against its
cmusen figures):
- bed angle: the mass-weighted centre of mass seen from the axis, in degrees from the bottom
  (-z), negative towards -x: atan2(x_com, -z_com);
- COM radius: its distance from the axis (m);
- kinetic energy: translational + rotational (2/5 m R^2 w^2 / 2) of all spheres (J);
- max radial reach: the largest sqrt(x^2 + z^2) + R of any sphere at each save (m).
Tolerances (README): angle 3 deg, COM radius 3 %, KE 30 %, reach 50 um.
"""

from __future__ import annotations

import argparse
import gzip
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[2]))

from fibrelmp.translate.musen.scene import read as read_scene  # noqa: E402
from fibrelmp.translate.musen.text import read_time_points  # noqa: E402

# the scenario as copied into the repository (tests/data), else the developers' shared folder
_PARTS = ("real-outputs", "musen", "scenarios", "rotating_drum")
SCENARIO = next((p for p in (HERE.parents[1] / "data" / Path(*_PARTS), HERE.parents[3] / "shared" / Path(*_PARTS))
                 if p.exists()), HERE.parents[1] / "data" / Path(*_PARTS))
TOLERANCES = {"bed_angle_deg": ("abs", 3.0), "com_radius": ("rel", 0.03),
              "kinetic_energy": ("rel", 0.30), "max_reach": ("abs", 50e-6)}


def _plain(path: Path, tmp: Path) -> Path:
    if path.suffix != ".gz":
        return path
    out = tmp / path.stem
    with gzip.open(path, "rb") as src, open(out, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return out


def drum_metrics(result: str | Path, scene: str | Path, t0: float = 0.3, t1: float = 0.8) -> dict:
    """The four metrics of one result (radii and masses from ``scene``, matched by id)."""
    with tempfile.TemporaryDirectory() as tmp:
        tp = read_time_points(_plain(Path(result), Path(tmp)), types=(1,), tags=(12, 15, 16))
    model = read_scene(scene)
    where = {int(i): k for k, i in enumerate(model.spheres.ids)}
    rows = np.array([where[int(i)] for i in tp.ids])
    radius, mass = model.spheres.radius[rows], model.spheres.mass[rows]
    sel = (tp.times >= t0 - 1e-9) & (tp.times <= t1 + 1e-9)
    if not sel.any():
        raise ValueError(f"{result}: no saved time in [{t0}, {t1}]")
    x, v, w = tp.fields[12][sel], tp.fields[15][sel], tp.fields[16][sel]
    com = (x * mass[None, :, None]).sum(1) / mass.sum()
    inertia = 0.4 * mass * radius ** 2
    ke = 0.5 * (mass * (v ** 2).sum(2)).sum(1) + 0.5 * (inertia * (w ** 2).sum(2)).sum(1)
    reach = np.hypot(x[:, :, 0], x[:, :, 2]) + radius[None, :]
    return {"saves": int(sel.sum()),
            "bed_angle_deg": float(np.degrees(np.arctan2(com[:, 0], -com[:, 2])).mean()),
            "com_radius": float(np.hypot(com[:, 0], com[:, 2]).mean()),
            "kinetic_energy": float(ke.mean()),
            "max_reach": float(reach.max(axis=1).mean())}


def compare(mine: dict, ref: dict) -> list[tuple[str, float, float, bool]]:
    out = []
    for key, (kind, tol) in TOLERANCES.items():
        a, b = mine[key], ref[key]
        ok = abs(a - b) <= tol if kind == "abs" else abs(a - b) <= tol * abs(b)
        out.append((key, a, b, ok))
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("result")
    p.add_argument("--scene", default=None)
    p.add_argument("--reference", default=None)
    a = p.parse_args(argv)
    scene = a.scene or SCENARIO / "drum_scene.txt"
    mine = drum_metrics(a.result, scene)
    ref_path = a.reference or SCENARIO / "cmusen_drum_result.txt.gz"
    ref = drum_metrics(ref_path, scene)
    print(f"# metric\tthis\tcmusen\twithin tolerance\t({mine['saves']} / {ref['saves']} saves in 0.3-0.8 s)")
    for key, mv, rv, ok in compare(mine, ref):
        print(f"{key}\t{mv:.6g}\t{rv:.6g}\t{'yes' if ok else 'NO'}\t{TOLERANCES[key]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
