/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixMusenPbcMove: see fix_musen_pbc_move.h.
------------------------------------------------------------------------- */

#include "fix_musen_pbc_move.h"
#include "lammps_time.h"
#include "style_registry.h"

#include "comm.h"
#include "domain.h"
#include "error.h"
#include "update.h"
#include "utils.h"

#include <cmath>

using namespace LAMMPS_NS;
using namespace FixConst;

FixMusenPbcMove::FixMusenPbcMove(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg)
{
  if (narg != 6) error->all(FLERR, "Illegal fix musen/pbc/move command: fix ID group musen/pbc/move vx vy vz");
  if (domain->triclinic) error->all(FLERR, "Fix musen/pbc/move needs an orthogonal box");
  const int periodic[3] = {domain->xperiodic, domain->yperiodic, domain->zperiodic};
  const int flags[3] = {BOX_CHANGE_X, BOX_CHANGE_Y, BOX_CHANGE_Z};
  for (int k = 0; k < 3; k++) {
    vel[k] = utils::numeric(FLERR, arg[3 + k], false, lmp);
    if (!std::isfinite(vel[k])) error->all(FLERR, "Fix musen/pbc/move: velocities must be finite");
    if (!periodic[k]) vel[k] = 0.0;     // MUSEN's box only matters on periodic axes
    if (vel[k] != 0.0) box_change |= flags[k];
    lo0[k] = domain->boxlo[k];
    hi0[k] = domain->boxhi[k];
  }
  restart_global = 1;
}

int FixMusenPbcMove::setmask()
{
  return POST_INTEGRATE;
}

void FixMusenPbcMove::init()
{
  if (update->whichflag == 2) error->all(FLERR, "Fix musen/pbc/move cannot be used with minimize");
}

void FixMusenPbcMove::post_integrate()
{
  set_box();
}

/* SPBC::UpdatePBC at the current time: coordBeg = initBeg - vVel t, coordEnd = initEnd + vVel t */
void FixMusenPbcMove::set_box()
{
  const double t = simulation_time(update);
  bool changed = false;
  for (int k = 0; k < 3; k++) {
    if (vel[k] == 0.0) continue;
    const double lo = lo0[k] - vel[k] * t, hi = hi0[k] + vel[k] * t;
    if (!(hi > lo)) error->all(FLERR, "Fix musen/pbc/move: the periodic box has shrunk to nothing at t = {}", t);
    if (lo != domain->boxlo[k] || hi != domain->boxhi[k]) changed = true;
    domain->boxlo[k] = lo;
    domain->boxhi[k] = hi;
  }
  if (!changed) return;
  domain->set_global_box();
  domain->set_local_box();
}

void FixMusenPbcMove::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  double list[6] = {lo0[0], lo0[1], lo0[2], hi0[0], hi0[1], hi0[2]};
  const int size = 6 * sizeof(double);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list, sizeof(double), 6, fp);
}

void FixMusenPbcMove::restart(char *buf)
{
  const auto *list = reinterpret_cast<const double *>(buf);
  for (int k = 0; k < 3; k++) {
    lo0[k] = list[k];
    hi0[k] = list[3 + k];
  }
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Fix *create(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenPbcMove(lmp, narg, arg);
}
const style_registry::Registration registered(
    100, "musen/pbc/move", "MUSEN moving periodic box", &create);
}    // namespace
