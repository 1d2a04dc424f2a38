"""What every MUSEN model's test module shares (tests/test_<kind>_<model>.py): its case in
tests/data/real-outputs/musen/models/<model>/ (``<prefix>_scene.txt``, the cmusen job script
``job_<prefix>.txt`` and cmusen's 17-digit result ``cmusen_<prefix>_result_prec17.txt``), the
job with other parameters, the opt-in rerun of the real cmusen, and the refusal without
fibrelmp's LAMMPS styles."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from fibrelmp import lammps_styles, python_api
from fibrelmp.errors import InputError

CMUSEN = os.environ.get("FIBRELMP_CMUSEN")
needs_cmusen = pytest.mark.skipif(not CMUSEN, reason="set FIBRELMP_CMUSEN to the real cmusen")
VEL, ANGVEL, COORD = 15, 16, 12                # MUSEN text tags


def styles_or_skip() -> None:
    if not lammps_styles.plugin().available:
        pytest.skip("fibrelmp's LAMMPS styles are not available")


def model_job(tmp_path: Path, data: Path, prefix: str, params: str, new_params: str | None = None) -> Path:
    """The case's job script and scene in ``tmp_path``, its ``params`` line replaced by
    ``new_params``."""
    shutil.copy(data / f"{prefix}_scene.txt", tmp_path)
    job = (data / f"job_{prefix}.txt").read_text()
    (tmp_path / f"job_{prefix}.txt").write_text(job if new_params is None else job.replace(params, new_params))
    return tmp_path / f"job_{prefix}.txt"


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


def run_cut_and_resumed(monkeypatch: pytest.MonkeyPatch, job: Path, work: Path, every: int) -> None:
    """Run ``job`` with a checkpoint every ``every`` steps, stopped after its first checkpoint
    (as if SIGTERM came), then resumed to the end."""
    import signal

    from fibrelmp import checkpoint

    write = checkpoint.Checkpointing.write

    def write_then_stop(self, *args, **kwargs):
        write(self, *args, **kwargs)
        self._stop = signal.SIGTERM
    monkeypatch.setattr(checkpoint.Checkpointing, "write", write_then_stop)
    with pytest.raises(checkpoint.CheckpointStop):
        python_api.run(job, work=work, checkpoint_every=every)
    monkeypatch.setattr(checkpoint.Checkpointing, "write", write)
    python_api.run(job, work=work, resume=True)
