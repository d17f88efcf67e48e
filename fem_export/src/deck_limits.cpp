// Bounded work for the FEM decks: the element count is estimated before Gmsh runs (decks.hpp).
#include <cmath>

#include "impactdeck/fem_export/decks.hpp"

namespace impactdeck::fem_export {

namespace {
// Tetrahedra per h^3 of volume in Gmsh 4.8.4's meshes of the decks (MeshAdapt surface, Delaunay
// volume, the load-point size field), measured: the paper's ellipsoid 2000/500/500 mm at h = 400,
// 250, 150, 100, 60, 40 mm gave 3.9, 5.0, 5.3, 5.0, 4.7, 4.6 times V/h^3 (plus the refinement
// term); the mesh part ellipsoid_200x50x50.stl at h = 30, 15, 8 mm gave 4.0, 4.8, 4.7
// (docs/reliability.md). Regular tetrahedra of edge h would give 8.5.
constexpr double kTetsPerCubicSize = 5.0;
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
