/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/sintering: MUSEN's sintering contact (Bouvard and McMeeking; MUSEN
   commit e0ff360, Models/ParticleParticle/TestSinteringModel/ModelPPSintering.cpp).
     pair_style musen/sintering D ETA GAMMA [then LAW [params]] ...
     pair_coeff I J Estar Gstar e mu mu_r        (as musen/hm)
   musen/hm whose first law is sintering D ETA GAMMA (musen_pp_sintering.cpp: MUSEN's
   DIFFUSION, VISCOUS_PARAMETER, the equivalent surface energy [J/m2]); later laws as musen/hm's.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(musen/sintering,PairMusenSintering);
// clang-format on
#else

#ifndef FIBRELMP_PAIR_MUSEN_SINTERING_H
#define FIBRELMP_PAIR_MUSEN_SINTERING_H

#include "pair_musen_hm.h"

namespace LAMMPS_NS {

class PairMusenSintering : public PairMusenHM {
 public:
  PairMusenSintering(class LAMMPS *);
  void settings(int, char **) override;
};

}    // namespace LAMMPS_NS

#endif
#endif
