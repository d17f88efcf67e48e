#pragma once
// The Hertz-patch load: instead of the whole force F(t) on the contact node, the Hertz pressure
//     p(u, v, t) = p0(t) sqrt(1 - (u/a(t))^2 - (v/b(t))^2),   p0 = 3 F / (2 pi a b)
// over that instant's contact ellipse, whose semi-axes grow and shrink as F^(1/3) (a = a_max
// (F/F_max)^(1/3), likewise b; Johnson, Contact Mechanics, Sect. 4.2), turned into nodal forces on
// the surface nodes it covers. u runs along the long semi-axis a, v along the short one, both in
// the tangent plane normal to the force direction through the contact point.
//
// Nodal forces at each table time: the work-equivalent ("consistent") loads q_i = int p N_i dA over
// the boundary triangles the ellipse covers (N_i the linear shape function of node i; the integral
// over the triangles projected on the tangent plane, 64 sub-triangles x 3 points each), so the
// corners of the triangles the ellipse's rim cuts carry a share. Then a least-squares correction
// w = q + diag(q) A^T lambda (a linear tilt of the same support) enforces, to round-off,
//     sum_i w_i = F(t)   and   sum_i w_i (x_i - c) x d = 0   (zero moment about the contact point c).
// All forces act along the load direction d. When the ellipse covers too few nodes to carry both
// conditions (early and late in the contact), the whole force goes to the contact node, which is a
// mesh node exactly at c (mesh.hpp), so both still hold.
#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {

/// The contact ellipse of the Hertz solution in the target's frame.
struct ContactPatch {
  /// Unit tangent along the long semi-axis a (collision::RelativeCurvatures::direction_A); any
  /// tangent for a circle. Projected onto the plane normal to the load direction.
  Eigen::Vector3d axis_a = Eigen::Vector3d::UnitX();
  double a_max_m = 0;      ///< long semi-axis at max_force_N
  double b_max_m = 0;      ///< short semi-axis at max_force_N (b <= a)
  double max_force_N = 0;  ///< at force F the semi-axes are scaled by (F / max_force_N)^(1/3)
};

struct PatchLoad {
  std::vector<int> nodes;                     ///< mesh nodes loaded at some time; the contact node first
  std::vector<double> time_s;                 ///< the force table's times
  std::vector<std::vector<double>> force_N;   ///< [node][time]: force along the load direction, N
  double max_sum_relative_error = 0;          ///< max over times with F > 0 of |sum_i w_i - F| / F
  double max_moment_relative = 0;             ///< max over times of |sum (x_i - c) x w_i d| / (F_max a_max)
  std::size_t max_nodes_loaded_at_once = 0;
  std::size_t point_load_samples = 0;         ///< times with F > 0 where everything sat on the contact node
  std::size_t patch_triangles = 0;            ///< boundary triangles the largest ellipse covers
  /// 2 b_max over the mean edge length of those triangles: how many elements the largest ellipse
  /// spans along its short axis.
  double largest_ellipse_elements = 0;
};

/// Nodal forces of the Hertz pressure at every time of `force` (F >= 0, N) on the boundary of
/// `mesh`, centred on node `contact_node`, along the unit `direction` of the force on the body.
/// Only boundary triangles reachable from the contact node across edges, facing against the
/// force (outward normal . direction < -0.5), are loaded. Throws InputError for a degenerate patch
/// (a_max < b_max, non-positive sizes, no boundary triangle at the contact node) or more than 9999
/// loaded nodes: ctx.error("hertz-patch load", reason), `ctx` naming the deck it is for.
PatchLoad hertz_patch_load(const TetMesh& mesh, int contact_node, const Eigen::Vector3d& direction,
                           const ContactPatch& patch, const collision::ForceTable& force,
                           const InputContext& ctx = {});

}  // namespace impactdeck::fem_export
