"""What ``fibrelmp check`` prints for a granular (MUSEN / DEMDF) model; the physics behind
the time-step check lives in ``sanity``."""

from __future__ import annotations

from fibrelmp.granmodel import GranularModel
from fibrelmp.sanity import time_step_check, units_line


def summary(model: GranularModel) -> list[str]:
    s, plan = model.spheres, model.plan
    lines = [f"input        {model.source} ({model.kind})",
             units_line(model),
             f"spheres      {s.count}"]
    if model.bonds is not None:
        lines.append(f"solid bonds  {model.bonds.count}")
    if model.triangles is not None:
        lines.append(f"wall triangles {model.triangles.count} in {len(model.geometries)} geometries")
    if model.planes:
        lines.append(f"wall planes  {len(model.planes)}")
    try:
        from fibrelmp.translate.granular_job import describe_walls

        for text in describe_walls(model):
            lines.append(f"wall         {text}")
    except ImportError:
        pass
    lines.append("materials    " + ", ".join(f"{m.key} ({m.name})" for m in model.materials))
    for (a, b), law in sorted(model.contacts.items()):
        lines.append(f"contact      {model.materials[a].name}-{model.materials[b].name}: "
                     f"E* {law.youngs_eff:.4g}  G* {law.shear_eff:.4g}  e {law.restitution:g}  "
                     f"mu {law.friction:g}  mu_roll {law.rolling_friction:g}")
    if plan.domain is not None:
        lo, hi = plan.domain
        lines.append(f"domain       {' '.join(f'{v:g}' for v in lo)} .. {' '.join(f'{v:g}' for v in hi)}")
    lines.append(f"gravity      {' '.join(f'{v:g}' for v in plan.gravity)}")
    for fld in plan.external_fields:      # MUSEN's EF models, in the order they act
        lines.append(f"field        {fld.model}: {fld.style} {fld.fix_args}")
    lines.append(f"time         {plan.t_start:g} .. {plan.t_end:g}  step {plan.dt:g}")
    if plan.save_every_time is not None:
        lines.append(f"saves        every {plan.save_every_time:g} time units")
    elif plan.save_every_steps is not None:
        lines.append(f"saves        every {plan.save_every_steps} steps")
    return lines + time_step_check(model)
