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

find_package(Threads REQUIRED)

if(IMPACTDECK_CORE_ONLY)
  return()  # common + collision need Eigen and GSL only
endif()

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

# cairo renders the pictures (SVG is written by our own code, PNG by cairo's image surface).
find_package(PkgConfig QUIET)
impactdeck_require(PKG_CONFIG_FOUND "pkg-config" pkgconf)
pkg_check_modules(Cairo QUIET IMPORTED_TARGET cairo)
impactdeck_require(Cairo_FOUND "cairo" libcairo2-dev)
# zlib: the compressed blocks of the sweeps' VTK files (study/src/vtk_xml.cpp).
find_package(ZLIB QUIET)
impactdeck_require(ZLIB_FOUND "zlib" zlib1g-dev)
# nettle: the SHA-256 of the input files on the report page.
pkg_check_modules(Nettle QUIET IMPORTED_TARGET nettle)
impactdeck_require(Nettle_FOUND "nettle" nettle-dev)

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

# Gmsh (C++ API, Debian libgmsh-dev): fem_export meshes with it; only fem_export/src sees gmsh.h.
find_path(IMPACTDECK_GMSH_INCLUDE gmsh.h)
find_library(IMPACTDECK_GMSH_LIBRARY gmsh)
impactdeck_require(IMPACTDECK_GMSH_LIBRARY "the Gmsh library" libgmsh-dev)
impactdeck_require(IMPACTDECK_GMSH_INCLUDE "the Gmsh C++ API header gmsh.h" libgmsh-dev)
if(NOT TARGET impactdeck_gmsh)
  add_library(impactdeck_gmsh INTERFACE)
  target_include_directories(impactdeck_gmsh SYSTEM INTERFACE ${IMPACTDECK_GMSH_INCLUDE})
  target_link_libraries(impactdeck_gmsh INTERFACE ${IMPACTDECK_GMSH_LIBRARY})
endif()

# OpenCASCADE (Debian libocct-data-exchange-dev, libocct-modeling-algorithms-dev): the CAD plugin
# uses its readers and its adaptive mass properties directly (geometry/src/cad_occ.cpp); the same
# shared libraries Gmsh is built on.
find_path(IMPACTDECK_OCCT_INCLUDE BRepGProp.hxx PATH_SUFFIXES opencascade)
impactdeck_require(IMPACTDECK_OCCT_INCLUDE "the OpenCASCADE headers" libocct-modeling-algorithms-dev)
set(IMPACTDECK_OCCT_LIBRARIES)
foreach(lib TKSTEP TKIGES TKXSBase TKTopAlgo TKGeomBase TKBRep TKG3d TKMath TKernel)
  find_library(IMPACTDECK_OCCT_${lib} ${lib})
  impactdeck_require(IMPACTDECK_OCCT_${lib} "the OpenCASCADE library ${lib}" libocct-data-exchange-dev)
  list(APPEND IMPACTDECK_OCCT_LIBRARIES ${IMPACTDECK_OCCT_${lib}})
endforeach()
if(NOT TARGET impactdeck_occt)
  add_library(impactdeck_occt INTERFACE)
  target_include_directories(impactdeck_occt SYSTEM INTERFACE ${IMPACTDECK_OCCT_INCLUDE})
  target_link_libraries(impactdeck_occt INTERFACE ${IMPACTDECK_OCCT_LIBRARIES})
endif()

# MED (libmedc, Debian libmedc-dev): the mesh format Code_Aster reads. Debian's med.h defines
# MED_HAVE_MPI and includes hdf5.h, so it needs the OpenMPI and parallel-HDF5 include folders.
find_path(IMPACTDECK_MED_INCLUDE med.h)
find_library(IMPACTDECK_MED_LIBRARY medC)
impactdeck_require(IMPACTDECK_MED_LIBRARY "the MED library (libmedC)" libmedc-dev)
impactdeck_require(IMPACTDECK_MED_INCLUDE "the MED header med.h" libmedc-dev)
find_path(IMPACTDECK_MPI_INCLUDE mpi.h PATHS /usr/lib/x86_64-linux-gnu/openmpi/include
          /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/openmpi/include /usr/include/openmpi)
impactdeck_require(IMPACTDECK_MPI_INCLUDE "MPI headers for med.h" libopenmpi-dev)
find_path(IMPACTDECK_HDF5_INCLUDE hdf5.h PATHS /usr/include/hdf5/openmpi NO_DEFAULT_PATH)
find_path(IMPACTDECK_HDF5_INCLUDE hdf5.h PATH_SUFFIXES hdf5/openmpi)
impactdeck_require(IMPACTDECK_HDF5_INCLUDE "parallel HDF5 headers for med.h" libhdf5-openmpi-dev)
if(NOT TARGET impactdeck_med)
  add_library(impactdeck_med INTERFACE)
  target_include_directories(impactdeck_med SYSTEM INTERFACE ${IMPACTDECK_MED_INCLUDE}
                             ${IMPACTDECK_HDF5_INCLUDE} ${IMPACTDECK_MPI_INCLUDE})
  target_link_libraries(impactdeck_med INTERFACE ${IMPACTDECK_MED_LIBRARY})
endif()

# Programs the tests run: ccx (calculix-ccx) for the decks, gmsh (gmsh) for the .geo, mdump
# (libmed-tools) to read the MED file back. A missing one makes its tests fail with the package name.
find_program(IMPACTDECK_CCX ccx)
find_program(IMPACTDECK_GMSH_EXE gmsh)
find_program(IMPACTDECK_MDUMP NAMES mdump mdump4 mdump3)
