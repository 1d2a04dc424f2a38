/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/linear: MUSEN's ModelPPLinearElastic (see pair_musen_linear.h).
------------------------------------------------------------------------- */

#include "pair_musen_linear.h"
#include "style_registry.h"

#include "error.h"

#include <cstring>

using namespace LAMMPS_NS;

PairMusenLinear::PairMusenLinear(LAMMPS *lmp) : PairMusenHM(lmp) {}

void PairMusenLinear::settings(int narg, char **arg)
{
  if (narg < 2 || strcmp(arg[0], "then") == 0 || strcmp(arg[1], "then") == 0)
    error->all(FLERR, "Illegal pair_style musen/linear command: pair_style musen/linear Kn Kt "
                      "[then LAW [params]] ...");
  set_laws("linear/elastic", narg, arg);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenLinear(lmp); }
const style_registry::Registration registered(
    30, "musen/linear", "MUSEN linear elastic particle-particle contact", &create);
}    // namespace
