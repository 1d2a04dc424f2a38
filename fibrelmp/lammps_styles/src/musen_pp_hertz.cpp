/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "hertz": MUSEN's ModelPPHertz.cpp CalculatePP (commit e0ff360).
   Hertz normal force -2/3 Kn overlap (Kn = 2 E* sqrt(R* overlap)), no damping; the tangential
   force is incremental: the stored tangential FORCE (MUSEN's vTangForce, not vTangOverlap),
   rotated into the tangent plane keeping its length, plus Kt vt dt (Kt = 8 G* sqrt(R* overlap)),
   capped at mu |Fn|; rolling torque with |Fn|.  The history slot that other laws use for the
   tangential overlap holds this force, so hertz must be the only PP law (pair musen/pp checks).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

class Hertz : public musen_pp::Law {
  using Shaped = musen_pp::MindlinShaped<Hertz>;

 public:
  // ft_old: in, the stored tangential force; out, this step's
  void force(const musen_pp::Contact &c, const musen_pp::Materials &m, double *ft_old,
             musen_pp::Result &r) const override
  {
    const double *n = c.n, *vt = c.vt;
    const double contact_radius = std::sqrt(c.equiv_radius * c.overlap);
    const double kn = 2.0 * m.estar * contact_radius;
    const double fn = -2.0 / 3.0 * c.overlap * kn;

    // rotate the old tangential force into the tangent plane, keeping its length
    const double f_n = n[0] * ft_old[0] + n[1] * ft_old[1] + n[2] * ft_old[2];
    double rot[3];
    for (int k = 0; k < 3; k++) rot[k] = ft_old[k] - n[k] * f_n;
    if (Shaped::significant(rot)) {
      const double scale = Shaped::length(ft_old) / Shaped::length(rot);
      for (int k = 0; k < 3; k++) rot[k] *= scale;
    }
    // MUSEN: tangForce = tangOverlapRot + tangOverlap * Kt, tangOverlap = vt dt
    const double kt = 8.0 * m.gstar * contact_radius;
    double *ft = r.ft;
    for (int k = 0; k < 3; k++) ft[k] = rot[k] + (vt[k] * c.dt) * kt;
    const double ft_len = Shaped::length(ft);
    const double friction_len = m.mu * std::fabs(fn);
    if (ft_len > friction_len)
      for (int k = 0; k < 3; k++) ft[k] *= friction_len / ft_len;

    double roll1[3] = {0.0, 0.0, 0.0}, roll2[3] = {0.0, 0.0, 0.0};
    if (Shaped::significant(c.w1)) {
      const double s = -m.mu_roll * std::fabs(fn) * c.r1 / Shaped::length(c.w1);
      for (int k = 0; k < 3; k++) roll1[k] = c.w1[k] * s;
    }
    if (Shaped::significant(c.w2)) {
      const double s = -m.mu_roll * std::fabs(fn) * c.r2 / Shaped::length(c.w2);
      for (int k = 0; k < 3; k++) roll2[k] = c.w2[k] * s;
    }
    const double nxft[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                            n[0] * ft[1] - n[1] * ft[0]};
    r.fn_len = fn;
    for (int k = 0; k < 3; k++) {
      r.fn[k] = n[k] * fn;
      r.m1[k] = nxft[k] * c.r1 + roll1[k];
      r.m2[k] = nxft[k] * c.r2 + roll2[k];
      ft_old[k] = ft[k];
    }
  }
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  if (!params.empty()) {
    why = "law hertz takes no parameters";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new Hertz());
}

const bool registered = musen_pp::add("hertz", &create);

}    // namespace
