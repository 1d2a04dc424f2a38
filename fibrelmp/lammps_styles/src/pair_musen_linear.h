/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/linear: MUSEN's linear elastic particle-particle contact (MUSEN commit
   e0ff360, Models/ParticleParticle/LinearElastic/ModelPPLinearElastic.cpp, CalculatePP).
     pair_style musen/linear Kn Kt [then LAW [params]] ...
     pair_coeff I J Estar Gstar e mu mu_r        (as musen/hm; Estar, Gstar unused)
   musen/hm whose first law is linear/elastic Kn Kt (musen_pp_linear_elastic.cpp: constant
   stiffnesses Kn, Kt [N/m], elastic normal force -Kn * overlap); later laws as musen/hm's.
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
};

}    // namespace LAMMPS_NS

#endif
#endif
