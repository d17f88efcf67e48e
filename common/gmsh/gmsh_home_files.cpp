// Gmsh without FLTK's preference files and Gmsh's ~/.gmsh-tmp (gmsh_home_files.hpp says why).
#include "gmsh_home_files.hpp"

#include <gmsh.h>

// FLTK 1.3's class Fl as far as its two Fl::option functions go (the same mangled names:
// _ZN2Fl6optionENS_9Fl_OptionE, _ZN2Fl6optionENS_9Fl_OptionEb). FLTK's own reads its preference
// files on the first call and writes them back; these keep the options in memory.
class Fl {
 public:
  enum Fl_Option { kOptionCount = 16 };  // FLTK 1.3.8 has 9 (OPTION_LAST); the rest is room
  static bool option(Fl_Option opt);
  static void option(Fl_Option opt, bool value);
};

namespace {
bool fltk_options[Fl::kOptionCount] = {};
}  // namespace

__attribute__((visibility("default"))) bool Fl::option(Fl_Option opt) {
  return opt >= 0 && opt < kOptionCount && fltk_options[opt];
}

__attribute__((visibility("default"))) void Fl::option(Fl_Option opt, bool value) {
  if (opt >= 0 && opt < kOptionCount) fltk_options[opt] = value;
}

namespace impactdeck {

void initialize_gmsh_without_home_files() {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setString("General.TmpFileName", "");
}

}  // namespace impactdeck
