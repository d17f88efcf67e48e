# One place per third-party dependency: each missing package stops configuration with one clear
# message naming the Debian package that provides it (scripts/deps installs them all).
include_guard(GLOBAL)

function(impactdeck_require found what debian_package)
  if(NOT ${found})
    message(FATAL_ERROR "impactdeck needs ${what}: install the Debian package '${debian_package}' "
                        "(scripts/deps installs every dependency).")
  endif()
endfunction()

find_package(Eigen3 3.3 NO_MODULE QUIET)
impactdeck_require(Eigen3_FOUND "Eigen 3" libeigen3-dev)

find_package(GSL QUIET)
impactdeck_require(GSL_FOUND "GSL" libgsl-dev)

# toml++ is used header-only: Debian's package config declares a compiled library it does not ship.
find_path(IMPACTDECK_TOMLPP_INCLUDE toml++/toml.h)
impactdeck_require(IMPACTDECK_TOMLPP_INCLUDE "toml++" libtomlplusplus-dev)
if(NOT TARGET impactdeck_tomlplusplus)
  add_library(impactdeck_tomlplusplus INTERFACE)
  target_include_directories(impactdeck_tomlplusplus SYSTEM INTERFACE ${IMPACTDECK_TOMLPP_INCLUDE})
  target_compile_definitions(impactdeck_tomlplusplus INTERFACE TOML_HEADER_ONLY=1 TOML_EXCEPTIONS=1)
endif()

find_package(nlohmann_json 3 QUIET)
impactdeck_require(nlohmann_json_FOUND "nlohmann-json" nlohmann-json3-dev)

find_package(CLI11 QUIET)
impactdeck_require(CLI11_FOUND "CLI11" libcli11-dev)

find_package(Threads REQUIRED)

# cairo renders the pictures (SVG is written by our own code, PNG by cairo's image surface).
find_package(PkgConfig QUIET)
impactdeck_require(PKG_CONFIG_FOUND "pkg-config" pkgconf)
pkg_check_modules(Cairo QUIET IMPORTED_TARGET cairo)
impactdeck_require(Cairo_FOUND "cairo" libcairo2-dev)

# The tests parse the written SVG / VTP files back with tinyxml2.
if(IMPACTDECK_BUILD_TESTS)
  find_package(tinyxml2 CONFIG QUIET)
  impactdeck_require(tinyxml2_FOUND "tinyxml2 (tests only)" libtinyxml2-dev)
endif()

# Geometry front end: assimp reads the part files, CGAL (header-only, GPL packages Polygon Mesh
# Processing and Jet fitting) validates and queries them. CGAL is linked PRIVATE to
# impactdeck::geometry only: no public header includes it.
find_package(assimp QUIET)
impactdeck_require(assimp_FOUND "assimp" libassimp-dev)

find_package(CGAL 5.0 QUIET)
impactdeck_require(CGAL_FOUND "CGAL" libcgal-dev)
