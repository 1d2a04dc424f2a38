/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   The simulation time of the current step, as LAMMPS computes it for dumps and thermo
   (Dump::compute_time): the time accumulated up to atimestep plus the steps since.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_LAMMPS_TIME_H
#define FIBRELMP_LAMMPS_TIME_H

#include "update.h"

namespace LAMMPS_NS {

inline double simulation_time(const Update *update)
{
  return update->atime + static_cast<double>(update->ntimestep - update->atimestep) * update->dt;
}

}    // namespace LAMMPS_NS

#endif
