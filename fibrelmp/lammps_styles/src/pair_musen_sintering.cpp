/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/sintering: MUSEN's ModelPPSintering (see pair_musen_sintering.h).
------------------------------------------------------------------------- */

#include "pair_musen_sintering.h"
#include "style_registry.h"

#include "error.h"

#include <cstring>

using namespace LAMMPS_NS;

PairMusenSintering::PairMusenSintering(LAMMPS *lmp) : PairMusenHM(lmp) {}

void PairMusenSintering::settings(int narg, char **arg)
{
  if (narg < 3 || strcmp(arg[0], "then") == 0 || strcmp(arg[1], "then") == 0 || strcmp(arg[2], "then") == 0)
    error->all(FLERR, "Illegal pair_style musen/sintering command: pair_style musen/sintering D ETA GAMMA "
                      "[then LAW [params]] ...");
  set_laws("sintering", narg, arg);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenSintering(lmp); }
const style_registry::Registration registered(
    30, "musen/sintering", "MUSEN sintering particle-particle contact", &create);
}    // namespace
