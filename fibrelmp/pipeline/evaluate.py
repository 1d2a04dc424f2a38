"""One force evaluation of a FibreNet model by LAMMPS (tests compare it with FibreNet's own
force laws): the translated set-up, then ``run 0``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from fibrelmp.model import Model

# the first command of the dynamics: the set-up ends before it
_DYNAMICS = ("displace_atoms", "velocity", "write_dump", "fibrenet/frame")


@dataclass
class Evaluation:
    forces: "np.ndarray"      # (n,3) total force per particle, model order
    energy: float             # potential energy (pair + bond + angle + walls), LAMMPS thermo pe


def evaluate(model: "Model", folder: str | Path) -> Evaluation:
    """Forces and potential energy LAMMPS computes for the model's current state.

    Runs the translated set-up (the commands ``runner.parse_commands`` reads from the script,
    up to the first dynamics action) and ``run 0``: the forces include drag on the current
    velocities, gravity and walls, exactly as the integrator would see them.
    """
    import numpy as np

    from fibrelmp._lammps import new_lammps
    from fibrelmp.errors import RunError
    from fibrelmp.runner import in_folder, parse_commands
    from fibrelmp.translate.lammps_job import write_job

    job = write_job(model, folder)
    commands, _ = parse_commands(job.text, str(job.script))
    stop = next(i for i, cmd in enumerate(commands) if cmd.words[0] in _DYNAMICS)
    lmp = new_lammps(["-nocite", "-log", "none", "-screen", "none"])
    try:
        with in_folder(job.folder):       # this thread's directory only (runner.in_folder)
            for cmd in commands[:stop]:
                lmp.command(cmd.text)
            lmp.command("thermo_style custom step pe")
            lmp.command("thermo_modify norm no")
            lmp.command("run 0 post no")
        n = model.particles.count
        f = np.array(lmp.numpy.extract_atom("f")[:n], dtype=float)
        ids = np.array(lmp.numpy.extract_atom("id")[:n], dtype=np.int64)
        out = np.empty_like(f)
        out[ids - 1] = f
        return Evaluation(out, float(lmp.get_thermo("pe")))
    except Exception as exc:
        raise RunError(f"LAMMPS error: {exc}") from None
    finally:
        lmp.close()
