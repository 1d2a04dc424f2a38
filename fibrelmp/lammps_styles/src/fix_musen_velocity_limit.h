/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenVelocityLimit (fix style musen/velocity/limit): MUSEN's particle velocity limit
   (LIMIT_PARTICLE_VELOCITY, CCPUSimulator::MoveParticles, MUSEN 1.74.2 e0ff360): after the
   velocity update, a sphere faster than VMAX has its velocity scaled to VMAX, and that is the
   velocity it moves with.

     fix ID group musen/velocity/limit VMAX      (defined BEFORE the group's fix nve/bpm/sphere)

   fix nve/bpm/sphere kicks (v += dt/2 f/m) and moves (x += dt v) in one initial_integrate;
   MUSEN's leapfrog velocity at that point is v + dt/2 f/m.  This fix's initial_integrate runs
   first and sets v to clamp(v + dt/2 f/m) - dt/2 f/m, so the kick that follows gives the
   clamped velocity (to the rounding of one addition) before the move.  Angular velocities
   are not limited (neither are they in MUSEN).
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_VELOCITY_LIMIT_H
#define FIBRELMP_FIX_MUSEN_VELOCITY_LIMIT_H

#include "fix.h"

namespace LAMMPS_NS {

class FixMusenVelocityLimit : public Fix {
 public:
  FixMusenVelocityLimit(class LAMMPS *, int, char **);
  int setmask() override;
  void init() override;
  void initial_integrate(int) override;

 private:
  double vmax;
};

}    // namespace LAMMPS_NS

#endif
