// Bounded work for the FEM decks: the element count is estimated before Gmsh runs (decks.hpp).
#include <cmath>

#include "impactdeck/fem_export/decks.hpp"

namespace impactdeck::fem_export {

namespace {
// Tetrahedra per h^3 of volume in Gmsh 4.8.4's Delaunay meshes at a uniform target size h,
// measured on the decks' ellipsoids and mesh parts (docs/reliability.md). A regular tetrahedron
// of edge h holds h^3 / (6 sqrt 2), i.e. 8.5 per h^3; Gmsh's elements are smaller on average.
constexpr double kTetsPerCubicSize = 11.0;
}  // namespace

double estimate_tet_count(double volume_m3, double mesh_size_m, double load_mesh_size_m) {
  const double h = mesh_size_m;
  const double h0 = std::min(load_mesh_size_m > 0 ? load_mesh_size_m : h / 3.0, h);
  if (!(volume_m3 > 0) || !(h > 0)) return 0;
  // The size field (gmsh_mesh.cpp): h(r) = h0 + (h - h0) min(1, r / 4h) around the load point on
  // the surface; the refined half-ball adds (1/h(r)^3 - 1/h^3) elements per unit volume.
  const double R = 4.0 * h;
  double extra = 0;
  const int steps = 256;
  for (int i = 0; i < steps; ++i) {
    const double r = (i + 0.5) * R / steps;
    const double hr = h0 + (h - h0) * r / R;
    extra += 2.0 * M_PI * r * r * (1.0 / (hr * hr * hr) - 1.0 / (h * h * h)) * (R / steps);
  }
  // The refined region cannot hold more than the body.
  extra = std::min(extra, volume_m3 / (h0 * h0 * h0));
  return kTetsPerCubicSize * (volume_m3 / (h * h * h) + extra);
}

}  // namespace impactdeck::fem_export
