/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/liquid: MUSEN's ModelPPHertzMindlinLiquid (see pair_musen_liquid.h).
------------------------------------------------------------------------- */

#include "pair_musen_liquid.h"
#include "style_registry.h"

#include "error.h"

#include <cstring>

using namespace LAMMPS_NS;

PairMusenLiquid::PairMusenLiquid(LAMMPS *lmp) : PairMusenHM(lmp) {}

void PairMusenLiquid::settings(int narg, char **arg)
{
  bool four = narg >= 4;
  for (int a = 0; four && a < 4; a++) four = strcmp(arg[a], "then") != 0;
  if (!four)
    error->all(FLERR, "Illegal pair_style musen/liquid command: pair_style musen/liquid HMIN THETA "
                      "SIGMA ETA [then LAW [params]] ...");
  set_laws("hertz/mindlin/liquid", narg, arg);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenLiquid(lmp); }
const style_registry::Registration registered(
    30, "musen/liquid", "MUSEN Hertz-Mindlin particle-particle contact with a liquid bridge",
    &create);
}    // namespace
