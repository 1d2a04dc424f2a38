/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenVerlet (fix style musen/verlet): when MUSEN updates its contact list, and which
   broken bonds' spheres that update lets into the contacts.  MUSEN 1.74.2 (e0ff360):
   CCPUSimulator::UpdateVerletLists, CVerletList::IsNeedToBeUpdated / UpdateList /
   AutoAdjustVerletDistance / RemoveSBContacts, CSimplifiedScene::GetMaxPartVerletDistance.

     fix ID group musen/verlet DISTANCE [auto yes|no] [wallspeed W] [pbcspeed P]

   DISTANCE: MUSEN's initial Verlet distance (VERLET_COEF x the smallest contact radius);
   auto: MUSEN's auto-adjustment (default yes); W: the wall speed MUSEN's check adds per step
   (GetMaxWallVelocity as MUSEN freezes it after t = 0); P: the largest speed of a moving
   periodic box's faces (MUSEN adds 2 P per step, not P dt).

   At every force evaluation that is a MUSEN step (musen_startup.h) and before the forces,
   as MUSEN's UpdateCollisionsStep: wall += W dt (+ 2 P); the list is updated when
   d + max(wall, d) >= distance, d the largest displacement of a sphere since the last update
   (the first check always updates: MUSEN starts with wall = 1e12).  An update: the
   auto-adjustment (2nd and 3rd update: distance x 1.1; from the 4th on MUSEN chooses by its
   CPU clock: fibrelmp keeps the distance and warns when that could matter), the spheres'
   positions remembered, wall = 0, and every bond broken since the last update released:
   its spheres may touch from now on.  Until then (MUSEN: RemoveSBContacts kept the pair out
   of the list while the bond was active, and nothing adds it between updates) the pair stays
   a 1-2 special pair and the pair styles skip it.  A released pair leaves the special lists
   and its broken bond entry leaves the bond arrays (so a restart's special build does not make
   it special again); the neighbour list of the current build still marks it special, so the
   pair styles ask released() until LAMMPS's next build.

   Contacts of other pairs: MUSEN's list misses none (a pair outside it was farther apart
   than the distance at the update, and the check updates before any two spheres can have
   closed that gap), so LAMMPS's neighbour lists find the same contacts.

   Restart: the distance, the update count, the wall term, the broken pairs waiting
   (global) and each sphere's remembered position (per atom).
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIX_MUSEN_VERLET_H
#define FIBRELMP_FIX_MUSEN_VERLET_H

#include "fix.h"

#include <utility>
#include <vector>

namespace LAMMPS_NS {

class FixMusenVerlet : public Fix {
 public:
  FixMusenVerlet(class LAMMPS *, int, char **);
  ~FixMusenVerlet() override;
  int setmask() override;
  void setup_pre_force(int) override;
  void pre_force(int) override;
  void setup_post_neighbor() override;
  void post_neighbor() override;

  // bonds broken in this step (tag pairs, the same on every rank): wait for the next update
  void add_broken(const std::vector<std::pair<tagint, tagint>> &pairs);
  // a released pair the current neighbour list still marks special (pair styles ask)
  bool released(tagint a, tagint b) const;
  bool any_released() const { return !released_pairs.empty(); }

  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;
  void write_restart(FILE *) override;
  void restart(char *) override;
  double compute_vector(int) override;
  double memory_usage() override;

 private:
  double distance;          // MUSEN's m_dVerletDistance now
  int auto_adjust;          // m_bAutoAdjustVerletDistance
  double wall_speed;        // m_maxWallVelocity
  double pbc_speed;         // max |SPBC::vVel|
  double wall_term;         // m_dMaxTheorWallDistance
  bigint updates;           // contact-list updates so far
  bigint natoms_seen;       // a rise: new spheres (MUSEN: ResetCurrentData, update now)
  int warned;
  double **xref;            // each sphere's position at the last update (CoordVerlet)
  std::vector<std::pair<tagint, tagint>> waiting;          // broken, not yet released
  std::vector<std::pair<tagint, tagint>> released_pairs;   // released since the last build

  void check();
  void update_list();
  void release(tagint a, tagint b);
};

}    // namespace LAMMPS_NS

#endif
