/* ----------------------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).
   FixFibreNetOutput and the fibrenet/frame command: see fix_fibrenet_output.h.

   The reference for every byte is fibrelmp's Python path, which follows FibreNet's
   SimulationManager::DumpData / DumpRestartData (github.com/ppieczywek/FibreNet, fe11bbcc):
   - fibrelmp/post/to_fibrenet.py (FibreNetFrames, wrapped_and_unwrapped): atoms in id order,
     unwrapped = x + image * (hi - lo), wrapped = lo + ((unwrapped - lo) mod L) on periodic
     axes with Python's/numpy's float modulo, x as is on the others;
   - fibrelmp/translate/fibrenet/writer.py: xyz frames "N\nFRAME\tstep\t%.5f dt\t%.5f L...\n"
     and rows "name\t%.5f\t%.5f\t%.5f\n" (std::fixed, 5 decimals in FibreNet); restart
     "N\nFRAME\tstep\t%g dt\t%g L...\n" and rows "\tname" + 12 x "\t%g" (default ostream
     precision in FibreNet); nan is written "nan" (Python's %), never glibc's "-nan".
------------------------------------------------------------------------- */

#include "fix_fibrenet_output.h"
#include "lammps_time.h"
#include "style_registry.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "input.h"
#include "modify.h"
#include "update.h"
#include "utils.h"
#include "variable.h"

#include <mpi.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <numeric>
#include <sys/stat.h>
#include <unistd.h>

using namespace LAMMPS_NS;

namespace {

// per gathered atom: tag type x y z ix iy iz v0 v1 v2 f0 f1 f2 [radius mass] (the work dump's)
constexpr int NV = 14;
constexpr int NV_DUMP = 16;
// a frame is formatted in chunks of this many rows, chunk c by rank c % nprocs, and written by
// rank 0 in order (all ranks format; no rank holds more than a chunk of text)
constexpr bigint CHUNK_ROWS = 32768;    // the default of keyword chunk
// the largest piece of text in one MPI message
constexpr size_t TEXT_PIECE = size_t(1) << 30;

const char *const XYZ_SUFFIX[3] = {"_coord.xyz", "_vel.xyz", "_force.xyz"};
const char *const RESTART_SUFFIX = "_restart.res";
const char *const FILE_KEYS[3] = {"coord", "vel", "force"};

// Python's float % and numpy's remainder (npy_divmod): fmod, moved into [0, b) for b > 0,
// and +0.0 for an exact multiple.  Exactly these operations, so the wrapped coordinate is
// the double fibrelmp's converter computes.
double py_mod(double a, double b)
{
  double mod = std::fmod(a, b);
  if (mod != 0.0) {
    if ((b < 0) != (mod < 0)) mod += b;
  } else {
    mod = std::copysign(0.0, b);
  }
  return mod;
}

// ---- "%.5f" as printf writes it, without printf's cost for ordinary values.
// |x| 1e5 = p + e exactly (Dekker's product), so the rounding decision, ties to even
// included, is made on the exact binary value as glibc does.  Values whose scaled magnitude
// reaches 2^51 (and inf) go to snprintf; nan is "nan" as Python's % writes it.
constexpr double SPLIT = 134217729.0;         // 2^27 + 1
constexpr double LIMIT = 2251799813685248.0;  // 2^51

const char DIGITS2[201] = "0001020304050607080910111213141516171819"
                          "2021222324252627282930313233343536373839"
                          "4041424344454647484950515253545556575859"
                          "6061626364656667686970717273747576777879"
                          "8081828384858687888990919293949596979899";

void put_uint(std::string &out, uint64_t v)
{
  char buf[24];
  char *end = buf + sizeof(buf), *q = end;
  while (v >= 100) {
    const unsigned r = static_cast<unsigned>(v % 100);
    v /= 100;
    *--q = DIGITS2[2 * r + 1];
    *--q = DIGITS2[2 * r];
  }
  if (v >= 10) {
    *--q = DIGITS2[2 * v + 1];
    *--q = DIGITS2[2 * v];
  } else {
    *--q = static_cast<char>('0' + v);
  }
  out.append(q, end - q);
}

void put_fixed5(std::string &out, double x)
{
  if (std::isnan(x)) {
    out += "nan";
    return;
  }
  const double a = std::fabs(x);
  const double scale = 100000.0;
  const double p = a * scale;
  if (!(p < LIMIT)) {
    char buf[400];    // %.5f of DBL_MAX: 309 digits + sign + point + decimals
    std::snprintf(buf, sizeof(buf), "%.5f", x);
    out += buf;
    return;
  }
  const double c = SPLIT * a, ah = c - (c - a), al = a - ah;
  const double cb = SPLIT * scale, bh = cb - (cb - scale), bl = scale - bh;
  const double e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;    // p + e == a * 1e5
  auto m = static_cast<uint64_t>(p);                                  // floor (p >= 0)
  const double f = p - static_cast<double>(m);                       // exact below 2^51
  if (f > 0.5 || (f == 0.5 && (e > 0 || (e == 0 && (m & 1))))) m++;
  if (std::signbit(x)) out += '-';                                    // printf keeps -0.0's sign
  put_uint(out, m / 100000);
  const auto fr = static_cast<unsigned>(m % 100000);
  char d[6] = {'.', DIGITS2[2 * (fr / 1000)], DIGITS2[2 * (fr / 1000) + 1],
               DIGITS2[2 * ((fr / 10) % 100)], DIGITS2[2 * ((fr / 10) % 100) + 1],
               static_cast<char>('0' + fr % 10)};
  out.append(d, 6);
}

// printf's "%.<precision>g", byte for byte: std::to_chars in general format with a precision
// is specified to give printf's output, ~4x faster than glibc's printf (which formats with
// multi-precision arithmetic)
void put_general(std::string &out, double x, int precision)
{
  char buf[32];
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
  const auto r = std::to_chars(buf, buf + sizeof(buf), x, std::chars_format::general, precision);
  out.append(buf, r.ptr - buf);
#else
  const int n = std::snprintf(buf, sizeof(buf), "%.*g", precision, x);
  out.append(buf, static_cast<size_t>(n));
#endif
}

// "%g" (6 significant digits, FibreNet's default ostream precision); nan as "nan"
void put_g(std::string &out, double x)
{
  if (std::isnan(x))
    out += "nan";
  else
    put_general(out, x, 6);
}

// "%.17g" (dump custom's "format float %.17g": nan stays printf's, e.g. "-nan")
void put_g17(std::string &out, double x)
{
  put_general(out, x, 17);
}

void put_int(std::string &out, bigint v)
{
  if (v < 0) {
    out += '-';
    put_uint(out, static_cast<uint64_t>(-(v + 1)) + 1);
  } else {
    put_uint(out, static_cast<uint64_t>(v));
  }
}

// a FibreNet frame's first two lines: "count\nFRAME\tstep\tdt\tLx\tLy\tLz\n", the numbers by put
std::string frame_head(bigint count, bigint step, double dt, const double *box,
                       void (*put)(std::string &, double))
{
  std::string head;
  put_int(head, count);
  head += "\nFRAME\t";
  put_int(head, step);
  for (double v : {dt, box[0], box[1], box[2]}) {
    head += '\t';
    put(head, v);
  }
  head += '\n';
  return head;
}

std::string reason(int err)
{
  return std::strerror(err);
}

// the whole of data appended to fd (retrying short writes); errno on failure, else 0
int write_all(int fd, const std::string &data)
{
  const char *p = data.data();
  size_t left = data.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  return 0;
}

}    // namespace

/* ---------------------------------------------------------------------- */

FixFibreNetOutput::FixFibreNetOutput(LAMMPS *lmp, int narg, char **arg) :
    Fix(lmp, narg, arg), dt(0.0), restart_steps(-1), nv(NV), chunk_rows(CHUNK_ROWS), frames_written(0), restart_stage(0.25f),
    outside_step(-1), outside_count(0), nonfinite_xyz(0), nonfinite_res(0)
{
  const std::string usage =
      "fix ID group fibrenet/output PREFIX dt DT box LX LY LZ names N1 .. Nntypes "
      "[files coord vel force] [only T ...|none] velocity v_x v_y v_z force v_x v_y v_z "
      "restart N|no [dump FILE radius v_r mass v_m] [chunk ROWS]";
  if (narg < 4) error->all(FLERR, "Illegal fix fibrenet/output command: {}", usage);
  if (!atom->tag_enable) error->all(FLERR, "Fix fibrenet/output needs atom IDs");
  if (domain->triclinic) error->all(FLERR, "Fix fibrenet/output needs an orthogonal box");
  prefix = arg[3];
  if (prefix.empty()) error->all(FLERR, "Fix fibrenet/output: empty file prefix");

  const int ntypes = atom->ntypes;
  type_names.assign(ntypes + 1, "");
  in_xyz.assign(ntypes + 1, 1);
  files[COORD] = files[VEL] = files[FORCE] = false;
  bool have_dt = false, have_box = false, have_names = false, have_vel = false,
       have_force = false, have_restart = false;

  auto need = [&](int iarg, int n, const char *key) {
    if (iarg + n >= narg)
      error->all(FLERR, "Fix fibrenet/output: keyword {} needs {} value(s); usage: {}", key, n,
                 usage);
  };
  auto variables = [&](int iarg, std::string *out, const char *key) {
    need(iarg, 3, key);
    for (int k = 0; k < 3; k++) {
      const std::string name = arg[iarg + 1 + k];
      if (!utils::strmatch(name, "^v_."))
        error->all(FLERR, "Fix fibrenet/output: {} takes three atom-style variables (v_name), got {}",
                   key, name);
      out[k] = name.substr(2);
    }
  };

  int iarg = 4;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "dt") {
      need(iarg, 1, "dt");
      dt = utils::numeric(FLERR, arg[iarg + 1], false, lmp);
      have_dt = true;
      iarg += 2;
    } else if (key == "box") {
      need(iarg, 3, "box");
      for (int d = 0; d < 3; d++) box[d] = utils::numeric(FLERR, arg[iarg + 1 + d], false, lmp);
      have_box = true;
      iarg += 4;
    } else if (key == "names") {
      // exactly one name per LAMMPS type: a name may be any word, even a keyword
      need(iarg, ntypes, "names");
      for (int t = 1; t <= ntypes; t++) type_names[t] = arg[iarg + t];
      have_names = true;
      iarg += 1 + ntypes;
    } else if (key == "files") {
      iarg++;
      while (iarg < narg) {
        int which = -1;
        for (int k = 0; k < 3; k++)
          if (strcmp(arg[iarg], FILE_KEYS[k]) == 0) which = k;
        if (which < 0) break;
        files[which] = true;
        iarg++;
      }
    } else if (key == "only") {
      std::fill(in_xyz.begin(), in_xyz.end(), 0);
      iarg++;
      int count = 0;
      if (iarg < narg && strcmp(arg[iarg], "none") == 0) {    // output_type of no bead's type
        iarg++;
        continue;
      }
      while (iarg < narg && utils::is_integer(arg[iarg])) {
        const int t = utils::inumeric(FLERR, arg[iarg], false, lmp);
        if (t < 1 || t > ntypes)
          error->all(FLERR, "Fix fibrenet/output: only {}: atom types are 1 to {}", t, ntypes);
        in_xyz[t] = 1;
        count++;
        iarg++;
      }
      if (!count) error->all(FLERR, "Fix fibrenet/output: only needs atom types (or none)");
    } else if (key == "velocity") {
      variables(iarg, vel_var, "velocity");
      have_vel = true;
      iarg += 4;
    } else if (key == "force") {
      variables(iarg, force_var, "force");
      have_force = true;
      iarg += 4;
    } else if (key == "restart") {
      need(iarg, 1, "restart");
      if (strcmp(arg[iarg + 1], "no") == 0) {
        restart_steps = -1;
      } else {
        restart_steps = utils::bnumeric(FLERR, arg[iarg + 1], false, lmp);
        if (restart_steps < 0)
          error->all(FLERR, "Fix fibrenet/output: restart needs a number of steps >= 0 or no");
      }
      have_restart = true;
      iarg += 2;
    } else if (key == "chunk") {
      need(iarg, 1, "chunk");
      chunk_rows = utils::bnumeric(FLERR, arg[iarg + 1], false, lmp);
      if (chunk_rows < 1) error->all(FLERR, "Fix fibrenet/output: chunk needs a number of rows >= 1");
      iarg += 2;
    } else if (key == "dump") {
      need(iarg, 5, "dump");
      dump_path = arg[iarg + 1];
      if (dump_path.empty() || strcmp(arg[iarg + 2], "radius") != 0 || strcmp(arg[iarg + 4], "mass") != 0 ||
          !utils::strmatch(arg[iarg + 3], "^v_.") || !utils::strmatch(arg[iarg + 5], "^v_."))
        error->all(FLERR, "Fix fibrenet/output: dump needs FILE radius v_name mass v_name; usage: {}",
                   usage);
      radius_var = std::string(arg[iarg + 3]).substr(2);
      mass_var = std::string(arg[iarg + 5]).substr(2);
      nv = NV_DUMP;
      iarg += 6;
    } else {
      error->all(FLERR, "Fix fibrenet/output: unknown keyword {}; usage: {}", key, usage);
    }
  }
  if (!have_dt || !have_box || !have_names || !have_vel || !have_force || !have_restart)
    error->all(FLERR, "Fix fibrenet/output needs dt, box, names, velocity, force and restart; "
                      "usage: {}", usage);

  restart_global = 1;
  vector_flag = 1;
  size_vector = 3;
  global_freq = 1;
  extvector = 0;
}

int FixFibreNetOutput::setmask()
{
  return 0;    // nothing per step: frames are written by the fibrenet/frame command
}

double FixFibreNetOutput::compute_vector(int i)
{
  if (i == 2) return static_cast<double>(nonfinite_xyz + nonfinite_res);
  return i == 0 ? static_cast<double>(outside_step) : static_cast<double>(outside_count);
}

/* ---------------------------------------------------------------------- */

void FixFibreNetOutput::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  double list[6] = {static_cast<double>(frames_written), static_cast<double>(restart_stage),
                    static_cast<double>(outside_step), static_cast<double>(outside_count),
                    static_cast<double>(nonfinite_xyz), static_cast<double>(nonfinite_res)};
  int size = sizeof(list);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list, sizeof(double), 6, fp);
}

void FixFibreNetOutput::restart(char *buf)
{
  double list[6];
  memcpy(list, buf, sizeof(list));
  frames_written = static_cast<bigint>(list[0]);
  restart_stage = static_cast<float>(list[1]);
  outside_step = static_cast<bigint>(list[2]);
  outside_count = static_cast<bigint>(list[3]);
  nonfinite_xyz = static_cast<bigint>(list[4]);
  nonfinite_res = static_cast<bigint>(list[5]);
}

/* ---------------------------------------------------------------------- */

void FixFibreNetOutput::evaluate(const std::string &name, double *out)
{
  const int ivar = input->variable->find(name.c_str());
  if (ivar < 0) error->all(FLERR, "Fix {} fibrenet/output: variable {} does not exist", id, name);
  if (!input->variable->atomstyle(ivar))
    error->all(FLERR, "Fix {} fibrenet/output: variable {} is not atom-style", id, name);
  // the call dump custom makes for a v_name column: the very same doubles
  input->variable->compute_atom(ivar, igroup, out, 1, 0);
}

// FibreNet's DumpData: the restart file is rewritten at the first frame whose progress
// fraction, computed in float, exceeds restart_dump_stage (0.25, then +0.25 per write), and
// once more after the last step (DumpRestartData(progress) after the loop)
bool FixFibreNetOutput::restart_due(bigint step)
{
  if (restart_steps < 0) return false;
  bool due = false;
  const float fraction = static_cast<float>(step) / static_cast<float>(restart_steps);
  if (fraction > restart_stage) {
    restart_stage += 0.25f;
    due = true;
  }
  return due || step == restart_steps;
}

void FixFibreNetOutput::write_frame()
{
  const int nlocal = atom->nlocal;
  const int nvar = nv - 8;    // per-atom variables: velocity, force [, radius, mass]
  values.resize(nvar * static_cast<size_t>(std::max(nlocal, 1)));
  for (int k = 0; k < 3; k++) {
    evaluate(vel_var[k], &values[k * static_cast<size_t>(nlocal)]);
    evaluate(force_var[k], &values[(3 + k) * static_cast<size_t>(nlocal)]);
  }
  if (nv == NV_DUMP) {
    evaluate(radius_var, &values[6 * static_cast<size_t>(nlocal)]);
    evaluate(mass_var, &values[7 * static_cast<size_t>(nlocal)]);
  }

  int mine = 0;
  for (int i = 0; i < nlocal; i++)
    if (atom->mask[i] & groupbit) mine++;
  send.resize(nv * static_cast<size_t>(std::max(mine, 1)));
  double *s = send.data();
  const tagint *tag = atom->tag;
  const int *type = atom->type;
  const imageint *image = atom->image;
  double **x = atom->x;
  for (int i = 0; i < nlocal; i++) {
    if (!(atom->mask[i] & groupbit)) continue;
    s[0] = static_cast<double>(tag[i]);
    s[1] = type[i];
    s[2] = x[i][0];
    s[3] = x[i][1];
    s[4] = x[i][2];
    // image flags as dump custom's ix iy iz
    s[5] = static_cast<double>((image[i] & IMGMASK) - IMGMAX);
    s[6] = static_cast<double>((image[i] >> IMGBITS & IMGMASK) - IMGMAX);
    s[7] = static_cast<double>((image[i] >> IMG2BITS) - IMGMAX);
    for (int k = 0; k < nvar; k++) s[8 + k] = values[k * static_cast<size_t>(nlocal) + i];
    s += nv;
  }

  // every rank's atoms to rank 0
  const int me = comm->me, nprocs = comm->nprocs;
  if (static_cast<bigint>(mine) * nv > MAXSMALLINT)
    error->one(FLERR, "Fix fibrenet/output: too many atoms on one rank to gather");
  int count = mine * nv;
  std::vector<int> counts(me == 0 ? nprocs : 1), displs(me == 0 ? nprocs : 1);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  bigint total = 0;
  if (me == 0) {
    for (int p = 0; p < nprocs; p++) {
      displs[p] = static_cast<int>(total);
      total += counts[p];
    }
  }
  MPI_Bcast(&total, 1, MPI_LMP_BIGINT, 0, world);
  if (total > MAXSMALLINT)
    error->all(FLERR, "Fix fibrenet/output: too many atoms to gather on one rank");
  if (me == 0) recv.resize(static_cast<size_t>(std::max<bigint>(total, 1)));
  MPI_Gatherv(send.data(), count, MPI_DOUBLE, recv.data(), counts.data(), displs.data(),
              MPI_DOUBLE, 0, world);

  const bigint step = update->ntimestep;
  const bool restart_now = restart_due(step);
  const bigint n = total / nv;
  const int nr = nv + 6;
  if (n * nr > MAXSMALLINT)
    error->all(FLERR, "Fix fibrenet/output: too many atoms to gather on one rank");

  // rank 0: the rows in id order, with their positions, cut into chunks; chunk c is formatted
  // by rank c % nprocs, and the rows go to their ranks (rank 0's own chunks stay in place)
  const bigint nchunks = chunk_count(n);
  bigint kept = 0;
  std::vector<int> row_counts(me == 0 ? nprocs : 1), row_displs(me == 0 ? nprocs : 1);
  if (me == 0) {
    kept = sort_rows(n, step);
    bigint at = 0;
    for (int p = 0; p < nprocs; p++) {
      row_displs[p] = static_cast<int>(at * nr);
      for (bigint c = p; c < nchunks; c += nprocs) at += chunk_size(c, n);
      row_counts[p] = static_cast<int>(at * nr) - row_displs[p];
    }
  }
  bigint my_rows = 0;
  for (bigint c = me; c < nchunks; c += nprocs) my_rows += chunk_size(c, n);
  if (nprocs > 1) {
    if (me == 0) {
      MPI_Scatterv(rows.data(), row_counts.data(), row_displs.data(), MPI_DOUBLE, MPI_IN_PLACE, 0,
                   MPI_DOUBLE, 0, world);
    } else {
      rows.resize(static_cast<size_t>(std::max<bigint>(my_rows * nr, 1)));
      MPI_Scatterv(nullptr, nullptr, nullptr, MPI_DOUBLE, rows.data(),
                   static_cast<int>(my_rows * nr), MPI_DOUBLE, 0, world);
    }
  }

  std::string failure;
  if (me == 0) {
    failure = write_files(n, kept, step, restart_now);
  } else {
    // this rank's chunks, formatted in order; each sent to rank 0 (which writes them in order)
    const double *r = rows.data();
    for (bigint c = me; c < nchunks; c += nprocs) {
      const bigint size = chunk_size(c, n);
      format_rows(r, size, restart_now, text);
      send_text(text);
      r += size * nr;
    }
  }

  // rank 0's outcome to every rank: a failure ends the run everywhere with its message
  int len = static_cast<int>(failure.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, world);
  if (len > 0) {
    failure.resize(len);
    MPI_Bcast(&failure[0], len, MPI_CHAR, 0, world);
    error->all(FLERR, failure);
  }
  bigint outside[4] = {outside_step, outside_count, nonfinite_xyz, nonfinite_res};
  MPI_Bcast(outside, 4, MPI_LMP_BIGINT, 0, world);
  outside_step = outside[0];
  outside_count = outside[1];
  nonfinite_xyz = outside[2];
  nonfinite_res = outside[3];
  frames_written++;
}

// ids 1..n each once (FibreNet's beads; the usual case on several ranks): order[id - 1] = row,
// in one pass instead of a sort; false (order unspecified) for any other set of ids
bool FixFibreNetOutput::place_by_tag(std::vector<bigint> &order) const
{
  const bigint n = static_cast<bigint>(order.size());
  std::fill(order.begin(), order.end(), -1);
  for (bigint k = 0; k < n; k++) {
    const auto id = static_cast<bigint>(recv[k * nv]);
    if (id < 1 || id > n || order[id - 1] >= 0) return false;
    order[id - 1] = k;
  }
  return true;
}

// rank 0: the gathered atoms as rows in id order (as the dump's "modify sort id"), each the
// gathered values and the wrapped and unwrapped position, stored chunk by chunk in the order
// of the ranks that format them (rank 0's chunks first); the wall check; returns how many
// rows the xyz files keep
bigint FixFibreNetOutput::sort_rows(bigint n, bigint step)
{
  std::vector<bigint> order(n);
  std::iota(order.begin(), order.end(), 0);
  bool sorted = true;
  for (bigint k = 1; k < n && sorted; k++) sorted = recv[k * nv] > recv[(k - 1) * nv];
  if (!sorted && !place_by_tag(order)) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [this](bigint a, bigint b) { return recv[a * nv] < recv[b * nv]; });
  }

  // positions as the converter computes them from the dump's x and image flags
  double lo[3], len[3];
  for (int d = 0; d < 3; d++) {
    lo[d] = domain->boxlo[d];
    len[d] = domain->boxhi[d] - domain->boxlo[d];
  }
  const int nr = nv + 6, nprocs = comm->nprocs;
  const bigint nchunks = chunk_count(n);
  rows.resize(static_cast<size_t>(std::max<bigint>(n * nr, 1)));
  bigint pos = 0, kept = 0, outside = 0;
  for (int p = 0; p < nprocs; p++) {
    for (bigint c = p; c < nchunks; c += nprocs) {
      for (bigint k = c * chunk_rows; k < c * chunk_rows + chunk_size(c, n); k++) {
        const double *r = &recv[order[k] * nv];
        double *w = &rows[pos++ * nr];
        std::copy(r, r + nv, w);
        bool out = false;
        for (int d = 0; d < 3; d++) {
          const double u = r[2 + d] + r[5 + d] * len[d];
          w[nv + 3 + d] = u;
          w[nv + d] = domain->periodicity[d] ? lo[d] + py_mod(u - lo[d], len[d]) : r[2 + d];
          if (!domain->periodicity[d] && (w[nv + d] < 0 || w[nv + d] >= box[d])) out = true;
        }
        outside += out;
        kept += in_xyz[static_cast<int>(r[1])];
      }
    }
  }
  // FibreNet drops beads outside [0, L) on a walled axis from its contact grid: the first
  // frame where that happens is reported (to_fibrenet.outside_finite_box)
  if (outside_step < 0 && outside) {
    outside_step = step;
    outside_count = outside;
  }
  return kept;
}

// any rank: the lines of `count` rows in every file of the frame
void FixFibreNetOutput::format_rows(const double *rows_, bigint count, bool restart_now,
                                    FrameText &t) const
{
  const int nr = nv + 6;
  for (auto &s : t.xyz) s.clear();
  t.res.clear();
  t.dump.clear();
  t.bad_xyz = t.bad_res = 0;
  for (int f = 0; f < 3; f++)
    if (files[f]) t.xyz[f].reserve(static_cast<size_t>(count) * 48);
  if (restart_now) t.res.reserve(static_cast<size_t>(count) * 160);
  if (!dump_path.empty()) t.dump.reserve(static_cast<size_t>(count) * 330);
  for (bigint k = 0; k < count; k++) {
    const double *r = rows_ + k * nr;
    const double *wrapped = r + nv, *unwrapped = r + nv + 3;
    const int type = static_cast<int>(r[1]);
    const std::string &name = type_names[type];
    if (in_xyz[type]) {
      for (int f = 0; f < 3; f++) {
        if (!files[f]) continue;
        const double *v = f == COORD ? wrapped : (f == VEL ? r + 8 : r + 11);
        std::string &out = t.xyz[f];
        out += name;
        for (int d = 0; d < 3; d++) {
          out += '\t';
          put_fixed5(out, v[d]);
          t.bad_xyz += !std::isfinite(v[d]);
        }
        out += '\n';
      }
    }
    if (restart_now) {
      t.res += '\t';
      t.res += name;
      for (const double *part : {wrapped, unwrapped, r + 8, r + 11}) {
        for (int d = 0; d < 3; d++) {
          t.res += '\t';
          put_g(t.res, part[d]);
          t.bad_res += !std::isfinite(part[d]);
        }
      }
      t.res += '\n';
    }
    if (!dump_path.empty()) {
      put_int(t.dump, static_cast<bigint>(r[0]));    // id, type
      t.dump += ' ';
      put_int(t.dump, static_cast<bigint>(r[1]));
      for (int j = 2; j < nv; j++) {
        t.dump += ' ';
        if (j >= 5 && j <= 7)
          put_int(t.dump, static_cast<bigint>(r[j]));    // image flags
        else
          put_g17(t.dump, r[j]);
      }
      t.dump += '\n';
    }
  }
}

// a chunk's text to rank 0, and its receipt there (strings in pieces below 2^30 bytes)
void FixFibreNetOutput::send_text(FrameText &t)
{
  std::string *parts[5] = {&t.xyz[0], &t.xyz[1], &t.xyz[2], &t.res, &t.dump};
  bigint head[7];
  for (int k = 0; k < 5; k++) head[k] = static_cast<bigint>(parts[k]->size());
  head[5] = t.bad_xyz;
  head[6] = t.bad_res;
  MPI_Send(head, 7, MPI_LMP_BIGINT, 0, 0, world);
  for (auto *s : parts)
    for (size_t at = 0; at < s->size(); at += TEXT_PIECE)
      MPI_Send(&(*s)[at], static_cast<int>(std::min(TEXT_PIECE, s->size() - at)), MPI_CHAR, 0, 0, world);
}

void FixFibreNetOutput::receive_text(int from, FrameText &t)
{
  std::string *parts[5] = {&t.xyz[0], &t.xyz[1], &t.xyz[2], &t.res, &t.dump};
  bigint head[7];
  MPI_Recv(head, 7, MPI_LMP_BIGINT, from, 0, world, MPI_STATUS_IGNORE);
  for (int k = 0; k < 5; k++) {
    std::string &s = *parts[k];
    s.resize(static_cast<size_t>(head[k]));
    for (size_t at = 0; at < s.size(); at += TEXT_PIECE)
      MPI_Recv(&s[at], static_cast<int>(std::min(TEXT_PIECE, s.size() - at)), MPI_CHAR, from, 0,
               world, MPI_STATUS_IGNORE);
  }
  t.bad_xyz = head[5];
  t.bad_res = head[6];
}

// rank 0: the frame written chunk by chunk (its own chunks formatted here, the others'
// received in order); xyz files and the work dump appended (truncated at this job's first
// frame) and cut back if any write fails, the restart file through a temp file and a rename.
// Every chunk is received even after a failure (the other ranks are sending).  Returns the
// failure message, or "" on success.
std::string FixFibreNetOutput::write_files(bigint n, bigint kept, bigint step, bool restart_now)
{
  const bool first = frames_written == 0;
  const std::string restart_path = prefix + RESTART_SUFFIX;
  if (first && restart_steps >= 0) ::unlink(restart_path.c_str());    // not a stale run's
  std::string failure;
  auto fail = [&failure](const std::string &path, int err) {
    if (failure.empty()) failure = fmt::format("Fix fibrenet/output: cannot write {}: {}", path, reason(err));
  };

  // the files: 0-2 the xyz files, 3 the restart file's temp file, 4 the work dump
  std::string paths[5], heads[5];
  int fds[5] = {-1, -1, -1, -1, -1};
  off_t sizes[5] = {0, 0, 0, 0, 0};
  const std::string xyz_head = frame_head(kept, step, dt, box, put_fixed5);
  for (int f = 0; f < 3; f++)
    if (files[f]) {
      paths[f] = prefix + XYZ_SUFFIX[f];
      heads[f] = xyz_head;
    }
  if (restart_now) {
    const size_t slash = restart_path.rfind('/');
    const std::string folder = slash == std::string::npos ? "" : restart_path.substr(0, slash + 1);
    const std::string name = slash == std::string::npos ? restart_path : restart_path.substr(slash + 1);
    paths[3] = fmt::format("{}.{}.tmp{}", folder, name, static_cast<long>(::getpid()));
    heads[3] = frame_head(n, step, dt, box, put_g);
  }
  if (!dump_path.empty()) {
    paths[4] = dump_path;
    heads[4] = dump_head(n);
  }
  for (int k = 0; k < 5 && failure.empty(); k++) {
    if (paths[k].empty()) continue;
    const bool append = k != 3 && !first;
    fds[k] = ::open(paths[k].c_str(), O_WRONLY | O_CREAT | (append ? O_APPEND : O_TRUNC), 0666);
    if (fds[k] < 0) {
      fail(k == 3 ? restart_path : paths[k], errno);
      break;
    }
    struct stat st;
    if (::fstat(fds[k], &st) == 0) sizes[k] = st.st_size;
  }
  auto put = [&](int k, const std::string &data) {
    if (fds[k] < 0 || !failure.empty()) return;
    const int err = write_all(fds[k], data);
    if (err) fail(k == 3 ? restart_path : paths[k], err);
  };
  for (int k = 0; k < 5; k++) put(k, heads[k]);

  const int nr = nv + 6, nprocs = comm->nprocs;
  const bigint nchunks = chunk_count(n);
  const double *own = rows.data();
  bigint bad_xyz = 0, bad_res = 0;
  for (bigint c = 0; c < nchunks; c++) {
    const int owner = static_cast<int>(c % nprocs);
    if (owner == 0) {
      format_rows(own, chunk_size(c, n), restart_now, text);
      own += chunk_size(c, n) * nr;
    } else {
      receive_text(owner, text);
    }
    for (int f = 0; f < 3; f++) put(f, text.xyz[f]);
    put(3, text.res);
    put(4, text.dump);
    bad_xyz += text.bad_xyz;
    bad_res += text.bad_res;
  }

  for (int k = 0; k < 5; k++)
    if (fds[k] >= 0 && ::close(fds[k]) != 0) fail(k == 3 ? restart_path : paths[k], errno);
  if (failure.empty() && restart_now && ::rename(paths[3].c_str(), restart_path.c_str()) != 0)
    fail(restart_path, errno);
  if (!failure.empty()) {
    if (restart_now) ::unlink(paths[3].c_str());
    for (int k : {0, 1, 2, 4}) {
      if (fds[k] >= 0 && ::truncate(paths[k].c_str(), sizes[k]) != 0) {
        // nothing more to do: the error reported names the file that failed first
      }
    }
    return failure;
  }
  nonfinite_xyz += bad_xyz;
  if (restart_now) nonfinite_res = bad_res;    // the file holds this frame only
  return "";
}

// the work dump's frame header as write_dump custom writes it (Dump::header_item's formats)
std::string FixFibreNetOutput::dump_head(bigint n) const
{
  // Domain::boundary_string's letters: p f s m per face, "xx yy zz"
  std::string bounds;
  for (int d = 0; d < 3; d++) {
    if (d) bounds += ' ';
    for (int side = 0; side < 2; side++) bounds += "pfsm"[domain->boundary[d][side] & 3];
  }
  std::string out = fmt::format("ITEM: TIME\n{:.16}\n", simulation_time(update));
  out += fmt::format("ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\n", update->ntimestep, n);
  out += fmt::format("ITEM: BOX BOUNDS {}\n{:>1.16e} {:>1.16e}\n{:>1.16e} {:>1.16e}\n{:>1.16e} {:>1.16e}\n",
                     bounds, domain->boxlo[0], domain->boxhi[0], domain->boxlo[1], domain->boxhi[1],
                     domain->boxlo[2], domain->boxhi[2]);
  out += "ITEM: ATOMS id type x y z ix iy iz vx vy vz fx fy fz radius mass\n";
  return out;
}

/* ---------------------------------------------------------------------- */

void FibreNetFrame::command(int narg, char **arg)
{
  if (narg != 1) error->all(FLERR, "Illegal fibrenet/frame command: fibrenet/frame <fix ID>");
  auto *fix = dynamic_cast<FixFibreNetOutput *>(modify->get_fix_by_id(arg[0]));
  if (!fix) error->all(FLERR, "fibrenet/frame: {} is not the ID of a fix fibrenet/output", arg[0]);
  if (!domain->box_exist) error->all(FLERR, "fibrenet/frame before the simulation box exists");
  fix->write_frame();
}

// registration with LAMMPS when the plugin loads (style_registry.h); the command makes the fix
// write a frame where the script says
namespace {
Fix *create_fix(LAMMPS *lmp, int narg, char **arg)
{
  return new FixFibreNetOutput(lmp, narg, arg);
}
Command *create_frame(LAMMPS *lmp) { return new FibreNetFrame(lmp); }
const style_registry::Registration registered_fix(
    70, "fibrenet/output", "FibreNet xyz/res output written by LAMMPS", &create_fix);
const style_registry::Registration registered_frame(
    80, "fibrenet/frame", "write a frame of fix fibrenet/output", &create_frame);
}    // namespace
