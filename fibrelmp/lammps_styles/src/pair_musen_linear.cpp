/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/linear: MUSEN's ModelPPLinearElastic (see pair_musen_linear.h).
------------------------------------------------------------------------- */

#include "pair_musen_linear.h"
#include "style_registry.h"

#include "comm.h"
#include "error.h"
#include "utils.h"

#include <cmath>

using namespace LAMMPS_NS;

PairMusenLinear::PairMusenLinear(LAMMPS *lmp) : PairMusenHM(lmp) {}

void PairMusenLinear::settings(int narg, char **arg)
{
  if (narg != 2) error->all(FLERR, "Illegal pair_style musen/linear command: pair_style musen/linear Kn Kt");
  normal_stiffness = utils::numeric(FLERR, arg[0], false, lmp);
  tangential_stiffness = utils::numeric(FLERR, arg[1], false, lmp);
  if (!(normal_stiffness > 0.0) || !std::isfinite(normal_stiffness))
    error->all(FLERR, "pair musen/linear: Kn must be > 0, got {}", arg[0]);
  if (!(tangential_stiffness > 0.0) || !std::isfinite(tangential_stiffness))
    error->all(FLERR, "pair musen/linear: Kt must be > 0, got {}", arg[1]);
}

void PairMusenLinear::stiffness(int, int, double overlap, double, double &kn, double &kt,
                                double &fn_el) const
{
  kn = normal_stiffness;
  kt = tangential_stiffness;
  fn_el = -overlap * kn;
}

void PairMusenLinear::write_restart_settings(FILE *fp)
{
  fwrite(&normal_stiffness, sizeof(double), 1, fp);
  fwrite(&tangential_stiffness, sizeof(double), 1, fp);
}

void PairMusenLinear::read_restart_settings(FILE *fp)
{
  if (comm->me == 0) {
    utils::sfread(FLERR, &normal_stiffness, sizeof(double), 1, fp, nullptr, error);
    utils::sfread(FLERR, &tangential_stiffness, sizeof(double), 1, fp, nullptr, error);
  }
  MPI_Bcast(&normal_stiffness, 1, MPI_DOUBLE, 0, world);
  MPI_Bcast(&tangential_stiffness, 1, MPI_DOUBLE, 0, world);
}

// registration with LAMMPS when the plugin loads (style_registry.h)
namespace {
Pair *create(LAMMPS *lmp) { return new PairMusenLinear(lmp); }
const style_registry::Registration registered(
    30, "musen/linear", "MUSEN linear elastic particle-particle contact", &create);
}    // namespace
