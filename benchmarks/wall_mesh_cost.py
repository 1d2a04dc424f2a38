"""Cost of fix musen/wall/mesh per time step: ~5000 triangles (a bumpy floor of 2 mm
triangles) under ~5000 spheres resting on it, static and rotating, against the same run
without the fix (spheres only: fix nve/sphere + gravity, no pair style).

    python benchmarks/wall_mesh_cost.py [--steps 2000] [--spheres 5000] [--cells 50]

Prints ms per step of each run and the fix's own share.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fibrelmp import lammps_styles  # noqa: E402
from fibrelmp._lammps import new_lammps  # noqa: E402


def floor_mesh(cells: int, size: float, rng) -> np.ndarray:
    xs = np.linspace(-size / 2, size / 2, cells + 1)
    z = rng.uniform(0, 0.0002, (cells + 1, cells + 1))      # 0.2 mm bumps: no two normals alike
    tris = []
    for i in range(cells):
        for j in range(cells):
            a = [xs[i], xs[j], z[i, j]]
            b = [xs[i + 1], xs[j], z[i + 1, j]]
            c = [xs[i + 1], xs[j + 1], z[i + 1, j + 1]]
            d = [xs[i], xs[j + 1], z[i, j + 1]]
            tris += [[a, b, c], [a, c, d]]
    return np.array(tris)


def mesh_file(tris: np.ndarray, rotating: bool) -> str:
    out = ["musen/wall/mesh 1", "laws 1", "1 0 1e8 4e7 0.5 0.5 0.05", "geometries 1"]
    if rotating:      # slow rotation about z through the centre (0.1 rad/s)
        kr = np.zeros((4, 3, 3))
        kr[0] = np.diag([0.0, 0.0, 1.0])
        kr[2] = np.diag([1.0, 1.0, 0.0])
        kr[3] = np.array([[0, -1.0, 0], [1.0, 0, 0], [0, 0, 0]])
        seg = "seg 0.0 inf 0.1 0 0 1 " + " ".join(repr(float(v)) for v in kr.ravel()) + " " + " ".join(["0.0"] * 12)
        out += ["geometry floor 0 1 1", seg, "int 0.0 100.0 0 0 0 0 0 0 0 0 0.1"]
    else:
        out += ["geometry floor 0 0 0"]
    out.append(f"triangles {len(tris)}")
    out += ["0 0 " + " ".join(repr(float(v)) for v in t.ravel()) for t in tris]
    return "\n".join(out) + "\n"


def run(folder: Path, plugin: str | None, nspheres: int, size: float, steps: int, mesh: str | None) -> float:
    L = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    side = int(math.ceil(math.sqrt(nspheres)))
    cmds = ([f"plugin load {plugin}"] if plugin else []) + [
        "units si", "atom_style sphere", "boundary f f f",
        f"region box block {-size / 2} {size / 2} {-size / 2} {size / 2} -0.002 0.01", "create_box 1 box",
    ]
    step = size / side
    for i in range(side):
        for j in range(side):
            if i * side + j < nspheres:
                cmds.append(f"create_atoms 1 single {-size / 2 + (i + 0.5) * step!r} "
                            f"{-size / 2 + (j + 0.5) * step!r} 0.00121 units box")
    cmds += ["set group all diameter 0.002 density 2500",
        "timestep 1e-6", "neighbor 0.0005 bin", "fix nve all nve/sphere",
        "fix grav all gravity 9.81 vector 0 0 -1"]
    if mesh is not None:
        (folder / "mesh.txt").write_text(mesh)
        cmds.append(f"fix walls all musen/wall/mesh {folder / 'mesh.txt'}")
    for c in cmds:
        L.command(c)
    L.command("run 200")              # settle onto the floor: every sphere touches it
    n = int(L.get_natoms())
    t = time.perf_counter()
    L.command(f"run {steps}")
    ms = (time.perf_counter() - t) / steps * 1e3
    L.close()
    return ms, n


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--spheres", type=int, default=5000)
    p.add_argument("--cells", type=int, default=50)
    a = p.parse_args(argv)
    found = lammps_styles.plugin()
    if not found.available:
        sys.exit(f"fibrelmp's styles are not available: {found.how}")
    size = a.cells * 0.002
    tris = floor_mesh(a.cells, size, np.random.default_rng(1))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        base, n = run(tmp, None, a.spheres, size, a.steps, None)
        static, _ = run(tmp, str(found.path), a.spheres, size, a.steps, mesh_file(tris, False))
        turning, _ = run(tmp, str(found.path), a.spheres, size, a.steps, mesh_file(tris, True))
    print(f"{len(tris)} triangles, {n} spheres, {a.steps} steps (after 200 settling steps)")
    print(f"  spheres only (nve/sphere + gravity): {base:.3f} ms/step")
    print(f"  + fix musen/wall/mesh, static:       {static:.3f} ms/step (fix: {static - base:.3f} ms)")
    print(f"  + fix musen/wall/mesh, rotating:     {turning:.3f} ms/step (fix: {turning - base:.3f} ms)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
