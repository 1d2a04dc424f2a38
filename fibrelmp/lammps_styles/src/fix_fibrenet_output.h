/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   FixFibreNetOutput (fix fibrenet/output) and its frame command (fibrenet/frame): FibreNet's
   own result files written by LAMMPS, byte for byte what fibrelmp's Python writer
   (fibrelmp/translate/fibrenet/writer.py fed by fibrelmp/post/to_fibrenet.py) writes from a
   %.17g dump of the same frames, so a job run with `lmp -in in.lammps` leaves FibreNet's
   files and `fibrelmp run` converts nothing.

     fix ID group fibrenet/output PREFIX keyword values ...
       dt DT                   FibreNet's time step (the FRAME lines)
       box LX LY LZ            FibreNet's box lengths (the FRAME lines, the wall check)
       names N1 ... Nntypes    FibreNet type name of every LAMMPS atom type
       files coord vel force   which of PREFIX_coord.xyz / _vel.xyz / _force.xyz to write
       only T1 T2 ... | none   LAMMPS types written to the xyz files (FibreNet's output_type;
                               default all); the restart file always holds every bead
       velocity v_a v_b v_c    atom-style variables of the velocity written (FibreNet's v~)
       force v_a v_b v_c       atom-style variables of the force written
       restart N | no          PREFIX_restart.res at the frames where FibreNet writes it for a
                               run of N steps (first frame past 25, 50, 75 %, and step N)
       dump FILE radius v_r mass v_m
                               also fibrelmp's work dump at every frame: byte for byte what
                                 write_dump all custom FILE id type x y z ix iy iz <velocity>
                                 <force> v_r v_m modify sort id format float %.17g time yes
                                 (columns named vx vy vz fx fy fz radius mass) appends, but
                                 formatted with std::to_chars (%.17g's digits, ~4x faster) and
                                 written in pieces (no second copy of the frame as text)
       chunk ROWS              rows formatted per chunk (default 32768); chunk c of a frame is
                                 formatted by rank c % nprocs

     fibrenet/frame ID         write one frame now (where fibrelmp's script has write_dump)

   The frame is written when the script says so, not at a step of a run: FibreNet's frames
   follow steps that are no LAMMPS `run` (the step-0 frame shows stored state, the first step
   after a (re)start is a `run 0` with velocities set around it), and the variables give the
   values exactly as the dump of the same point in the script evaluates them.

   Files: the xyz files are appended frame by frame (truncated at this job's first frame);
   a frame is formatted in chunks of rows, chunk c by rank c % nprocs (every rank formats),
   and rank 0 writes the chunks in order; every file is cut back to its size before the frame
   if any write fails, so no half frame is left.  The restart file goes through a temp file and a rename.  Rank 0
   writes; a failure ends every rank with the message.  The count of frames written, the
   restart stage and the wall-check result are global state saved in restart files, so a job
   continued from a LAMMPS restart appends (fibrelmp's checkpoints cut the xyz files back to
   the checkpoint).

   Global vector (f_ID[1], f_ID[2], f_ID[3]): the step of the first frame with a bead centre
   outside [0, L) on a non-periodic axis (-1: none so far), how many beads were outside then,
   and how many nan/inf values FibreNet's files hold (the xyz files' and the restart file's:
   fibrelmp scans the files for their lines only when it is not 0).
------------------------------------------------------------------------- */

#ifdef FIX_CLASS
// clang-format off
FixStyle(fibrenet/output,FixFibreNetOutput);
// clang-format on
#else

#ifndef FIBRELMP_FIX_FIBRENET_OUTPUT_H
#define FIBRELMP_FIX_FIBRENET_OUTPUT_H

#include "command.h"
#include "fix.h"

#include <algorithm>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FixFibreNetOutput : public Fix {
 public:
  FixFibreNetOutput(class LAMMPS *, int, char **);
  int setmask() override;
  double compute_vector(int) override;
  void write_restart(FILE *) override;
  void restart(char *) override;

  void write_frame();    // the fibrenet/frame command (every rank)

 private:
  enum { COORD, VEL, FORCE };
  std::string prefix;
  double dt;
  double box[3];
  std::vector<std::string> type_names;    // index: LAMMPS type (0 unused)
  std::vector<char> in_xyz;               // index: LAMMPS type; written to the xyz files?
  bool files[3];
  std::string vel_var[3], force_var[3];
  bigint restart_steps;                   // -1: no restart file
  std::string dump_path, radius_var, mass_var;    // the work dump ("": none)
  int nv;                                 // values gathered per atom (14, 16 with the dump)
  bigint chunk_rows;                      // rows formatted per chunk (keyword chunk)
  bigint chunk_count(bigint n) const { return (n + chunk_rows - 1) / chunk_rows; }
  bigint chunk_size(bigint c, bigint n) const { return std::min<bigint>(chunk_rows, n - c * chunk_rows); }

  // global state (restart files)
  bigint frames_written;
  float restart_stage;                    // FibreNet's restart_dump_stage (a float)
  bigint outside_step, outside_count;
  bigint nonfinite_xyz, nonfinite_res;    // nan/inf written: xyz files so far, last restart file

  // one chunk of a frame's rows as text: the lines of each file, the nan/inf among them
  struct FrameText {
    std::string xyz[3], res, dump;
    bigint bad_xyz = 0, bad_res = 0;
  };
  std::vector<double> send, recv, values, rows;
  FrameText text;
  void evaluate(const std::string &, double *);
  bool restart_due(bigint step);
  bool place_by_tag(std::vector<bigint> &) const;
  bigint sort_rows(bigint n, bigint step);
  void format_rows(const double *, bigint, bool, FrameText &) const;
  void send_text(FrameText &);
  void receive_text(int, FrameText &);
  std::string write_files(bigint n, bigint kept, bigint step, bool restart_now);
  std::string dump_head(bigint n) const;
};

// fibrenet/frame ID: FixFibreNetOutput ID writes a frame
class FibreNetFrame : public Command {
 public:
  FibreNetFrame(class LAMMPS *lmp) : Command(lmp) {}
  void command(int, char **) override;
};

}    // namespace LAMMPS_NS

#endif
#endif
