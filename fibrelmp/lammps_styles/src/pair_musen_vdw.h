/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/vdw: MUSEN's Hertz-Mindlin contact with van der Waals attraction (MUSEN
   commit e0ff360, Models/ParticleParticle/HertzMindlinVdW/ModelPPHertzMindlinVdW.cpp).
     pair_style musen/vdw GAMMA [then LAW [params]] ...
     pair_coeff I J Estar Gstar e mu mu_r        (as musen/hm)
   musen/hm whose first law is hertz/mindlin/vdw GAMMA (musen_pp_hertz_mindlin_vdw.cpp,
   GAMMA the equivalent surface energy [J/m2]); later laws as musen/hm's.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(musen/vdw,PairMusenVdW);
// clang-format on
#else

#ifndef FIBRELMP_PAIR_MUSEN_VDW_H
#define FIBRELMP_PAIR_MUSEN_VDW_H

#include "pair_musen_hm.h"

namespace LAMMPS_NS {

class PairMusenVdW : public PairMusenHM {
 public:
  PairMusenVdW(class LAMMPS *);
  void settings(int, char **) override;
};

}    // namespace LAMMPS_NS

#endif
#endif
