/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenLeapfrog (fix style musen/leapfrog) and the command musen/predict: MUSEN's
   integrator (CBaseSimulator::StartSimulation, CCPUSimulator::MoveParticles, MUSEN 1.74.2
   e0ff360) for spheres.  Per MUSEN step: forces F(x, v) -> v += F/m dt, w += M/I dt (then
   the velocity limit) -> x += v dt.  LAMMPS computes forces between initial_integrate and
   final_integrate, so this fix does the whole update in initial_integrate with the forces of
   the previous step (still in f: LAMMPS clears them after initial_integrate), and nothing in
   final_integrate.  Between steps, v is then the velocity MUSEN's SaveData stores at that
   time: the one the spheres moved with to x(t).

     fix ID group musen/leapfrog [vlimit VMAX] [variable MOVE FACTOR STEP SAVING END]
     musen/predict ID start   (before the first run 0: its set-up is MUSEN's first evaluation)
     musen/predict ID         (after it: MUSEN's half-step prediction kick)

   MUSEN starts with a "prediction" iteration at t = 0: forces at x(0), v += F/m dt/2,
   w += M/I dt/2, no move; then its first full step computes the forces at x(0) again with
   those velocities; both evaluations advance contact and bond states (musen_startup.h).  The
   job script does: musen/predict start, run 0 (forces at x(0), v(0): the first frame),
   musen/predict, run 0 (forces again, with the predicted velocities), then the run.
   Quaternions are not integrated: MUSEN turns them only with anisotropy, which fibrelmp
   does not simulate.  VMAX: MUSEN's particle velocity limit (|v| scaled down to VMAX after
   the kick, before the move; angular velocities are not limited).

   variable: MUSEN's variable time step (CCPUSimulator::MoveParticles, m_variableTimeStep).
   Every step, once the forces are known (gravity added), before the kick:
   dt_max = sqrt(MOVE * sqrt(min m^2/|F|^2)) over the group's atoms whose force is not zero;
   dt > dt_max -> dt = dt_max, else dt < STEP -> dt = min(dt * FACTOR, STEP).  The new dt
   kicks and moves the spheres (and musen/predict's half kick); update->dt, atime and
   atimestep are set as fix dt/reset does, atime to MUSEN's summed time t += dt.  The fix keeps
   the time and dt from before the change (the walls move by them: MoveWalls gets the old
   dt) and writes them to the restart file.  The run stops (LAMMPS's timer, as fix halt
   does) after the step where MUSEN saves (|t - t_last| + 0.1 dt > SAVING) or ends
   (t >= END); "fix_modify ID write FILE [append yes|no]" appends "step t dt" (%.17g) to FILE
   and makes t the last save.  Global vector: [1] t, [2] 1 once t >= END, [3] dt, [4] the
   previous dt.

   Per-atom array (f_ID[1..3]): the force MUSEN's SaveData stores at this time, the total force
   of the previous evaluation (its SaveData runs before the step's force evaluation): f as
   initial_integrate finds it; zero before the first step.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_LEAPFROG_H
#define FIBRELMP_FIX_MUSEN_LEAPFROG_H

#include "command.h"
#include "fix.h"

namespace LAMMPS_NS {

class FixMusenLeapfrog : public Fix {
 public:
  FixMusenLeapfrog(class LAMMPS *, int, char **);
  ~FixMusenLeapfrog() override;
  int setmask() override;
  void init() override;
  void initial_integrate(int) override;
  void kick(double fraction);    // v += F/m fraction dt, w += M/I fraction dt (group atoms)

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;
  double memory_usage() override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int) override;
  int modify_param(int, char **) override;
  void write_restart(FILE *) override;
  void restart(char *) override;

  void vary_step();    // MUSEN's rule: update->dt from the forces in f (variable only)
  bool variable_step() const { return variable; }
  double step_start_time() const { return t_before; }    // MUSEN's time before this step
  double previous_dt() const { return dt_before; }      // the dt before this step's change

 private:
  double vmax;             // 0: no limit
  bool variable;           // MUSEN's variable time step
  double move_limit, step_factor, step_max, saving_step, end_time;
  double t_now, t_last, t_before, dt_before;    // MUSEN's time, last save, before this step
  int stopped_for;         // 0 running, 1 a save is due, 2 the end is reached
  double **saved_force;    // per atom: the force cmusen saves now (previous evaluation's)
};

class MusenPredict : public Command {
 public:
  MusenPredict(class LAMMPS *lmp) : Command(lmp) {}
  void command(int, char **) override;
};

}    // namespace LAMMPS_NS

#endif
