/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenPbcMove (fix style musen/pbc/move): MUSEN's moving periodic box (SPBC::vVel,
   GeneralSources/BasicTypes.h UpdatePBC, MUSEN 1.74.2 e0ff360): at time t the periodic box
   is [lo0 - v t, hi0 + v t] on each periodic axis (both faces move outwards with v; a
   negative v shrinks the box); positions are not remapped.

     fix ID group musen/pbc/move vx vy vz

   lo0, hi0: the box when the fix is created (t = 0, where MUSEN's simulation time starts).
   MUSEN sets the box for the current time before the forces of a step are computed; this
   fix sets it after the step's move (post_integrate), before LAMMPS wraps, exchanges and
   computes forces at the step's time.  The box change is declared (box_change), so LAMMPS's
   neighbour check accounts for it.  A restart file holds the box of its time and lo0, hi0.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_PBC_MOVE_H
#define FIBRELMP_FIX_MUSEN_PBC_MOVE_H

#include "fix.h"

namespace LAMMPS_NS {

class FixMusenPbcMove : public Fix {
 public:
  FixMusenPbcMove(class LAMMPS *, int, char **);
  int setmask() override;
  void init() override;
  void post_integrate() override;
  void write_restart(FILE *) override;
  void restart(char *) override;

 private:
  double vel[3], lo0[3], hi0[3];
  void set_box();
};

}    // namespace LAMMPS_NS

#endif
