/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   PP law heat/conduction SCALE RESIST MIN MAX: MUSEN's ModelPPHeatConduction
   (Models/ParticleParticle/HeatConduction/ModelPPHeatConduction.cpp, e0ff360), operation by
   operation.  No force; the heat flux into src
     q = 2 a SCALE f k* (T_dst - T_src),  a = 2 sqrt(R* overlap),  k* = 1/(1/k_src + 1/k_dst)
   f = RESIST for overlap/(4 R*) <= MIN, 1 from MAX on, linear in between.
   Temperatures and conductivities come from fix musen/heat (pair musen/hm fills the contact).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

class HeatConduction : public musen_pp::Law {
 public:
  HeatConduction(double scale, double resist, double lo, double hi) :
      scale(scale), resist(resist), lo(lo), hi(hi)
  {
  }
  bool heats() const override { return true; }

  void force(const musen_pp::Contact &c, const musen_pp::Materials &, double *, musen_pp::Result &r) const override
  {
    for (int k = 0; k < 3; k++) r.fn[k] = r.ft[k] = r.m1[k] = r.m2[k] = 0.0;
    r.fn_len = 0.0;
    // SimplifiedScene.cpp: dEquivThermalConductivity = 1. / (1. / k1 + 1. / k2)
    const double conductivity = 1. / (1. / c.k1 + 1. / c.k2);
    const double scaled_overlap = c.overlap / (4 * c.equiv_radius);
    double factor = 1.0;
    if (scaled_overlap <= lo)
      factor = resist;
    else if (scaled_overlap < hi)
      factor = resist + (1 - resist) / (hi - lo) * (scaled_overlap - lo);
    const double contact_radius = 2 * std::sqrt(c.equiv_radius * c.overlap);
    r.heat = 2 * contact_radius * scale * factor * conductivity * (c.t2 - c.t1);
  }

 private:
  double scale, resist, lo, hi;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 4) {
    why = "law heat/conduction needs SCALE RESIST MIN MAX";
    return nullptr;
  }
  for (double p : params)
    if (!std::isfinite(p)) {
      why = "law heat/conduction: parameters must be finite";
      return nullptr;
    }
  return std::unique_ptr<musen_pp::Law>(new HeatConduction(params[0], params[1], params[2], params[3]));
}

const bool registered = musen_pp::add("heat/conduction", &create);

}    // namespace
