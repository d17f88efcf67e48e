#include "impactdeck/contact/contact_model.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>

#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::contact {

ContactModel::ContactModel(const PreparedBody& target, const PreparedBody& impactor, collision::ContactRule rule,
                           double effective_modulus_Pa, const collision::RestitutionModel& restitution,
                           const InputContext& ctx)
    : ContactModel(target, impactor, rule, effective_modulus_Pa,
                   std::make_shared<const collision::HertzLaw>(restitution, ctx), ctx) {}

ContactModel::ContactModel(const PreparedBody& target, const PreparedBody& impactor, collision::ContactRule rule,
                           double effective_modulus_Pa, std::shared_ptr<const collision::ContactLaw> law,
                           const InputContext& ctx)
    : target_(target),
      impactor_(impactor),
      target_frame_(target.pose),
      impactor_frame_(impactor.pose),
      rule_(rule),
      law_(std::move(law)),
      impactor_mesh_(impactor.shape ? impactor.shape->triangle_mesh() : nullptr),
      target_centroid_(target.centroid_world_m()),
      impactor_centroid_(impactor.centroid_world_m()) {
  invariants_.target = collision::kernel_body(target.rigid_body(), ctx.at("target '" + target.name + "'"));
  invariants_.impactor = collision::kernel_body(impactor.rigid_body(), ctx.at("impactor '" + impactor.name + "'"));
  invariants_.rule = rule;
  invariants_.effective_modulus_Pa = effective_modulus_Pa;
  invariants_.law = law_.get();
  // The weaker body's yield strength (0: neither has one).
  const double yt = target.yield_strength_Pa.value_or(0.0), yi = impactor.yield_strength_Pa.value_or(0.0);
  invariants_.yield_strength_Pa = yt > 0.0 && yi > 0.0 ? std::min(yt, yi) : std::max(yt, yi);
  if (target.fixed() && impactor.fixed()) {
    throw ctx.error("bodies", "both bodies are fixed (infinite mass): nothing can move");
  }
}

namespace {

// A sharp point's feature into the kernel's surface c (sharp, no curvature); with an edge radius
// rho, rounded: a corner a sphere of radius rho, an edge a cylinder of radius rho along it
// (k = 1/rho across, 0 along), `outward` the body's outward contact normal (world).
void sharp_surface(const geometry::SharpFeature& f, const geometry::PoseMap& frame, std::optional<double> edge_radius_m,
                   const Eigen::Vector3d& outward, collision::ContactCurvature& c) {
  const bool corner = f.kind == geometry::SharpFeature::Kind::corner;
  c.feature = corner ? collision::SharpKind::corner : collision::SharpKind::edge;
  c.feature_angle_rad = corner ? f.apex_half_angle_rad : f.dihedral_angle_rad;
  c.feature_length_m = f.length_m;
  if (!edge_radius_m) return;
  const double k = 1.0 / *edge_radius_m;
  // Along the edge in the tangent plane (any tangent direction at a corner).
  Eigen::Vector3d along = corner ? outward.unitOrthogonal() : frame.direction_to_world(f.direction);
  along -= along.dot(outward) * outward;
  if (!(along.norm() > 1e-6)) return;  // an edge along the normal: no rounding of it touches, stays sharp
  along.normalize();
  c.sharp = false;
  c.d2 = along;
  c.d1 = outward.cross(along).normalized();
  c.k1_per_m = k;
  c.k2_per_m = corner ? k : 0.0;
  c.paper_curvature_per_m = 0.5 * (c.k1_per_m + c.k2_per_m);
}

}  // namespace

void ContactModel::surface(const PreparedBody& b, const geometry::PoseMap& frame, const geometry::SurfacePoint& own,
                           const geometry::Curvature& k, const Eigen::Vector3d& outward,
                           collision::ContactCurvature& c) const {
  if (k.sharp_feature) {  // no curvature exists there: the defaults, flagged sharp, with the feature
    c = collision::ContactCurvature{};
    c.sharp = true;
    geometry::SurfacePoint at = own;
    at.normal = frame.direction_to_own(outward);
    if (const std::optional<geometry::SharpFeature> f = b.shape->sharp_feature(at)) {
      sharp_surface(*f, frame, b.edge_radius_m, outward, c);
    }
    return;
  }
  c.sharp = false;
  c.k1_per_m = k.k1_per_m;
  c.k2_per_m = k.k2_per_m;
  c.d1 = frame.direction_to_world(k.d1);
  c.d2 = frame.direction_to_world(k.d2);
  c.paper_curvature_per_m = 0;
  if (rule_ == collision::ContactRule::paper) {
    // Eq. 26 in the body's own axes; a sphere's radius is its radius; a plane's curvature is 0.
    try {
      c.paper_curvature_per_m = 1.0 / b.shape->paper_radius_m(own);
    } catch (const InputError&) {
      c.paper_curvature_per_m = std::numeric_limits<double>::quiet_NaN();  // kernel: degenerate
    }
  }
}

// One contact point on its way through ContactModel: where it is (set by the caller: the target's
// point, the impactor's touching point, the world point and normal, the impactor's centroid and
// velocity), what evaluate() adds (fitted curvatures, lever arms), and where the results go.
struct ContactModel::PointWork {
  const geometry::SurfacePoint* target_point = nullptr;  ///< target's own frame
  geometry::SurfacePoint impactor_point;                  ///< impactor's own frame
  Eigen::Vector3d point_m, normal, impactor_centroid_m, impactor_velocity_m_s;  ///< world
  Eigen::Vector3d target_lever_arm_m, impactor_lever_arm_m;                     ///< world
  geometry::Curvature target_curvature, impactor_curvature;  ///< own frames, as fitted
  collision::ContactCurvature* target_surface = nullptr;      ///< out: the kernel's surfaces (world)
  collision::ContactCurvature* impactor_surface = nullptr;
  collision::KernelResult* result = nullptr;                  ///< out
  std::string* problem = nullptr;  ///< out, optional: why a curvature fit could not be made
};

bool ContactModel::fit(const PreparedBody& b, const geometry::SurfacePoint& at, geometry::Curvature& k,
                       PointWork& w) const {
  try {
    k = b.shape->curvature(at);
    return true;
  } catch (const InputError& err) {
    // A curvature fit that cannot be made (too few vertices around the point): flagged, so that a
    // sweep goes on and `run` names the reason.
    if (w.problem) *w.problem = (err.place().empty() ? "" : err.place() + ": ") + err.reason();
    *w.result = collision::KernelResult{};
    w.result->flag = collision::ContactFlag::no_curvature;
    return false;
  }
}

void ContactModel::evaluate(PointWork* w, std::size_t n) const {
  // Step by step over the group, as the kernel does: each step's calls for different points are
  // independent, so the processor overlaps their chains.
  assert(n <= collision::kKernelLanes);
  bool fitted[collision::kKernelLanes];
  for (std::size_t k = 0; k < n; ++k) fitted[k] = fit(target_, *w[k].target_point, w[k].target_curvature, w[k]);
  for (std::size_t k = 0; k < n; ++k) {
    fitted[k] = fitted[k] && fit(impactor_, w[k].impactor_point, w[k].impactor_curvature, w[k]);
  }
  collision::KernelPoint points[collision::kKernelLanes];
  collision::KernelResult* results[collision::kKernelLanes];
  std::size_t m = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (!fitted[k]) continue;  // flagged no_curvature: no kernel
    PointWork& x = w[k];
    x.target_lever_arm_m = x.point_m - target_centroid_;
    x.impactor_lever_arm_m = x.point_m - x.impactor_centroid_m;
    surface(target_, target_frame_, *x.target_point, x.target_curvature, x.normal, *x.target_surface);
    surface(impactor_, impactor_frame_, x.impactor_point, x.impactor_curvature, -x.normal, *x.impactor_surface);
    points[m] = {&x.normal,
                 &x.target_lever_arm_m,
                 &x.impactor_lever_arm_m,
                 &invariants_.target.velocity_m_s,
                 &x.impactor_velocity_m_s,
                 x.target_surface,
                 x.impactor_surface};
    results[m++] = x.result;
  }
  collision::solve_kernel(invariants_, points, results, m);
}

void ContactModel::evaluate(ContactEvaluation& e, const Eigen::Vector3d& impactor_centroid_world,
                            std::optional<double> approach_speed_m_s) const {
  PointWork w;
  w.target_point = &e.target_point;
  w.impactor_point = e.impactor_point;
  w.point_m = e.point_m;
  w.normal = e.normal;
  w.impactor_centroid_m = impactor_centroid_world;
  // The paper's sweep setting: the impactor moves along the inward normal at the given speed.
  w.impactor_velocity_m_s =
      approach_speed_m_s ? Eigen::Vector3d(-*approach_speed_m_s * e.normal) : invariants_.impactor.velocity_m_s;
  collision::ContactCurvature target_surface, impactor_surface;
  w.target_surface = &target_surface;
  w.impactor_surface = &impactor_surface;
  w.result = &e.result;
  w.problem = &e.curvature_problem;
  evaluate(&w, 1);
  e.target_curvature = w.target_curvature;
  e.impactor_curvature = w.impactor_curvature;
  if (e.result.flag == collision::ContactFlag::no_curvature) return;  // no fit: no kernel input
  // The kernel's input that the result stands for (reports, the paper's checks).
  collision::KernelInput& in = e.input;
  in = invariants_;
  in.normal = e.normal;
  in.impactor.velocity_m_s = w.impactor_velocity_m_s;
  in.target.lever_arm_m = w.target_lever_arm_m;
  in.impactor.lever_arm_m = w.impactor_lever_arm_m;
  in.target.curvature = target_surface;
  in.impactor.curvature = impactor_surface;
}

void ContactModel::place(const geometry::SurfacePoint& at, geometry::SurfacePoint& impactor_point,
                         Eigen::Vector3d& point_m, Eigen::Vector3d& normal,
                         Eigen::Vector3d& impactor_translation_m) const {
  point_m = target_frame_.to_world(at.point_m);
  normal = target_frame_.direction_to_world(at.normal);
  // The impactor touches with its support point along -n; a plane (unbounded) is laid tangent.
  const Eigen::Vector3d down_own = impactor_frame_.direction_to_own(-normal);
  Eigen::Vector3d touch_world;
  std::optional<geometry::SurfacePoint> support;
  if (impactor_.shape->bounded()) {
    // A mesh touches with its smoothed surface where that is smooth (see first_contact).
    if (impactor_mesh_) support = impactor_mesh_->smooth_support_point(down_own);
    if (!support) support = impactor_.shape->support_point(down_own);
  }
  if (const auto& sp = support) {
    impactor_point = *sp;
    touch_world = impactor_frame_.to_world(sp->point_m);
  } else {
    impactor_point.point_m = impactor_frame_.to_own(point_m);
    impactor_point.normal = down_own;
    touch_world = point_m;
  }
  impactor_translation_m = point_m - touch_world;
}

ContactEvaluation ContactModel::at_surface_point(const geometry::SurfacePoint& at,
                                                 std::optional<double> approach_speed_m_s) const {
  ContactEvaluation e;
  e.target_point = at;
  place(at, e.impactor_point, e.point_m, e.normal, e.impactor_translation_m);
  const Eigen::Vector3d centroid = impactor_centroid_ + e.impactor_translation_m;
  evaluate(e, centroid, approach_speed_m_s);  // in place: no copy of the evaluation per sweep point
  return e;
}

void ContactModel::at_surface_point(const geometry::SurfacePoint& at, double approach_speed_m_s,
                                    ContactPointResult& out) const {
  at_surface_points(&at, 1, approach_speed_m_s, &out);
}

void ContactModel::at_surface_points(const geometry::SurfacePoint* at, std::size_t count, double approach_speed_m_s,
                                     ContactPointResult* out) const {
  PointWork work[collision::kKernelLanes];
  for (std::size_t begin = 0; begin < count; begin += collision::kKernelLanes) {
    const std::size_t n = std::min(collision::kKernelLanes, count - begin);
    for (std::size_t k = 0; k < n; ++k) {
      PointWork& w = work[k];
      w.target_point = &at[begin + k];
      Eigen::Vector3d translation;
      place(*w.target_point, w.impactor_point, w.point_m, w.normal, translation);
      w.impactor_centroid_m = impactor_centroid_ + translation;
      // The paper's sweep setting, as the full evaluation sets it.
      w.impactor_velocity_m_s = -approach_speed_m_s * w.normal;
      w.target_surface = &out[begin + k].target_surface;
      w.impactor_surface = &out[begin + k].impactor_surface;
      w.result = &out[begin + k].result;
      w.problem = nullptr;
    }
    evaluate(work, n);
  }
}

ContactEvaluation ContactModel::at_first_contact(const InputContext& ctx) const {
  const Eigen::Vector3d u = impactor_.velocity_m_s - target_.velocity_m_s;
  if (!(u.norm() > 0.0)) {
    throw ctx.error("", "point = \"first-contact\" needs the bodies to move relative to each other (the "
                        "impactor's velocity equals the target's)");
  }
  contact::PlacedShape t{target_.shape.get(), target_.pose};
  contact::PlacedShape m{impactor_.shape.get(), impactor_.pose};
  const contact::FirstContact fc = contact::first_contact(t, m, u, ctx);
  ContactEvaluation e;
  e.target_point = fc.target_point;
  e.impactor_point = fc.mover_point;
  e.point_m = fc.point_m;
  e.normal = fc.normal;
  e.travel_m = fc.travel_m;
  e.impactor_translation_m = fc.travel_m * u.normalized();
  const Eigen::Vector3d centroid = impactor_centroid_ + e.impactor_translation_m;
  evaluate(e, centroid, std::nullopt);
  return e;
}

}  // namespace impactdeck::contact
