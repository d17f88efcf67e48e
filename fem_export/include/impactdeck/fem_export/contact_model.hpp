#pragma once
// The full-contact model of an impact, for CalculiX: both bodies meshed with quadratic tetrahedra
// (C3D10) refined around the contact point, surface-to-surface penalty contact between them, the
// bodies' translations and spins as initial velocities, implicit dynamics through the contact and
// past the separation. It is what the hybrid deck (decks.hpp) replaces by the analytic Hertz force:
// `impactdeck compare-contact` runs both and compares them (docs/contact-vs-hybrid.md).
//
// Frame: the deck's coordinates are the world's, translated so that the contact point is the
// origin (mm in the deck; SI in every struct here). Each body is meshed in its own frame by the
// Gmsh plugin (mesh.hpp, with the contact point as the load point, so a node lies on it exactly),
// then placed by its pose.
//
// Quadratic elements: the plugin's linear tetrahedra get a node at the middle of every edge; on an
// analytic body (ellipsoid, sphere) the middle nodes of boundary edges are moved onto the exact
// surface, so that the contact surface is curved as the body is (a faceted surface concentrates the
// curvature on its edges, and the contact patch spans only a few elements). Mesh parts keep straight
// edges (their surface is faceted anyway).
//
// Penalty (PRESSURE-OVERCLOSURE=LINEAR): slope K = penalty_factor * E* / h_c (N/m^3), h_c the
// contact element size. The overclosure at the peak pressure p0 is p0 / K; Hertz gives
// p0 = 2 E* a / (pi R) and x_max = a^2 / R, so overclosure / x_max = 2 h_c / (pi penalty_factor a):
// 1 % for a / h_c = 3 and the default factor 20, which softens the contact and lowers F_max by
// roughly 0.6 of that (F ~ x^(3/2), the penalty layer in series).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/stress.hpp"

namespace impactdeck::fem_export {

/// One body of the contact model.
struct ContactBody {
  std::string name;  ///< named in messages and the deck
  DeckBody body;     ///< shape in its own frame (ellipsoid / part / cad)
  DeckMaterial material;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< own frame -> world
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();    ///< world position of the own origin
  Eigen::Vector3d contact_point_own_m = Eigen::Vector3d::Zero();  ///< on its surface, own frame
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();           ///< world, of its centroid
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  ///< world
  Eigen::Vector3d centroid_own_m = Eigen::Vector3d::Zero();  ///< the spin's centre (exact body)
  double far_mesh_size_m = 0;  ///< element size away from the contact
  /// Stress probes (own frame; the target's [outputs.fem] probes): embedded nodes PROBE1, ...
  /// whose von Mises history ccx writes (`*EL FILE, NSET=`), as the hybrid deck's.
  std::vector<Eigen::Vector3d> probes_own_m;
  /// The yield strength of a MaterialModel::plastic material (its *PLASTIC card starts there).
  double yield_strength_Pa = 0;
  /// Set: the body is fixed (a floor or a fixed body: infinite mass). Its nodes at least this deep
  /// under the contact point (along the inward normal) are held by *BOUNDARY, or, when the body is
  /// shallower than this, those deeper than half its depth. A plane floor is given as a block
  /// (floor_block) whose bottom face lies exactly at this depth. It starts at rest.
  std::optional<double> support_depth_m;
};

/// The block that models a plane floor (or any fixed half-space) under a contact: a square box with
/// its top face through `contact_point_m` normal to `outward_normal`, half-width and depth
/// `size_m`, triangulated outward (12 triangles) in the frame of the point. Its bottom face lies at
/// depth size_m: give the body support_depth_m = kFloorSupportDepthFraction * size_m.
PartSurface floor_block(const Eigen::Vector3d& contact_point_m, const Eigen::Vector3d& outward_normal, double size_m);
/// Just under 1, so that the bottom face's nodes (at depth size_m, to rounding) are held.
inline constexpr double kFloorSupportDepthFraction = 1.0 - 1e-6;

struct ContactModelOptions {
  /// The smaller Hertz contact semi-axis at F_max spans this many elements (h_c = b / this).
  double contact_elements = 3;
  /// The element size stays h_c within this many larger semi-axes a of the contact point.
  double refined_zone_factor = 2.0;
  /// Contact surfaces: boundary faces within this many larger semi-axes of the contact point
  /// (at least 4 h_c); the rest of the surface never touches.
  double surface_zone_factor = 4.0;
  double penalty_factor = 20;  ///< K = penalty_factor E* / h_c (see above)
  /// A plane floor becomes a block of half-width and depth this many contact radii (the larger
  /// semi-axis a; docs/contact-vs-hybrid.md, "A floor": its compliance misses the half-space's
  /// by about 0.4 a / size of the approach, 1 % at 40).
  double floor_block_factor = 40;
  /// Largest step: the analytic (elastic) contact duration 2 t_m / this (ccx may cut it back).
  int contact_increments = 40;
  double end_time_factor = 1.3;  ///< simulated time: this times 2 t_m (past the separation)
  /// *DYNAMIC, SOLVER=ITERATIVE SCALING; false: SPOOLES. Measured on two spheres, 6,882 nodes, 22
  /// increments: 49 s against 225 s, the same force to 4 digits.
  bool iterative_solver = true;
  /// The quasi-static route (the plastic comparison; see "Quasi-static" below): static steps of
  /// prescribed approach instead of the dynamic step, each load and unload in this many increments.
  bool quasi_static = false;
  int static_increments = 16;
};

// Quasi-static: ccx 2.20 does not run a dynamic contact deck with *PLASTIC (it dies in incplas,
// docs/contact-vs-hybrid.md), but it runs the static one. The contact laws are quasi-static
// themselves (the contact time is many wave transits of the bodies), so the reference is the FE
// contact's force-approach curve with the impact's mass on it:
//   - each body is held or driven by its nodes beyond half its depth along the contact normal (a
//     fixed body by its support as above); the driven one (the free body, or the impactor of two
//     free bodies) is pushed toward the other by the approach d, then brought back to d = 0;
//   - run `load` (load.inp) goes to probe_approach_m and back; the approach d_max where its loading
//     work reaches 1/2 m* V^2 (m* the impact's effective mass along the normal, V the normal
//     approach speed) is found on its curve (probe_approach_m doubled, twice at most, when the
//     work falls short);
//   - run `impact` (impact.inp, written after `load`) goes to d_max and back: F_max is its force at
//     d_max, the restitution sqrt(unloading work / loading work), the residual approach where the
//     unloading force vanishes, each body's dent from its contact node; F(t) and the contact
//     time come from m* d'' = -F(d) on the two curves (impact_on_curves).

struct ContactModelRequest {
  std::string source, impact;
  ContactBody target, impactor;
  Eigen::Vector3d contact_point_m = Eigen::Vector3d::Zero();  ///< world
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< world, the target's outward normal
  double effective_modulus_Pa = 0;                    ///< E* (with the Poisson terms)
  /// The analytic Hertz impact (elastic): contact semi-axes at F_max (a >= b) and t_m.
  double semi_axis_a_m = 0, semi_axis_b_m = 0;
  double compression_time_s = 0;
  /// The contact duration the time steps are cut from; 0: 2 t_m (elastic). A plastic law's t_c.
  double contact_duration_s = 0;
  ContactModelOptions options;
  /// Quasi-static route: m*, V and the first run's approach (a generous guess: the laws' largest
  /// x_max times 1.5).
  double effective_mass_kg = 0, approach_speed_m_s = 0, probe_approach_m = 0;
  /// Where the request comes from (a scene's impact): its errors name it, then the deck folder.
  /// Empty: the deck folder alone.
  InputContext context;
};

struct ContactBodyMesh {
  std::size_t node_count = 0, element_count = 0, contact_faces = 0;
  double contact_mesh_size_m = 0, far_mesh_size_m = 0;
  double fe_mass_kg = 0;
  Eigen::Vector3d fe_centroid_m = Eigen::Vector3d::Zero();  ///< deck frame
  Eigen::Matrix3d fe_inertia_kg_m2 = Eigen::Matrix3d::Zero();  ///< world axes, about the centroid
  std::size_t first_node = 0;  ///< 0-based: this body's nodes in the deck are [first, first + count)
  std::size_t contact_node = 0;  ///< 0-based, body-local: the node on the contact point
  std::size_t fixed_nodes = 0;   ///< nodes held by *BOUNDARY (a fixed body), else 0
  bool plastic = false;          ///< *PLASTIC material
};

struct ContactDeck {
  std::filesystem::path folder;
  ContactBodyMesh target, impactor;
  std::size_t node_count = 0;
  double contact_mesh_size_m = 0, penalty_N_m3 = 0;
  double time_step_s = 0, end_time_s = 0;
  std::size_t increments = 0;
  double mesh_seconds = 0;
  nlohmann::json description;  ///< contact.json's contents, as written
};

/// Meshes both bodies and writes `folder`/impact.inp (+ contact.json with what the reader needs),
/// staged in a hidden sibling folder renamed at the end. Throws InputError on bad input or a
/// meshing failure.
ContactDeck write_contact_deck(const ContactModelRequest& request, const std::filesystem::path& folder);

/// A body's motion after the contact, from the FE velocities (rigid part of the field).
struct ContactBodyMotion {
  Eigen::Vector3d delta_velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_angular_velocity_rad_s = Eigen::Vector3d::Zero();
  double kinetic_energy_J = 0, strain_energy_J = 0;  ///< ccx's ELKE and ELSE totals at the end
  double rigid_kinetic_energy_J = 0;                  ///< 1/2 P^2 / M + 1/2 L . I^-1 L at the end
  double vibration_energy_J = 0;                      ///< kinetic + strain - rigid
  /// The permanent dent at the end: the contact node's displacement into the body (along its
  /// inward normal) less the body's rigid displacement there (fitted to all its nodes, weighted by
  /// their masses; 0 for a fixed body). Elastic ringing left in the body adds to it.
  double dent_m = 0;
  bool fixed = false;
};

struct ContactRunResult {
  std::vector<double> time_s, force_N;  ///< contact force on the impactor along n, per increment
  double max_force_N = 0, max_force_time_s = 0;
  double impulse_Ns = 0;          ///< trapezoidal integral of the force
  double contact_duration_s = 0;  ///< first to last increment with a force above 1e-3 F_max
  std::size_t increments = 0;  ///< increments ccx took (both steps)
  double wall_time_s = 0;
  ContactBodyMotion target, impactor;
  double initial_kinetic_energy_J = 0;  ///< of the initial (rigid) velocity field, FE masses
  /// |P_after - P_before| / |impulse| over both bodies, and the same for the angular momentum
  /// about the contact point (the solver's conservation check). With a fixed body: the free body's
  /// momentum change against the contact impulse on it, and its angular momentum about the point.
  double linear_momentum_relative_error = 0, angular_momentum_relative_error = 0;
  double vibration_energy_J = 0;      ///< both bodies
  double final_total_energy_J = 0;    ///< kinetic + strain of both bodies at the end
  /// Restitution from the bodies' rigid motions: the normal relative velocity of the contact
  /// points after the contact over the one before, -(v_after . n) / (v_before . n).
  double restitution = 0;
  double residual_indentation_m = 0;  ///< both bodies' dent_m summed (the laws' d_p)
  /// The target's probes (PROBE1, ...): von Mises history at the contact force's times and peak;
  /// `point_m` in the deck frame (world, origin at the contact point); `node` the ccx node.
  std::vector<ProbeStress> probes;
  std::vector<double> probe_time_s;
  /// Quasi-static route: the peak approach d_max, the `impact` run's force against approach
  /// (loading then unloading, from d = 0), |its loading work at d_max / (1/2 m* V^2) - 1| (runs
  /// `load` and `impact` agree), and the number of ccx runs. The momentum, vibration, velocity-jump
  /// and probe figures above are the dynamic route's and stay empty.
  bool quasi_static = false;
  double peak_approach_m = 0, energy_relative_error = 0;
  std::vector<double> curve_approach_m, curve_force_N;
  int solver_runs = 1;
};

/// An impact on a tabulated contact: mass m (kg) meets the contact at speed V (m/s) and moves by
/// m d'' = -F(d), F the loading curve (approach m, force N, from d = 0 with F(0) = 0, increasing d)
/// while d grows, then the unloading curve (decreasing d, from the turning point down to where F
/// vanishes). Both piecewise linear. The turning point is where the loading work is 1/2 m V^2.
struct CurveImpact {
  double max_force_N = 0, max_approach_m = 0, max_force_time_s = 0;
  double contact_time_s = 0, restitution = 0, impulse_Ns = 0;
  double residual_approach_m = 0;  ///< where the unloading force vanishes
  std::vector<double> time_s, force_N;  ///< F(t), about 400 samples
};
/// Throws std::invalid_argument when the loading curve's work falls short of 1/2 m V^2 or a curve
/// is not as described. RK4 in time for F(t) and the contact time (step: the loading time / 4000);
/// the turning point, F_max and the restitution (sqrt of the work ratio) from the curves exactly.
/// `extension` > 0: the loading curve's last segment is continued for up to that fraction of
/// 1/2 m V^2 more work (a run that was to end at the turning point and ended a little short).
/// The work of a piecewise-linear force over its approaches (trapezoids, exact for it), J.
double curve_work_J(const std::vector<double>& approach_m, const std::vector<double>& force_N);
/// The approach at which a loading curve (as impact_on_curves takes it) has done `work_J`, exact for
/// its piecewise-linear force; nullopt when its whole work falls short.
std::optional<double> approach_at_work(const std::vector<double>& load_approach_m, const std::vector<double>& load_force_N,
                                       double work_J);
CurveImpact impact_on_curves(const std::vector<double>& load_approach_m, const std::vector<double>& load_force_N,
                             const std::vector<double>& unload_approach_m, const std::vector<double>& unload_force_N,
                             double mass_kg, double speed_m_s, double extension = 0);

/// Runs ccx on the deck folder (check.hpp's runner) and reads the contact force history and the
/// final state. Throws InputError when ccx fails or its output is incomplete.
ContactRunResult run_contact_model(const std::filesystem::path& folder, const CheckOptions& options = {});
/// The same for the deck `written` has just written: contact.json's contents from memory.
ContactRunResult run_contact_model(const ContactDeck& written, const CheckOptions& options = {});

/// Exposed for tests: the C3D10 edge-middle node of the ccx ordering (5: 1-2, 6: 2-3, 7: 3-1,
/// 8: 1-4, 9: 2-4, 10: 3-4), 0-based corner pairs.
inline constexpr int kTet10Edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};

}  // namespace impactdeck::fem_export
