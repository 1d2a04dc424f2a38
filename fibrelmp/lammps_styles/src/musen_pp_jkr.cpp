/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle laws "jkr GAMMA" and "popov/jkr SIGMA": MUSEN's ModelPPJKR.cpp and
   ModelPPPopovJKR.cpp CalculatePP (commit e0ff360).  Both are Hertz-Mindlin-shaped
   (musen_pp::MindlinShaped: Kn = 2 E* a, Kt = 8 G* a, a = sqrt(R* overlap), MUSEN's damping,
   friction and rolling torque) around an adhesive elastic normal force:
     jkr:       -(4 a^3 E* / (3 R*) - sqrt(8 pi E* GAMMA a^3)), GAMMA the equivalent surface
                energy sqrt(g1 g2) [J/m2] (MUSEN property 11);
     popov/jkr: -Fadh (-1 + 0.12 (overlap / s + 1)^(5/3)), Fadh = 3/2 SIGMA pi R*,
                s = (0.4626 (SIGMA / E*)^2 R*)^(1/3), SIGMA the equivalent surface TENSION
                sqrt(s1 s2) [N/m] (MUSEN property 13, as its code reads, not the energy).
   MUSEN evaluates them only for overlapping spheres (CheckPPCollision), so the attraction
   acts inside the contact: jkr's force is 0 at zero overlap, popov/jkr's is 0.88 Fadh there
   (MUSEN's law jumps at the contact edge).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;    // MUSENDefinitions.h PI

class JKR : public musen_pp::MindlinShaped<JKR> {
 public:
  explicit JKR(double gamma) : surface_energy(gamma) {}
  void stiffness(const musen_pp::Materials &m, double overlap, double equiv_radius, double &kn,
                 double &kt, double &fn_el) const
  {
    const double a = std::sqrt(equiv_radius * overlap);
    kn = 2 * m.estar * a;
    fn_el = -1 * (4. * std::pow(a, 3.) * m.estar / (3. * equiv_radius) -
                  std::sqrt(8 * MUSEN_PI * m.estar * surface_energy * std::pow(a, 3.)));
    kt = 8 * m.gstar * a;
  }

 private:
  double surface_energy;
};

class PopovJKR : public musen_pp::MindlinShaped<PopovJKR> {
 public:
  explicit PopovJKR(double sigma) : surface_tension(sigma) {}
  void stiffness(const musen_pp::Materials &m, double overlap, double equiv_radius, double &kn,
                 double &kt, double &fn_el) const
  {
    const double a = std::sqrt(equiv_radius * overlap);
    kn = 2 * m.estar * a;
    const double adh_force = 3. / 2. * surface_tension * MUSEN_PI * equiv_radius;
    const double s_adh =
        std::pow(0.4626 * std::pow(surface_tension / m.estar, 2) * equiv_radius, 1. / 3.);
    fn_el = -adh_force * (-1 + 0.12 * std::pow(overlap / s_adh + 1, 5. / 3.));
    kt = 8 * m.gstar * a;
  }

 private:
  double surface_tension;
};

std::unique_ptr<musen_pp::Law> create_jkr(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 1 || !(params[0] >= 0) || !std::isfinite(params[0])) {
    why = "law jkr needs the equivalent surface energy GAMMA >= 0 [J/m2]";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new JKR(params[0]));
}

std::unique_ptr<musen_pp::Law> create_popov(const std::vector<double> &params, std::string &why)
{
  // SIGMA = 0 divides by zero in MUSEN's range s (an infinite force)
  if (params.size() != 1 || !(params[0] > 0) || !std::isfinite(params[0])) {
    why = "law popov/jkr needs the equivalent surface tension SIGMA > 0 [N/m]";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new PopovJKR(params[0]));
}

const bool registered_jkr = musen_pp::add("jkr", &create_jkr);
const bool registered_popov = musen_pp::add("popov/jkr", &create_popov);

}    // namespace
