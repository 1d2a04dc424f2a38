/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/vdw: MUSEN's ModelPPHertzMindlinVdW (see pair_musen_vdw.h).
------------------------------------------------------------------------- */

#include "pair_musen_vdw.h"
#include "style_registry.h"

#include "error.h"

#include <cstring>

using namespace LAMMPS_NS;

PairMusenVdW::PairMusenVdW(LAMMPS *lmp) : PairMusenHM(lmp) {}

void PairMusenVdW::settings(int narg, char **arg)
{
  if (narg < 1 || strcmp(arg[0], "then") == 0)
    error->all(FLERR, "Illegal pair_style musen/vdw command: pair_style musen/vdw GAMMA "
                      "[then LAW [params]] ...");
  set_laws("hertz/mindlin/vdw", narg, arg);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenVdW(lmp); }
const style_registry::Registration registered(
    30, "musen/vdw", "MUSEN Hertz-Mindlin particle-particle contact with van der Waals attraction", &create);
}    // namespace
