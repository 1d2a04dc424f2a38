/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall law "hertz/mindlin": MUSEN's ModelPWHertzMindlin.cpp CalculatePW (commit
   e0ff360): musen_pw::MindlinShaped (musen_pw_law.h) with Hertz's elastic normal force
   2/3 overlap Kn |rc_n . n|, Kn = 2 E* sqrt(R overlap).
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

class HertzMindlin : public musen_pw::MindlinShaped<HertzMindlin> {
 public:
  double elastic(const musen_pw::Materials &L, double overlap, double a, double, double cos_rc) const
  {
    const double kn = 2 * L.estar * a;
    return 2. / 3. * overlap * kn * cos_rc;
  }
};

std::unique_ptr<musen_pw::Law> create(const std::vector<double> &params, std::string &why)
{
  if (!params.empty()) {
    why = "law hertz/mindlin takes no parameters";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new HertzMindlin());
}

const bool registered = musen_pw::add("hertz/mindlin", &create);

}    // namespace
