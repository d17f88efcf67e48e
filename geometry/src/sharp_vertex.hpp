#pragma once
// What a vertex where sharp edges meet is at a contact (docs/sharp-contacts.md, "Classification"):
// one rule for a mesh's vertex (MeshShape) and a B-rep's (CadShape). Private to geometry/src.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry::detail {

struct SharpVertex {
  enum class Kind {
    none,    ///< a flat contact (two edges of a face lie on the other body), or a dihedral unknown
    edge,    ///< the contact is edge `edge` (one lies in the tangent plane, or one straight edge)
    corner,  ///< `feature` is the corner
  } kind = Kind::none;
  std::size_t edge = 0;
  SharpFeature feature;
};

/// `away[i]`: the unit direction from the vertex `point_m` along its sharp edge i; `n`: the
/// contact's outward normal of the body (zero: unknown); `dihedral(i)`: edge i's interior dihedral
/// angle through the solid (nullopt: unknown). An edge within kSharpRunDeg of the tangent plane is
/// the contact (two of them, not one straight edge: a flat contact); a single edge, or two forming
/// one straight edge, is an edge; else a corner of solid angle 2 pi + sum (dihedral - pi).
template <class Dihedral>
SharpVertex classify_sharp_vertex(const Eigen::Vector3d& point_m, const std::vector<Eigen::Vector3d>& away,
                                  const Eigen::Vector3d& n, Dihedral&& dihedral) {
  const double cos_run = std::cos(kSharpRunDeg * M_PI / 180.0), sin_plane = std::sin(kSharpRunDeg * M_PI / 180.0);
  SharpVertex r;
  std::optional<std::size_t> in_plane;
  int in_plane_count = 0;
  if (!n.isZero()) {
    for (std::size_t i = 0; i < away.size(); ++i) {
      if (std::abs(away[i].dot(n)) > sin_plane) continue;
      if (!in_plane || away[i].dot(away[*in_plane]) > -cos_run) ++in_plane_count;
      in_plane = i;
    }
  }
  if (in_plane_count > 1) return r;
  if (in_plane) {
    r.kind = SharpVertex::Kind::edge;
    r.edge = *in_plane;
    return r;
  }
  if (away.size() == 1 || (away.size() == 2 && away[0].dot(away[1]) <= -cos_run)) {
    r.kind = SharpVertex::Kind::edge;
    return r;
  }
  double omega = 2.0 * M_PI;
  for (std::size_t i = 0; i < away.size(); ++i) {
    const std::optional<double> d = dihedral(i);
    if (!d) return r;
    omega += *d - M_PI;
  }
  r.kind = SharpVertex::Kind::corner;
  r.feature.kind = SharpFeature::Kind::corner;
  r.feature.point_m = point_m;
  r.feature.solid_angle_sr = omega;
  r.feature.apex_half_angle_rad = std::acos(std::clamp(1.0 - omega / (2.0 * M_PI), -1.0, 1.0));
  return r;
}

}  // namespace impactdeck::geometry::detail
