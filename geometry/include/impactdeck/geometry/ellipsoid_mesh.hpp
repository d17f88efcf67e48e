#pragma once
// Analytic test parts: a subdivided icosahedron mapped onto an ellipsoid.
#include "impactdeck/geometry/triangle_mesh.hpp"

namespace impactdeck::geometry {

/// Icosahedron subdivided `subdivisions` times (20·4^N triangles, 10·4^N + 2 vertices), every
/// vertex normalised onto the unit sphere and then scaled by diag(a, b, c): all vertices lie
/// exactly (to round-off) on x²/a² + y²/b² + z²/c² = 1; outward orientation. Semi-axes in metres
/// (or any unit: the mesh carries no unit). InputError for non-positive axes or N outside 0..10.
TriangleMesh make_ellipsoid_mesh(double a, double b, double c, int subdivisions);

/// The unit cube [0,1]^3 as 12 outward triangles.
TriangleMesh make_unit_cube_mesh();

/// Applies x -> R x + t to every vertex.
void transform_mesh(TriangleMesh& mesh, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& t);

}  // namespace impactdeck::geometry
