#pragma once
// A body made ready for impacts: shape, placement, mass, inertia, material and rigid-body state.
// Built by the scene (scene::prepare_body) or without one (body_of_mass: the study presets).
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Dense>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/kernel.hpp"
#include "impactdeck/geometry/pose.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::contact {

/// A body made ready for impacts: its shape in its own frame, its placement and its rigid-body
/// state (velocities in the world frame).
struct PreparedBody {
  std::string name;
  std::shared_ptr<const geometry::Shape> shape;
  geometry::Pose pose;             ///< own frame -> world
  geometry::VolumeProperties volume;  ///< own frame, unit density
  double mass_kg = 0;              ///< +infinity when fixed
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  ///< own frame, about the centroid
  collision::ElasticMaterial material;
  std::optional<double> yield_strength_Pa;
  /// The part's edge break (m): a sharp corner is a sphere of this radius, a sharp edge a cylinder
  /// (ContactModel; docs/sharp-contacts.md). Unset: sharp points stay sharp.
  std::optional<double> edge_radius_m;
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();            ///< world
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  ///< world

  bool fixed() const;
  Eigen::Vector3d centroid_world_m() const { return pose.to_world(volume.centroid_m); }
  /// R I R^T (identity for a fixed body: never used, its inverse mass is 0).
  Eigen::Matrix3d inertia_world_kg_m2() const;
  /// The rigid-body state in the world frame (collision::RigidBody).
  collision::RigidBody rigid_body() const;
};

/// A free body made without a scene: `shape` at rest at the origin of the world, with total mass
/// `mass_kg` (+infinity: fixed) spread uniformly (inertia scaled from the shape's unit-density
/// inertia). Throws InputError when the shape has no volume and the mass is finite.
PreparedBody body_of_mass(std::string name, std::shared_ptr<const geometry::Shape> shape, double mass_kg,
                          const collision::ElasticMaterial& material = {});

}  // namespace impactdeck::contact
