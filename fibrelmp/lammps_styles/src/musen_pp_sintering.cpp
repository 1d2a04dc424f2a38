/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "sintering D ETA GAMMA": MUSEN's ModelPPSintering.cpp CalculatePP
   (commit e0ff360, Models/ParticleParticle/TestSinteringModel), operation by operation
   (Bouvard and McMeeking): on src, along the unit normal n (src to dst)
     F = n 1.125 pi 2R* GAMMA  -  vn_M pi (4 R* overlap)^2 / (8 D)
         -  vt_M ETA pi (4 R* overlap) (2R*)^2 / (8 D)
   with vn_M, vt_M the normal and tangential parts of v_src - v_dst, the *centre* velocities
   (MUSEN's Particles().Vel: no spin term), GAMMA the equivalent surface energy
   sqrt(gamma1 gamma2).  No elastic force, no moments; the tangential overlap is left as the
   previous law left it (MUSEN's law does not touch vTangOverlap).
------------------------------------------------------------------------- */

#include "musen_pp_law.h"

#include <cmath>

using namespace LAMMPS_NS;

namespace {

constexpr double MUSEN_PI = 3.14159265358979323846;    // MUSENDefinitions.h PI

class Sintering final : public musen_pp::Law {
 public:
  Sintering(double d, double eta, double gamma) : diffusion(d), viscous(eta), surface_energy(gamma) {}

  void force(const musen_pp::Contact &c, const musen_pp::Materials &, double *,
             musen_pp::Result &r) const override
  {
    const double *n = c.n;
    double vn_m, vt_m[3];
    musen_pp::centre_relative_velocity(c, vn_m, vt_m);

    const double squared_contact_radius = 4 * c.equiv_radius * c.overlap;
    const double sintering = 1.125 * MUSEN_PI * 2 * c.equiv_radius * surface_energy;
    const double viscous_n = -MUSEN_PI * std::pow(squared_contact_radius, 2) / 8 / diffusion;
    const double viscous_t = -viscous * MUSEN_PI * squared_contact_radius *
        std::pow(2 * c.equiv_radius, 2) / 8 / diffusion;
    // sinteringForce + viscousForce along n; tangForce across it (MUSEN sums the vectors)
    r.fn_len = sintering + vn_m * viscous_n;
    for (int k = 0; k < 3; k++) {
      r.fn[k] = n[k] * sintering + n[k] * vn_m * viscous_n;
      r.ft[k] = vt_m[k] * viscous_t;
      r.m1[k] = r.m2[k] = 0.0;
    }
  }

 private:
  double diffusion, viscous, surface_energy;
};

std::unique_ptr<musen_pp::Law> create(const std::vector<double> &params, std::string &why)
{
  if (params.size() != 3 || !(params[0] > 0) || !std::isfinite(params[0]) ||
      !std::isfinite(params[1]) || !(params[2] >= 0) || !std::isfinite(params[2])) {
    why = "law sintering needs D > 0 (MUSEN's DIFFUSION), ETA (VISCOUS_PARAMETER) and the "
          "equivalent surface energy GAMMA >= 0 [J/m2]";
    return nullptr;
  }
  return std::unique_ptr<musen_pp::Law>(new Sintering(params[0], params[1], params[2]));
}

const bool registered = musen_pp::add("sintering", &create);

}    // namespace
