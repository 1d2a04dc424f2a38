/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall law "simple/viscoelastic Kn eta": MUSEN's ModelPWSimpleViscoElastic.cpp
   CalculatePW (commit e0ff360): a normal force only, n (overlap Kn |rc_n . n| - eta v_n),
   with v_n the normal relative velocity WITHOUT the sphere's spin; no tangential force, no
   torque, no history (NORMAL_FORCE_COEFF = Kn, NORMAL_DAMPING_PARAMETER = eta).
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

class SimpleViscoElastic : public musen_pw::Law {
 public:
  SimpleViscoElastic(double kn, double eta) : kn(kn), eta(eta) {}

  void force(const musen_pw::Contact &c, const musen_pw::Materials &, double *, double *fo,
             double *to) const override
  {
    const double *n = c.normal;
    const double vn = n[0] * c.vel[0] + n[1] * c.vel[1] + n[2] * c.vel[2];
    const double fn_el =
        c.overlap * kn * std::fabs(c.rc_n[0] * n[0] + c.rc_n[1] * n[1] + c.rc_n[2] * n[2]);
    const double fn_damp = -eta * vn;
    for (int k = 0; k < 3; k++) {
      fo[k] = n[k] * (fn_el + fn_damp);
      to[k] = 0.0;
    }
  }

 private:
  double kn, eta;
};

std::unique_ptr<musen_pw::Law> create(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 2 || !(params[0] > 0) || !std::isfinite(params[0]) ||
      !(params[1] >= 0) || !std::isfinite(params[1])) {
    why = "law simple/viscoelastic needs Kn > 0 and eta >= 0";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new SimpleViscoElastic(params[0], params[1]));
}

const bool registered = musen_pw::add("simple/viscoelastic", &create);

}    // namespace
