/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/liquid: MUSEN's Hertz-Mindlin contact with a liquid bridge (MUSEN commit
   e0ff360, Models/ParticleParticle/HertzMindlinLiquid/ModelPPHertzMindlinLiquid.cpp).
     pair_style musen/liquid HMIN THETA SIGMA ETA [then LAW [params]] ...
     pair_coeff I J Estar Gstar e mu mu_r        (as musen/hm)
   musen/hm whose first law is hertz/mindlin/liquid (musen_pp_hertz_mindlin_liquid.cpp: MUSEN's
   MIN_THICKNESS [m], CONTACT_ANGLE [degrees], SURFACE_TENSION [N/m], DYNAMIC_VISCOSITY [Pa s]);
   later laws as musen/hm's.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(musen/liquid,PairMusenLiquid);
// clang-format on
#else

#ifndef FIBRELMP_PAIR_MUSEN_LIQUID_H
#define FIBRELMP_PAIR_MUSEN_LIQUID_H

#include "pair_musen_hm.h"

namespace LAMMPS_NS {

class PairMusenLiquid : public PairMusenHM {
 public:
  PairMusenLiquid(class LAMMPS *);
  void settings(int, char **) override;
};

}    // namespace LAMMPS_NS

#endif
#endif
