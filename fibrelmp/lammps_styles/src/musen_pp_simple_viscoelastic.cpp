/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "simple/viscoelastic Kn mu": MUSEN's ModelPPSimpleViscoElastic.cpp
   CalculatePP (commit e0ff360): normal force (-Kn overlap + mu vn) along the normal, vn the
   normal relative velocity (dst minus src; MUSEN takes it from the centre velocities, whose
   normal part equals the contact point's); no tangential force, no moments, the tangential
   overlap left as it came (MUSEN writes neither vTangOverlap nor vTangForce).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

class SimpleViscoElastic : public musen_pp::Law {
 public:
  SimpleViscoElastic(double kn, double mu) : normal_stiffness(kn), damping(mu) {}
  void force(const musen_pp::Contact &c, const musen_pp::Materials &, double *,
             musen_pp::Result &r) const override
  {
    const double fn = -c.overlap * normal_stiffness + damping * c.vn;
    r.fn_len = fn;
    for (int k = 0; k < 3; k++) {
      r.fn[k] = c.n[k] * fn;
      r.ft[k] = r.m1[k] = r.m2[k] = 0.0;
    }
  }

 private:
  double normal_stiffness, damping;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 2 || !std::isfinite(params[0]) || !std::isfinite(params[1])) {
    why = "law simple/viscoelastic needs NORMAL_FORCE_COEFF and NORMAL_DAMPING_PARAMETER "
          "(finite numbers)";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new SimpleViscoElastic(params[0], params[1]));
}

const bool registered = musen_pp::add("simple/viscoelastic", &create);

}    // namespace
