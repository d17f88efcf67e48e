#pragma once
// Gmsh started so that it touches no file outside the run's folders (issue 43 item 6; built into
// both Gmsh plugins, libimpactdeck_gmsh_mesher.so and libimpactdeck_gmsh_cad.so, never into a
// library that is linked without Gmsh).
//
// Debian's libgmsh is built with FLTK. gmsh::initialize sets the option General.Tooltips, which
// calls FLTK's Fl::option; its first call reads FLTK's preference files and writes them back
// (/etc/fltk/fltk.org/fltk.prefs and ~/.fltk/fltk.org/fltk.prefs, creating the folders), seen in
// the system calls of every meshing run. Each plugin defines Fl::option itself (gmsh_home_files.cpp):
// a dlopen'ed plugin comes before its own dependencies in their symbol lookup, so libgmsh (and
// libfltk) call this one, which keeps the options in memory and reads or writes no file. No GUI
// runs in impactdeck.
//
// gmsh::finalize removes $HOME + General.TmpFileName (default ~/.gmsh-tmp, a file of Gmsh's GUI):
// with General.TmpFileName = "" it names $HOME/ itself, which unlink(2) cannot remove.
namespace impactdeck {

/// gmsh::initialize(0, nullptr, false) (no configuration files read) and General.TmpFileName = "".
void initialize_gmsh_without_home_files();

}  // namespace impactdeck
