/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/linear: MUSEN's linear elastic particle-particle contact (MUSEN commit
   e0ff360, Models/ParticleParticle/LinearElastic/ModelPPLinearElastic.cpp, CalculatePP).
     pair_style musen/linear Kn Kt
     pair_coeff I J Estar Gstar e mu mu_r        (as musen/hm; Estar, Gstar unused)
   MUSEN's law is musen/hm's with constant stiffnesses Kn, Kt [N/m] and the elastic normal
   force -Kn * overlap: damping (from e and m*), tangential overlap, Coulomb test and rolling
   torque are the same operations, so the style overrides PairMusenHM::stiffness only.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(musen/linear,PairMusenLinear);
// clang-format on
#else

#ifndef FIBRELMP_PAIR_MUSEN_LINEAR_H
#define FIBRELMP_PAIR_MUSEN_LINEAR_H

#include "pair_musen_hm.h"

namespace LAMMPS_NS {

class PairMusenLinear : public PairMusenHM {
 public:
  PairMusenLinear(class LAMMPS *);
  void settings(int, char **) override;
  void write_restart_settings(FILE *) override;
  void read_restart_settings(FILE *) override;

 protected:
  double normal_stiffness = 0.0, tangential_stiffness = 0.0;    // MUSEN's Kn, Kt
  void stiffness(int itype, int jtype, double overlap, double equiv_radius, double &kn,
                 double &kt, double &fn_el) const override;
};

}    // namespace LAMMPS_NS

#endif
#endif
