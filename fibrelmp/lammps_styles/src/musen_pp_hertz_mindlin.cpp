/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   Particle-particle law "hertz/mindlin" (musen_pp_hertz_mindlin.h): its registration.
------------------------------------------------------------------------- */

#include "musen_pp_hertz_mindlin.h"

using namespace LAMMPS_NS;

namespace {

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  if (!params.empty()) {
    why = "law hertz/mindlin takes no parameters";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new musen_pp::HertzMindlin());
}

const bool registered = musen_pp::add("hertz/mindlin", &create);

}    // namespace
