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

// per gathered atom: tag type x y z ix iy iz v0 v1 v2 f0 f1 f2
constexpr int NV = 14;
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

// "%g" (6 significant digits, FibreNet's default ostream precision); nan as "nan"
void put_g(std::string &out, double x)
{
  if (std::isnan(x)) {
    out += "nan";
    return;
  }
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", x);
  out += buf;
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
    Fix(lmp, narg, arg), dt(0.0), restart_steps(-1), frames_written(0), restart_stage(0.25f),
    outside_step(-1), outside_count(0)
{
  const std::string usage =
      "fix ID group fibrenet/output PREFIX dt DT box LX LY LZ names N1 .. Nntypes "
      "[files coord vel force] [only T ...|none] velocity v_x v_y v_z force v_x v_y v_z "
      "restart N|no";
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
    } else {
      error->all(FLERR, "Fix fibrenet/output: unknown keyword {}; usage: {}", key, usage);
    }
  }
  if (!have_dt || !have_box || !have_names || !have_vel || !have_force || !have_restart)
    error->all(FLERR, "Fix fibrenet/output needs dt, box, names, velocity, force and restart; "
                      "usage: {}", usage);

  restart_global = 1;
  vector_flag = 1;
  size_vector = 2;
  global_freq = 1;
  extvector = 0;
}

int FixFibreNetOutput::setmask()
{
  return 0;    // nothing per step: frames are written by the fibrenet/frame command
}

double FixFibreNetOutput::compute_vector(int i)
{
  return i == 0 ? static_cast<double>(outside_step) : static_cast<double>(outside_count);
}

/* ---------------------------------------------------------------------- */

void FixFibreNetOutput::write_restart(FILE *fp)
{
  if (comm->me != 0) return;
  double list[4] = {static_cast<double>(frames_written), static_cast<double>(restart_stage),
                    static_cast<double>(outside_step), static_cast<double>(outside_count)};
  int size = sizeof(list);
  fwrite(&size, sizeof(int), 1, fp);
  fwrite(list, sizeof(double), 4, fp);
}

void FixFibreNetOutput::restart(char *buf)
{
  double list[4];
  memcpy(list, buf, sizeof(list));
  frames_written = static_cast<bigint>(list[0]);
  restart_stage = static_cast<float>(list[1]);
  outside_step = static_cast<bigint>(list[2]);
  outside_count = static_cast<bigint>(list[3]);
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
  values.resize(6 * static_cast<size_t>(std::max(nlocal, 1)));
  for (int k = 0; k < 3; k++) {
    evaluate(vel_var[k], &values[k * static_cast<size_t>(nlocal)]);
    evaluate(force_var[k], &values[(3 + k) * static_cast<size_t>(nlocal)]);
  }

  int mine = 0;
  for (int i = 0; i < nlocal; i++)
    if (atom->mask[i] & groupbit) mine++;
  send.resize(NV * static_cast<size_t>(std::max(mine, 1)));
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
    for (int k = 0; k < 6; k++) s[8 + k] = values[k * static_cast<size_t>(nlocal) + i];
    s += NV;
  }

  // every rank's atoms to rank 0
  const int me = comm->me, nprocs = comm->nprocs;
  if (static_cast<bigint>(mine) * NV > MAXSMALLINT)
    error->one(FLERR, "Fix fibrenet/output: too many atoms on one rank to gather");
  int count = mine * NV;
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
  std::string failure;
  if (me == 0) failure = write_files(recv, total / NV, step, restart_now);

  // rank 0's outcome to every rank: a failure ends the run everywhere with its message
  int len = static_cast<int>(failure.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, world);
  if (len > 0) {
    failure.resize(len);
    MPI_Bcast(&failure[0], len, MPI_CHAR, 0, world);
    error->all(FLERR, failure);
  }
  bigint outside[2] = {outside_step, outside_count};
  MPI_Bcast(outside, 2, MPI_LMP_BIGINT, 0, world);
  outside_step = outside[0];
  outside_count = outside[1];
  frames_written++;
}

// rank 0: format and write the frame; the failure message, or "" on success
std::string FixFibreNetOutput::write_files(const std::vector<double> &rec, bigint n, bigint step,
                                           bool restart_now)
{
  // atoms in id order, as the dump's "modify sort id"
  std::vector<bigint> order(n);
  std::iota(order.begin(), order.end(), 0);
  bool sorted = true;
  for (bigint k = 1; k < n && sorted; k++) sorted = rec[k * NV] > rec[(k - 1) * NV];
  if (!sorted)
    std::sort(order.begin(), order.end(),
              [&rec](bigint a, bigint b) { return rec[a * NV] < rec[b * NV]; });

  // positions as the converter computes them from the dump's x and image flags
  double lo[3], len[3];
  for (int d = 0; d < 3; d++) {
    lo[d] = domain->boxlo[d];
    len[d] = domain->boxhi[d] - domain->boxlo[d];
  }
  std::vector<double> wrapped(3 * n), unwrapped(3 * n);
  for (bigint k = 0; k < n; k++) {
    const double *r = &rec[order[k] * NV];
    for (int d = 0; d < 3; d++) {
      const double u = r[2 + d] + r[5 + d] * len[d];
      unwrapped[3 * k + d] = u;
      wrapped[3 * k + d] = domain->periodicity[d] ? lo[d] + py_mod(u - lo[d], len[d]) : r[2 + d];
    }
  }

  // FibreNet drops beads outside [0, L) on a walled axis from its contact grid: the first
  // frame where that happens is reported (to_fibrenet.outside_finite_box)
  if (outside_step < 0) {
    bigint outside = 0;
    for (bigint k = 0; k < n; k++) {
      bool out = false;
      for (int d = 0; d < 3; d++)
        if (!domain->periodicity[d]) {
          const double w = wrapped[3 * k + d];
          if (w < 0 || w >= box[d]) out = true;
        }
      outside += out;
    }
    if (outside) {
      outside_step = step;
      outside_count = outside;
    }
  }

  std::string body[3];
  bool any = files[COORD] || files[VEL] || files[FORCE];
  if (any) {
    bigint kept = 0;
    for (bigint k = 0; k < n; k++) kept += in_xyz[static_cast<int>(rec[order[k] * NV + 1])];
    std::string head;
    put_int(head, kept);
    head += "\nFRAME\t";
    put_int(head, step);
    for (double v : {dt, box[0], box[1], box[2]}) {
      head += '\t';
      put_fixed5(head, v);
    }
    head += '\n';
    for (int f = 0; f < 3; f++) {
      if (!files[f]) continue;
      std::string &out = body[f];
      out.reserve(head.size() + static_cast<size_t>(kept) * 48);
      out = head;
      for (bigint k = 0; k < n; k++) {
        const double *r = &rec[order[k] * NV];
        const int t = static_cast<int>(r[1]);
        if (!in_xyz[t]) continue;
        const double *v = f == COORD ? &wrapped[3 * k] : (f == VEL ? r + 8 : r + 11);
        out += type_names[t];
        for (int d = 0; d < 3; d++) {
          out += '\t';
          put_fixed5(out, v[d]);
        }
        out += '\n';
      }
    }
  }

  std::string res;
  if (restart_now) {
    put_int(res, n);
    res += "\nFRAME\t";
    put_int(res, step);
    for (double v : {dt, box[0], box[1], box[2]}) {
      res += '\t';
      put_g(res, v);
    }
    res += '\n';
    for (bigint k = 0; k < n; k++) {
      const double *r = &rec[order[k] * NV];
      res += '\t';
      res += type_names[static_cast<int>(r[1])];
      for (int d = 0; d < 3; d++) {
        res += '\t';
        put_g(res, wrapped[3 * k + d]);
      }
      for (int d = 0; d < 3; d++) {
        res += '\t';
        put_g(res, unwrapped[3 * k + d]);
      }
      for (int j = 8; j < 14; j++) {
        res += '\t';
        put_g(res, r[j]);
      }
      res += '\n';
    }
  }

  // ---- the files: xyz appended (truncated at this job's first frame), every write cut back
  // when any part of the frame fails; the restart file through a temp file and a rename
  const bool first = frames_written == 0;
  const std::string restart_path = prefix + RESTART_SUFFIX;
  if (first && restart_steps >= 0) ::unlink(restart_path.c_str());    // not a stale run's
  struct Written {
    std::string path;
    off_t size;
  };
  std::vector<Written> done;
  auto undo = [&done]() {
    for (const auto &w : done) {
      if (::truncate(w.path.c_str(), w.size) != 0) {
        // nothing more to do: the error reported names the file that failed first
      }
    }
  };
  for (int f = 0; f < 3; f++) {
    if (!files[f]) continue;
    const std::string path = prefix + XYZ_SUFFIX[f];
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | (first ? O_TRUNC : O_APPEND), 0666);
    if (fd < 0) {
      const int err = errno;
      undo();
      return fmt::format("Fix fibrenet/output: cannot write {}: {}", path, reason(err));
    }
    struct stat st;
    off_t size = 0;
    if (::fstat(fd, &st) == 0) size = st.st_size;
    done.push_back({path, size});
    int err = write_all(fd, body[f]);
    if (::close(fd) != 0 && !err) err = errno;
    if (err) {
      undo();
      return fmt::format("Fix fibrenet/output: cannot write {}: {}", path, reason(err));
    }
  }
  if (restart_now) {
    const size_t slash = restart_path.rfind('/');
    const std::string folder = slash == std::string::npos ? "" : restart_path.substr(0, slash + 1);
    const std::string name = slash == std::string::npos ? restart_path : restart_path.substr(slash + 1);
    const std::string tmp = fmt::format("{}.{}.tmp{}", folder, name, static_cast<long>(::getpid()));
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);
    int err = fd < 0 ? errno : write_all(fd, res);
    if (fd >= 0 && ::close(fd) != 0 && !err) err = errno;
    if (!err && ::rename(tmp.c_str(), restart_path.c_str()) != 0) err = errno;
    if (err) {
      ::unlink(tmp.c_str());
      undo();
      return fmt::format("Fix fibrenet/output: cannot write {}: {}", restart_path, reason(err));
    }
  }
  return "";
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
