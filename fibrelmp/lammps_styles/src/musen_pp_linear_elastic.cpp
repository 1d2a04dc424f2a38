/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "linear/elastic Kn Kt": MUSEN's ModelPPLinearElastic.cpp CalculatePP
   (commit e0ff360): constant stiffnesses Kn, Kt [N/m], elastic normal force -Kn overlap; the
   rest is musen_pp::MindlinShaped (E*, G* unused).  pair_style musen/linear's first law.
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

class LinearElastic : public musen_pp::MindlinShaped<LinearElastic> {
 public:
  LinearElastic(double kn, double kt) : normal_stiffness(kn), tangential_stiffness(kt) {}
  void stiffness(const musen_pp::Materials &, double overlap, double, double &kn, double &kt,
                 double &fn_el) const
  {
    kn = normal_stiffness;
    kt = tangential_stiffness;
    fn_el = -overlap * kn;
  }

 private:
  double normal_stiffness, tangential_stiffness;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  // MUSEN divides by Kt when a contact slips: 0 would give nan
  if (params.size() != 2 || !(params[0] > 0) || !std::isfinite(params[0]) ||
      !(params[1] > 0) || !std::isfinite(params[1])) {
    why = "law linear/elastic needs Kn > 0 and Kt > 0";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new LinearElastic(params[0], params[1]));
}

const bool registered = musen_pp::add("linear/elastic", &create);

}    // namespace
