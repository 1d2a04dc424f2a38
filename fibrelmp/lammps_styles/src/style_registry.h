/* -*- c++ -*- ----------------------------------------------------------
   fibrelmp's LAMMPS styles; GPL-2.0-or-later like LAMMPS (see ../LICENSE).

   Every style (pair, bond, angle, fix, command) registers itself from its own .cpp with one
   static object, so a new style is one .cpp/.h pair and nothing else to edit:

     namespace {
     Pair *create(LAMMPS *lmp) { return new PairMusenHM(lmp); }
     const style_registry::Registration registered(
         20, "musen/hm", "MUSEN Hertz-Mindlin particle-particle contact", &create);
     }

   lammpsplugin_init (plugin.cpp) hands the list to LAMMPS sorted by the first number (then
   kind and name): static initialisation order across .cpp files is unspecified, and the order
   decides the "Loading plugin: INFO by ..." lines of log.lammps.  A new style takes any
   unused number; the info text is what log.lammps shows.
------------------------------------------------------------------------- */

#ifndef FIBRELMP_STYLE_REGISTRY_H
#define FIBRELMP_STYLE_REGISTRY_H

#include "lammpsplugin.h"

#include <vector>

namespace LAMMPS_NS {
class LAMMPS;
class Pair;
class Bond;
class Angle;
class Fix;
class Command;

namespace style_registry {

struct Style {
  int order;                    // position in the registration (log.lammps) order
  const char *kind;             // LAMMPS's plugin style: "pair", "bond", "angle", "fix", "command"
  const char *name;             // the style name input scripts use
  const char *info;             // LAMMPS prints it when the plugin loads
  lammpsplugin_factory1 *v1;    // creator of pair, bond, angle, command styles (else nullptr)
  lammpsplugin_factory2 *v2;    // creator of fix styles (else nullptr)
};

void add(const Style &style);
std::vector<Style> sorted();    // the registered styles in registration order

// the LAMMPS plugin style of a creator's base class: the kind follows from the creator's
// type, so a registration cannot name one kind and create another
template <class Base> constexpr const char *kind_of() = delete;
template <> constexpr const char *kind_of<Pair>() { return "pair"; }
template <> constexpr const char *kind_of<Bond>() { return "bond"; }
template <> constexpr const char *kind_of<Angle>() { return "angle"; }
template <> constexpr const char *kind_of<Command>() { return "command"; }

// a style's static registration object; the creators return the LAMMPS base class, as
// LAMMPS's plugin loader casts them back to exactly these signatures (a base without a
// kind_of does not compile)
class Registration {
 public:
  template <class Base>
  Registration(int order, const char *name, const char *info, Base *(*create)(LAMMPS *))
  {
    add({order, kind_of<Base>(), name, info, (lammpsplugin_factory1 *) create, nullptr});
  }
  Registration(int order, const char *name, const char *info,
               Fix *(*create)(LAMMPS *, int, char **))
  {
    add({order, "fix", name, info, nullptr, (lammpsplugin_factory2 *) create});
  }
};

}    // namespace style_registry
}    // namespace LAMMPS_NS

#endif
