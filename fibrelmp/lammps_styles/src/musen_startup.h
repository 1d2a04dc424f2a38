/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   MUSEN's two force evaluations at t = 0 (its prediction iteration and its first step, both at
   x(0); fix_musen_leapfrog.h) advance contact and bond states like every later step.  In
   LAMMPS they are the set-ups of two `run 0`, and set-up evaluations do not advance states
   (a run cut into several run commands must compute the same forces as one run).
   `musen/predict ID start` and `musen/predict ID` each let the next set-up advance them: the
   styles ask advances(); fix musen/leapfrog's setup() ends the allowance.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_MUSEN_STARTUP_H
#define FIBRELMP_MUSEN_STARTUP_H

#include "update.h"

namespace LAMMPS_NS {
namespace musen_startup {

// one instance in the plugin library: set-up evaluations still to count as MUSEN steps
inline int &advancing_setups()
{
  static int pending = 0;
  return pending;
}

// whether this force evaluation is a MUSEN step (advances histories and bond states)
inline bool advances(const Update *update)
{
  return !update->setupflag || advancing_setups() > 0;
}

}    // namespace musen_startup
}    // namespace LAMMPS_NS

#endif
