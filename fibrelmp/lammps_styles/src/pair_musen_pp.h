/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   pair_style musen/pp: MUSEN's particle-particle laws, any of musen_pp_law.h's first.
     pair_style musen/pp LAW [params] [then LAW [params]] ...
     pair_coeff I J Estar Gstar e mu mu_r        (as musen/hm; a law uses what it needs)
   musen/hm whose first law is named, not hertz/mindlin: for MUSEN's PP models without a
   Hertz-Mindlin part (ModelPPHertz: "hertz", ModelPPSimpleViscoElastic:
   "simple/viscoelastic Kn mu").  "hertz" keeps MUSEN's tangential force, not overlap, in the
   contact's history, so it is the only law of the style.
------------------------------------------------------------------------- */

#ifdef PAIR_CLASS
// clang-format off
PairStyle(musen/pp,PairMusenPP);
// clang-format on
#else

#ifndef FIBRELMP_PAIR_MUSEN_PP_H
#define FIBRELMP_PAIR_MUSEN_PP_H

#include "pair_musen_hm.h"

namespace LAMMPS_NS {

class PairMusenPP : public PairMusenHM {
 public:
  PairMusenPP(class LAMMPS *);
  void settings(int, char **) override;
  void write_restart_settings(FILE *) override;
};

}    // namespace LAMMPS_NS

#endif
#endif
