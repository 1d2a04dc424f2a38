/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Particle-particle law "hertz/mindlin": MUSEN's ModelPPHertzMindlin.cpp CalculatePP (commit
   e0ff360): Kn = 2 E* a, Kt = 8 G* a with a = sqrt(R* overlap), elastic normal force
   -2/3 overlap Kn; the rest is musen_pp::MindlinShaped.  pair_style musen/hm's first law; in
   a header so that musen/hm alone calls it inlined (pair_musen_hm.cpp).
------------------------------------------------------------------------- */

#ifndef FIBRELMP_MUSEN_PP_HERTZ_MINDLIN_H
#define FIBRELMP_MUSEN_PP_HERTZ_MINDLIN_H

#include "musen_pp_law.h"

#include <cmath>

namespace LAMMPS_NS {
namespace musen_pp {

class HertzMindlin final : public MindlinShaped<HertzMindlin> {
 public:
  void stiffness(const Materials &m, double overlap, double equiv_radius, double &kn,
                 double &kt, double &fn_el) const
  {
    // Hertz: both stiffnesses grow with the contact area radius
    const double contact_area_radius = std::sqrt(equiv_radius * overlap);
    kn = 2 * m.estar * contact_area_radius;
    fn_el = -overlap * kn * 2. / 3.;
    kt = 8 * m.gstar * contact_area_radius;
  }
};

}    // namespace musen_pp
}    // namespace LAMMPS_NS

#endif
