/* fibrelmp's LAMMPS styles: registration with a running LAMMPS (`plugin load`).
   Part of fibrelmp; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   The styles derive from LAMMPS's public base classes (Pair, Bond, Angle, Fix) whose layout is
   fixed by the headers of the LAMMPS release they were compiled against.  Loaded into another
   release, a layout change would corrupt memory silently, so nothing is registered unless the
   running LAMMPS is the one the build saw (FIBRELMP_LAMMPS_NUM_VER, set by build.py). */

#include "lammpsplugin.h"

#include "error.h"
#include "lammps.h"
#include "utils.h"

#include <cstring>
#include <string>

#include "fix_musen_history.h"

// FIBRELMP_CORE_ONLY: the registration and the history fix alone (tests of the version check)
#ifndef FIBRELMP_CORE_ONLY
#if __has_include("pair_musen_hm.h")
#include "pair_musen_hm.h"
#define HAVE_PAIR_MUSEN_HM
#endif
#if __has_include("pair_musen_linear.h")
#include "pair_musen_linear.h"
#define HAVE_PAIR_MUSEN_LINEAR
#endif
#if __has_include("bond_musen_elastic.h")
#include "bond_musen_elastic.h"
#define HAVE_BOND_MUSEN_ELASTIC
#endif
#if __has_include("fix_musen_wall_mesh.h")
#include "fix_musen_wall_mesh.h"
#define HAVE_FIX_MUSEN_WALL_MESH
#endif
#if __has_include("angle_fibrenet.h")
#include "angle_fibrenet.h"
#define HAVE_ANGLE_FIBRENET
#endif
#if __has_include("fix_fibrenet_output.h")
#include "fix_fibrenet_output.h"
#define HAVE_FIX_FIBRENET_OUTPUT
#endif
#endif

#ifndef FIBRELMP_LAMMPS_NUM_VER
#error "build with -DFIBRELMP_LAMMPS_NUM_VER=<lammps num_ver> (fibrelmp/lammps_styles/build.py does)"
#endif
#ifndef FIBRELMP_STYLES_ID
#define FIBRELMP_STYLES_ID "unknown"
#endif

using namespace LAMMPS_NS;

namespace {

// one creator per style (LAMMPS calls them through the C plugin interface)
Fix *fix_musen_history_creator(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenHistory(lmp, narg, arg);
}
#ifdef HAVE_PAIR_MUSEN_HM
Pair *pair_musen_hm_creator(LAMMPS *lmp) { return new PairMusenHM(lmp); }
#endif
#ifdef HAVE_PAIR_MUSEN_LINEAR
Pair *pair_musen_linear_creator(LAMMPS *lmp) { return new PairMusenLinear(lmp); }
#endif
#ifdef HAVE_BOND_MUSEN_ELASTIC
Bond *bond_musen_elastic_creator(LAMMPS *lmp) { return new BondMusenElastic(lmp); }
#endif
#ifdef HAVE_FIX_MUSEN_WALL_MESH
Fix *fix_musen_wall_mesh_creator(LAMMPS *lmp, int narg, char **arg)
{
  return new FixMusenWallMesh(lmp, narg, arg);
}
#endif
#ifdef HAVE_ANGLE_FIBRENET
Angle *angle_fibrenet_creator(LAMMPS *lmp) { return new AngleFibreNet(lmp); }
#endif
#ifdef HAVE_FIX_FIBRENET_OUTPUT
Fix *fix_fibrenet_output_creator(LAMMPS *lmp, int narg, char **arg)
{
  return new FixFibreNetOutput(lmp, narg, arg);
}
Command *fibrenet_frame_creator(LAMMPS *lmp) { return new FibreNetFrame(lmp); }
#endif

void add(lammpsplugin_regfunc reg, void *lmp, void *handle, const char *style, const char *name,
         const char *info, lammpsplugin_factory1 *v1, lammpsplugin_factory2 *v2)
{
  lammpsplugin_t plugin;
  plugin.version = static_cast<LAMMPS *>(lmp)->version;    // checked below, not by the string
  plugin.style = style;
  plugin.name = name;
  plugin.info = info;
  plugin.author = "fibrelmp developers";
  if (v1)
    plugin.creator.v1 = v1;
  else
    plugin.creator.v2 = v2;
  plugin.handle = handle;
  (*reg)(&plugin, lmp);
}

}    // namespace

extern "C" void lammpsplugin_init(void *ptr, void *handle, void *regfunc)
{
  auto *lmp = static_cast<LAMMPS *>(ptr);
  auto reg = reinterpret_cast<lammpsplugin_regfunc>(regfunc);
  if (lmp->num_ver != FIBRELMP_LAMMPS_NUM_VER) {
    // error->all would unwind through dlopen's caller; a warning and no styles is safe, and the
    // first use of a style then fails with LAMMPS's "Unrecognized ... style" after this text
    lmp->error->warning(FLERR,
                        "fibrelmp styles (build {}) were compiled for LAMMPS version {} but this "
                        "is LAMMPS {} ({}): none registered; rebuild them against this LAMMPS "
                        "(docs/cluster.md)",
                        FIBRELMP_STYLES_ID, FIBRELMP_LAMMPS_NUM_VER, lmp->num_ver, lmp->version);
    return;
  }
  // per-atom history of the MUSEN styles (created by them, not by input scripts)
  add(reg, lmp, handle, "fix", "MUSEN/HISTORY", "per-atom contact/bond history of fibrelmp styles",
      nullptr, (lammpsplugin_factory2 *) &fix_musen_history_creator);
#ifdef HAVE_PAIR_MUSEN_HM
  add(reg, lmp, handle, "pair", "musen/hm", "MUSEN Hertz-Mindlin particle-particle contact",
      (lammpsplugin_factory1 *) &pair_musen_hm_creator, nullptr);
#endif
#ifdef HAVE_PAIR_MUSEN_LINEAR
  add(reg, lmp, handle, "pair", "musen/linear", "MUSEN linear elastic particle-particle contact",
      (lammpsplugin_factory1 *) &pair_musen_linear_creator, nullptr);
#endif
#ifdef HAVE_BOND_MUSEN_ELASTIC
  add(reg, lmp, handle, "bond", "musen/elastic", "MUSEN elastic/Kelvin solid bond with breakage",
      (lammpsplugin_factory1 *) &bond_musen_elastic_creator, nullptr);
#endif
#ifdef HAVE_FIX_MUSEN_WALL_MESH
  add(reg, lmp, handle, "fix", "musen/wall/mesh", "MUSEN particle-wall contact with triangle walls",
      nullptr, (lammpsplugin_factory2 *) &fix_musen_wall_mesh_creator);
#endif
#ifdef HAVE_ANGLE_FIBRENET
  add(reg, lmp, handle, "angle", "fibrenet", "FibreNet bending law",
      (lammpsplugin_factory1 *) &angle_fibrenet_creator, nullptr);
#endif
#ifdef HAVE_FIX_FIBRENET_OUTPUT
  add(reg, lmp, handle, "fix", "fibrenet/output", "FibreNet xyz/res output written by LAMMPS",
      nullptr, (lammpsplugin_factory2 *) &fix_fibrenet_output_creator);
  // the command that makes fix fibrenet/output write a frame (where the script says)
  add(reg, lmp, handle, "command", "fibrenet/frame", "write a frame of fix fibrenet/output",
      (lammpsplugin_factory1 *) &fibrenet_frame_creator, nullptr);
#endif
}
