/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-wall laws "jkr GAMMA" and "popov/jkr SIGMA": MUSEN's ModelPWJKR.cpp and
   ModelPWPopovJKR.cpp CalculatePW (commit e0ff360): ModelPWHertzMindlin's operations
   (musen_pw::MindlinShaped, musen_pw_law.h; R* = R, m* = m) with another elastic normal force,
   as written:
     jkr:       4 a^3 E* / (3 R) - sqrt(8 pi E* GAMMA a^3) |rc_n . n|  (MUSEN scales only the
                adhesive term by |rc_n . n|: C++ precedence, kept);
     popov/jkr: Fadh (-1 + 0.12 (overlap / s + 1)^(5/3)) |rc_n . n|, Fadh = 3/2 SIGMA pi R,
                s = (0.4626 (SIGMA / E*)^2 R)^(1/3); and its tangential spring force is
                -Kt times the OLD tangential overlap (as it came, not rotated nor advanced;
                MUSEN's code), the new overlap still being stored.
   GAMMA: the equivalent surface energy sqrt(g_wall g_sphere) [J/m2]; SIGMA the equivalent
   surface tension [N/m] (MUSEN's interaction properties, CalculateInteractionProperty).
------------------------------------------------------------------------- */

#include "musen_pw_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;    // MUSENDefinitions.h PI

class JKR : public musen_pw::MindlinShaped<JKR> {
 public:
  explicit JKR(double gamma) : surface_energy(gamma) {}
  double elastic(const musen_pw::Materials &L, double, double a, double R, double cos_rc) const
  {
    return 4. * std::pow(a, 3.) * L.estar / (3. * R) -
        std::sqrt(8. * MUSEN_PI * L.estar * surface_energy * std::pow(a, 3.)) * cos_rc;
  }

 private:
  double surface_energy;
};

class PopovJKR : public musen_pw::MindlinShaped<PopovJKR, true> {
 public:
  explicit PopovJKR(double sigma) : surface_tension(sigma) {}
  double elastic(const musen_pw::Materials &L, double overlap, double, double R,
                 double cos_rc) const
  {
    const double adh_force = 3. / 2. * surface_tension * MUSEN_PI * R;
    const double s_adh = std::pow(0.4626 * std::pow(surface_tension / L.estar, 2) * R, 1. / 3.);
    return adh_force * (-1 + 0.12 * std::pow(overlap / s_adh + 1, 5. / 3.)) * cos_rc;
  }

 private:
  double surface_tension;
};

std::unique_ptr<musen_pw::Law> create_jkr(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 1 || !(params[0] >= 0) || !std::isfinite(params[0])) {
    why = "law jkr needs the equivalent surface energy GAMMA >= 0 [J/m2]";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new JKR(params[0]));
}

std::unique_ptr<musen_pw::Law> create_popov(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 1 || !(params[0] > 0) || !std::isfinite(params[0])) {
    why = "law popov/jkr needs the equivalent surface tension SIGMA > 0 [N/m]";
    return nullptr;
  }
  return std::unique_ptr<musen_pw::Law>(new PopovJKR(params[0]));
}

const bool registered_jkr = musen_pw::add("jkr", &create_jkr);
const bool registered_popov = musen_pw::add("popov/jkr", &create_popov);

}    // namespace
