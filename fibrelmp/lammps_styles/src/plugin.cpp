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

#include "style_registry.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <tuple>
#include <vector>

#ifndef FIBRELMP_LAMMPS_NUM_VER
#error "build with -DFIBRELMP_LAMMPS_NUM_VER=<lammps num_ver> (fibrelmp/lammps_styles/build.py does)"
#endif
#ifndef FIBRELMP_STYLES_ID
#define FIBRELMP_STYLES_ID "unknown"
#endif

using namespace LAMMPS_NS;

namespace LAMMPS_NS {
namespace style_registry {

namespace {
// a function-local list: the styles' registration objects run during static initialisation
std::vector<Style> &registry()
{
  static std::vector<Style> styles;
  return styles;
}
}    // namespace

void add(const Style &style)
{
  registry().push_back(style);
}

std::vector<Style> sorted()
{
  std::vector<Style> styles = registry();
  std::stable_sort(styles.begin(), styles.end(), [](const Style &a, const Style &b) {
    return std::make_tuple(a.order, std::string(a.kind), std::string(a.name)) <
        std::make_tuple(b.order, std::string(b.kind), std::string(b.name));
  });
  return styles;
}

}    // namespace style_registry
}    // namespace LAMMPS_NS

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
  // every style compiled in registered itself (style_registry.h); the FIBRELMP_CORE_ONLY build
  // of the version-check tests compiles only this file and fix_musen_history.cpp
  for (const style_registry::Style &style : style_registry::sorted()) {
    lammpsplugin_t plugin;
    plugin.version = lmp->version;    // checked above, not by the string
    plugin.style = style.kind;
    plugin.name = style.name;
    plugin.info = style.info;
    plugin.author = "fibrelmp developers";
    if (style.v1)
      plugin.creator.v1 = style.v1;
    else
      plugin.creator.v2 = style.v2;
    plugin.handle = handle;
    (*reg)(&plugin, lmp);
  }
}
