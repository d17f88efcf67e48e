#pragma once
// The paper's Eq. 26 radius from a curvature tensor: shared by the shapes whose surface is known
// through its principal curvatures at a point (MeshShape: jet fit; CadShape: the B-rep).
#include <Eigen/Dense>

#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

/// Mean radius of the sections of the surface by the three axis-normal planes through the point
/// (Eq. 26). The section by the plane with unit normal e has, at the point, tangent t = n×e/|n×e|
/// and curvature κ = κ_n(t) / |n×e| (Meusnier), κ_n(t) = k1 (t·d1)² + k2 (t·d2)² (Euler). Cuts
/// with |n×e| <= `tangent_cut` are left out (degenerate). Throws InputError("", "point", ...) when
/// no cut is left.
double paper_radius_from_curvature(const Curvature& c, const Eigen::Vector3d& normal, double tangent_cut);

}  // namespace impactdeck::geometry
