#include "impactdeck/scene/contact.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::scene {

bool PreparedBody::fixed() const { return std::isinf(mass_kg); }

Eigen::Matrix3d PreparedBody::inertia_world_kg_m2() const {
  if (fixed()) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d& R = pose.rotation;
  const Eigen::Matrix3d I = R * inertia_kg_m2 * R.transpose();
  return 0.5 * (I + I.transpose());
}

collision::RigidBody PreparedBody::rigid_body() const {
  collision::RigidBody r;
  r.mass_kg = mass_kg;
  r.inertia_kg_m2 = inertia_world_kg_m2();
  r.center_of_mass_m = centroid_world_m();
  r.velocity_m_s = velocity_m_s;
  r.angular_velocity_rad_s = angular_velocity_rad_s;
  return r;
}

PreparedBody body_of_mass(std::string name, std::shared_ptr<const geometry::Shape> shape, double mass_kg,
                          const collision::ElasticMaterial& material) {
  PreparedBody b;
  b.name = std::move(name);
  b.shape = std::move(shape);
  b.volume = b.shape->volume_properties();
  b.material = material;
  b.mass_kg = mass_kg;
  if (std::isinf(mass_kg)) {
    b.inertia_kg_m2 = Eigen::Matrix3d::Identity() * mass_kg;
    return b;
  }
  if (!(b.volume.volume_m3 > 0.0)) throw InputError("", "body '" + b.name + "'", "has no volume");
  b.inertia_kg_m2 = b.volume.inertia_per_density_m5 * (mass_kg / b.volume.volume_m3);
  return b;
}

ContactModel::ContactModel(const PreparedBody& target, const PreparedBody& impactor, collision::ContactRule rule,
                           double effective_modulus_Pa, const collision::RestitutionModel& restitution,
                           const InputContext& ctx)
    : target_(target),
      impactor_(impactor),
      rule_(rule),
      effective_modulus_Pa_(effective_modulus_Pa),
      restitution_(restitution),
      target_body_(collision::kernel_body(target.rigid_body(), ctx.at("target '" + target.name + "'"))),
      impactor_body_(collision::kernel_body(impactor.rigid_body(), ctx.at("impactor '" + impactor.name + "'"))),
      impactor_mesh_(dynamic_cast<const geometry::MeshShape*>(impactor.shape.get())),
      target_centroid_(target.centroid_world_m()),
      impactor_centroid_(impactor.centroid_world_m()) {
  if (target.fixed() && impactor.fixed()) {
    throw ctx.error("bodies", "both bodies are fixed (infinite mass): nothing can move");
  }
}

collision::ContactCurvature ContactModel::surface(const PreparedBody& b, const geometry::SurfacePoint& own,
                                                  const geometry::Curvature& k) const {
  collision::ContactCurvature c;
  c.sharp = k.sharp_feature;
  if (c.sharp) return c;
  c.k1_per_m = k.k1_per_m;
  c.k2_per_m = k.k2_per_m;
  c.d1 = b.pose.direction_to_world(k.d1);
  c.d2 = b.pose.direction_to_world(k.d2);
  if (rule_ == collision::ContactRule::paper) {
    // Eq. 26 in the body's own axes; a sphere's radius is its radius; a plane's curvature is 0.
    try {
      c.paper_curvature_per_m = 1.0 / b.shape->paper_radius_m(own);
    } catch (const InputError&) {
      c.paper_curvature_per_m = std::numeric_limits<double>::quiet_NaN();  // kernel: degenerate
    }
  }
  return c;
}

void ContactModel::evaluate(ContactEvaluation& e, const Eigen::Vector3d& impactor_centroid_world,
                            std::optional<double> approach_speed_m_s) const {
  collision::KernelInput& in = e.input;
  try {
    e.target_curvature = target_.shape->curvature(e.target_point);
    e.impactor_curvature = impactor_.shape->curvature(e.impactor_point);
  } catch (const InputError& err) {
    // A curvature fit that cannot be made (too few vertices around the point): flagged, so that a
    // sweep goes on and `run` names the reason.
    e.curvature_problem = (err.place().empty() ? "" : err.place() + ": ") + err.reason();
    e.result.flag = collision::ContactFlag::no_curvature;
    return;
  }
  in.target = target_body_;
  in.impactor = impactor_body_;
  in.target.lever_arm_m = e.point_m - target_centroid_;
  in.impactor.lever_arm_m = e.point_m - impactor_centroid_world;
  in.target.curvature = surface(target_, e.target_point, e.target_curvature);
  in.impactor.curvature = surface(impactor_, e.impactor_point, e.impactor_curvature);
  in.normal = e.normal;
  in.rule = rule_;
  in.effective_modulus_Pa = effective_modulus_Pa_;
  in.restitution = &restitution_;
  // The paper's sweep setting: the impactor moves along the inward normal at the given speed.
  if (approach_speed_m_s) in.impactor.velocity_m_s = -*approach_speed_m_s * e.normal;
  e.result = collision::solve_kernel(in);
}

ContactEvaluation ContactModel::at_surface_point(const geometry::SurfacePoint& at,
                                                 std::optional<double> approach_speed_m_s) const {
  ContactEvaluation e;
  e.target_point = at;
  e.point_m = target_.pose.to_world(at.point_m);
  e.normal = target_.pose.direction_to_world(at.normal);
  // The impactor touches with its support point along -n; a plane (unbounded) is laid tangent.
  const Eigen::Vector3d down_own = impactor_.pose.direction_to_own(-e.normal);
  const Eigen::Vector3d& placed_centroid = impactor_centroid_;
  Eigen::Vector3d touch_world;
  std::optional<geometry::SurfacePoint> support;
  if (impactor_.shape->bounded()) {
    // A mesh touches with its smoothed surface where that is smooth (see first_contact).
    if (impactor_mesh_) support = impactor_mesh_->smooth_support_point(down_own);
    if (!support) support = impactor_.shape->support_point(down_own);
  }
  if (const auto& sp = support) {
    e.impactor_point = *sp;
    touch_world = impactor_.pose.to_world(sp->point_m);
  } else {
    e.impactor_point.point_m = impactor_.pose.to_own(e.point_m);
    e.impactor_point.normal = down_own;
    touch_world = e.point_m;
  }
  e.impactor_translation_m = e.point_m - touch_world;
  const Eigen::Vector3d centroid = placed_centroid + e.impactor_translation_m;
  evaluate(e, centroid, approach_speed_m_s);  // in place: no copy of the evaluation per sweep point
  return e;
}

ContactEvaluation ContactModel::at_first_contact(const InputContext& ctx) const {
  const Eigen::Vector3d u = impactor_.velocity_m_s - target_.velocity_m_s;
  if (!(u.norm() > 0.0)) {
    throw ctx.error("", "point = \"first-contact\" needs the bodies to move relative to each other (the "
                        "impactor's velocity equals the target's)");
  }
  geometry::PlacedShape t{target_.shape.get(), target_.pose};
  geometry::PlacedShape m{impactor_.shape.get(), impactor_.pose};
  const geometry::FirstContact fc = geometry::first_contact(t, m, u, ctx);
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

}  // namespace impactdeck::scene
