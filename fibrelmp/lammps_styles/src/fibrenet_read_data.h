/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   fibrenet/read_data FILE: the box, masses, atoms, bonds and angles of a FibreNet job from
   the binary file fibrelmp writes beside data.lammps (topology.bin), with the result of
   `read_data data.lammps` for atom_style angle: the same box, atoms created in file order on
   the rank that owns them (unwrapped coordinates remapped into periodic boxes, image flags
   set), each bond stored with its first atom and each angle with its middle atom in file order
   (with newton_bond off also with the others), the same totals, the box shrink-wrapped around
   the atoms as read_data leaves it.  (read_data then moves atoms that the shrink-wrap put in
   another rank's sub-box at once; here the run's setup does, so on several ranks the atoms'
   order may differ from read_data's in that case: the same physics, sums in another order.)
   read_data parses the text on
   every rank and reads the topology twice (a first pass counts bonds per atom); this reads
   binary records once, on rank 0, in chunks broadcast to every rank: 2.6M beads load in about
   a second instead of 13.  The special lists are not built here: the `special_bonds` line
   that follows in fibrelmp's script changes the weights and so builds them (as it rebuilds
   them after read_data).

   The file's layout is documented once, where it is written: fibrelmp/translate/topology_file.py.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_FIBRENET_READ_DATA_H
#define FIBRELMP_FIBRENET_READ_DATA_H

#include "command.h"
#include "lmptype.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FibreNetReadData : public Command {
 public:
  FibreNetReadData(class LAMMPS *lmp) : Command(lmp) {}
  ~FibreNetReadData() override;    // closes the file, also when an error ends the command
  void command(int, char **) override;

 private:
  FILE *fp = nullptr;
  std::string path;

  void read(void *buf, size_t bytes, const char *what);     // every rank gets rank 0's bytes
  // the `count` records of `width` int64/double words that follow, CHUNK records at a time:
  // body(first, n, records) on every rank
  template <class Body> void each_chunk(int64_t count, int64_t width, const char *what, Body body);
  void check_stored(bigint stored, bigint expected, const char *what);
  void make_box(const int64_t *head, const double *box, const std::vector<double> &mass);
  void create_atoms(int64_t natoms, bool velocities);
  void add_bonds(int64_t nbonds);
  void add_angles(int64_t nangles);
};

}    // namespace LAMMPS_NS

#endif
