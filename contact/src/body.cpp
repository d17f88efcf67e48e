#include "impactdeck/contact/body.hpp"

#include <cmath>
#include <utility>

namespace impactdeck::contact {

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

}  // namespace impactdeck::contact
