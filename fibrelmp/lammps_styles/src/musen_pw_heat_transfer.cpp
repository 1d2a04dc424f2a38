/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall law "heat/transfer TWALL H RESIST": MUSEN's ModelPWHeatTransfer
   (Models/ParticleWall/PWHeatTransfer/ModelPWHeatTransfer.cpp, e0ff360).  No force; the heat
   flux into the sphere pi R overlap H RESIST (TWALL - T), TWALL the wall's constant
   temperature (K), H the heat transfer coefficient (W/(m2 K)); fix musen/heat updates T.
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {
constexpr double MUSEN_PI = 3.14159265358979323846;    // MUSENDefinitions.h PI

class HeatTransfer : public musen_pw::Law {
 public:
  HeatTransfer(double wall_temperature, double coefficient, double resist) :
      wall_temperature(wall_temperature), coefficient(coefficient), resist(resist)
  {
  }
  void force(const musen_pw::Contact &, const musen_pw::Materials &, double *, double *fo,
             double *to) const override
  {
    for (int k = 0; k < 3; k++) fo[k] = to[k] = 0.0;
  }
  bool heats() const override { return true; }
  double heat(const musen_pw::Contact &c) const override
  {
    return MUSEN_PI * c.radius * c.overlap * coefficient * resist * (wall_temperature - c.temperature);
  }

 private:
  double wall_temperature, coefficient, resist;
};

std::unique_ptr<musen_pw::Law> create(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 3 || !std::isfinite(params[0]) || !std::isfinite(params[1]) ||
      !std::isfinite(params[2])) {
    why = "law heat/transfer needs finite TWALL H RESIST";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new HeatTransfer(params[0], params[1], params[2]));
}

const bool registered = musen_pw::add("heat/transfer", &create);

}    // namespace
