#pragma once
// The geometric half of an impact: where two placed bodies touch, and the physics kernel's
// input built from both surfaces there. `run`, `sweep` and `study` all go through ContactModel, so
// that one contact point gives bit for bit the same numbers whatever command asks for it.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/kernel.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/contact/body.hpp"
#include "impactdeck/contact/first_contact.hpp"
#include "impactdeck/geometry/pose.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {
class MeshShape;
}

namespace impactdeck::contact {

/// Everything about one contact point: where it is on both bodies, both surfaces' curvature there,
/// the kernel's input and its result.
struct ContactEvaluation {
  geometry::SurfacePoint target_point;    ///< target's own frame (point, outward normal)
  geometry::SurfacePoint impactor_point;  ///< impactor's own frame
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< world
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< world, target's outward unit normal
  /// World translation of the impactor from its scene placement to the contact (point mode: the
  /// placement that makes it touch; first contact: travel along the relative velocity).
  Eigen::Vector3d impactor_translation_m = Eigen::Vector3d::Zero();
  double travel_m = 0;                    ///< first contact: distance travelled
  geometry::Curvature target_curvature;   ///< own frames, as fitted (error estimates kept)
  geometry::Curvature impactor_curvature;
  /// Why a curvature could not be estimated (result.flag no_curvature), e.g. a coarse mesh.
  std::string curvature_problem;
  collision::KernelInput input;
  collision::KernelResult result;
};

/// What a sweep keeps of one contact point (ContactModel::at_surface_point's lean form, filled in
/// place): both surfaces as the kernel saw them (world frame) and the kernel's result. The full
/// ContactEvaluation adds the points, the fitted curvatures with their error estimates and the
/// kernel's input, for `run`.
struct ContactPointResult {
  collision::ContactCurvature target_surface, impactor_surface;
  collision::KernelResult result;
};

/// One impact's invariants: both bodies, the rule, E*, the contact law and the kernel bodies
/// (inverse mass, world inverse inertia: computed once). Keeps references to the bodies: they must
/// outlive it; shares the law.
class ContactModel {
 public:
  /// Throws ctx.error(...) for invalid masses or inertias (place "target 'NAME': mass", ...) and
  /// when both bodies are fixed (place "bodies"); `ctx` names the impact (a scene's file and place).
  /// The law gets the yield strength of the weaker body (0 when neither has one).
  ContactModel(const PreparedBody& target, const PreparedBody& impactor, collision::ContactRule rule,
               double effective_modulus_Pa, std::shared_ptr<const collision::ContactLaw> law,
               const InputContext& ctx = {});
  /// Hertz with `restitution` (collision::HertzLaw; its errors name ctx's "restitution").
  ContactModel(const PreparedBody& target, const PreparedBody& impactor, collision::ContactRule rule,
               double effective_modulus_Pa, const collision::RestitutionModel& restitution,
               const InputContext& ctx = {});

  /// Point mode (and sweeps): the target is hit at its surface point `at` (own frame, with its
  /// outward normal). The impactor keeps its orientation and is translated so that its support
  /// point along -n touches there. With `approach_speed_m_s`, the impactor's velocity is replaced
  /// by -speed n and the target taken at rest (the paper's sweep setting). Never throws: a point
  /// where the model does not apply comes back flagged (result.flag).
  ContactEvaluation at_surface_point(const geometry::SurfacePoint& at,
                                     std::optional<double> approach_speed_m_s = std::nullopt) const;
  /// The same point, the same code and the same numbers, keeping only what a sweep needs: fills
  /// `out` in place (no ContactEvaluation, no copy of the kernel bodies per point).
  void at_surface_point(const geometry::SurfacePoint& at, double approach_speed_m_s, ContactPointResult& out) const;
  /// The same for `count` points (a sweep's group): out[k] is at_surface_point(at[k], speed, out[k])
  /// bit for bit, with the kernel's steps run over up to collision::kKernelLanes points at a time so
  /// that the points' dependency chains overlap.
  void at_surface_points(const geometry::SurfacePoint* at, std::size_t count, double approach_speed_m_s,
                         ContactPointResult* out) const;

  /// First-contact mode: the impactor, as placed, translates along the relative velocity of the
  /// bodies until they touch (contact::first_contact). Throws ctx.error("", reason) when they
  /// never touch, already overlap, or do not move relative to each other.
  ContactEvaluation at_first_contact(const InputContext& ctx = {}) const;

  const PreparedBody& target() const { return target_; }
  /// The target's pose as the model applies it (the identity rotation skipped).
  const geometry::PoseMap& target_frame() const { return target_frame_; }
  const PreparedBody& impactor() const { return impactor_; }
  collision::ContactRule rule() const { return rule_; }
  const std::shared_ptr<const collision::ContactLaw>& law() const { return law_; }

 private:
  /// Point mode's placement: the impactor's touching point (own frame), the world point and normal,
  /// and the impactor's translation.
  void place(const geometry::SurfacePoint& at, geometry::SurfacePoint& impactor_point, Eigen::Vector3d& point_m,
             Eigen::Vector3d& normal, Eigen::Vector3d& impactor_translation_m) const;
  struct PointWork;  // one point's placement, geometry and result slots (contact.cpp)
  /// One body's curvature at its point into k; a fit that cannot be made flags w's result
  /// no_curvature (reason in w.problem when given) and returns false.
  bool fit(const PreparedBody& b, const geometry::SurfacePoint& at, geometry::Curvature& k, PointWork& w) const;
  /// The per-point work of every mode, on a group of at most collision::kKernelLanes placed points:
  /// both surfaces' curvatures, the kernel's surfaces (world) and lever arms, then the kernel
  /// (collision::solve_kernel's grouped form).
  void evaluate(PointWork* work, std::size_t count) const;
  /// The full evaluation: one point through evaluate() into e, and e.input the kernel's input it
  /// stands for.
  void evaluate(ContactEvaluation& e, const Eigen::Vector3d& impactor_centroid_world_m,
                std::optional<double> approach_speed_m_s) const;
  /// The kernel's view of a body's surface at `own` (world directions, the rule's Eq. 26
  /// curvature), written into `c` (every field); `outward` is the body's outward contact normal
  /// (world). A sharp point carries its feature (Shape::sharp_feature), rounded by the body's
  /// edge_radius_m when it has one.
  void surface(const PreparedBody& b, const geometry::PoseMap& frame, const geometry::SurfacePoint& own,
               const geometry::Curvature& k, const Eigen::Vector3d& outward, collision::ContactCurvature& c) const;

  const PreparedBody& target_;
  const PreparedBody& impactor_;
  geometry::PoseMap target_frame_, impactor_frame_;  ///< both poses, unrotated ones skipped
  collision::ContactRule rule_;
  std::shared_ptr<const collision::ContactLaw> law_;  ///< invariants_.law points to it
  /// The kernel's invariants: both kernel bodies (inverse mass and world inverse inertia, computed
  /// once; velocities), the rule, E* and the law. Its per-point fields are unused.
  collision::KernelInput invariants_;
  const geometry::MeshShape* impactor_mesh_;  ///< the impactor as a mesh (smooth support point), or null
  Eigen::Vector3d target_centroid_, impactor_centroid_;  ///< world, as placed
};

}  // namespace impactdeck::contact
