#pragma once
// The momentum check of a deck, run for real with CalculiX: after the pulse a free body must carry
// the impulse as linear momentum, and its moment about the centre of mass as angular momentum.
//
//   linear   P_FE = sum_n m_n v_n   (lumped row sums of the consistent mass matrix: exact for P)
//            compared as P_FE / M_FE . d   vs   Pi / M_FE
//   angular  L_FE = y^T M v with the mass matrix ccx 2.20 builds for C3D4 (one integration point:
//            L_FE = sum_e m_e ybar_e x vbar_e, y = x - c; the fully integrated matrix's formula
//            misses by several %, measured)
//            omega_FE = I_FE^-1 L_FE   vs   omega_ref = I_FE^-1 ((p - c) x Pi d)
// M_FE, c, I_FE are the FE mesh's own mass, centroid and inertia (DECKS.md: a coarse mesh is
// lighter than the analytic body). Probe nodes' time-averaged velocities are reported with their
// scatter, not checked (DECKS.md: their elastic vibration exceeds the rigid-body velocity).
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

namespace impactdeck::fem_export {

struct CheckOptions {
  std::string ccx = "ccx";           ///< solver executable (searched in PATH)
  bool run_solver = true;            ///< false: only parse an existing impact.dat
  double linear_tolerance = 1e-3;    ///< max relative error of the mean velocity (0.1 %)
  double angular_tolerance = 1e-2;   ///< max relative error of the angular velocity (1 %)
  std::ostream* progress = nullptr;  ///< progress lines from the .sta file (e.g. &std::cerr)
  /// OMP_NUM_THREADS and CCX_NPROC_EQUATION_SOLVER for ccx; 0: all cores.
  int threads = 0;
};

struct ProbeResult {
  std::string name;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();   ///< node position
  double mean_velocity_m_s = 0;      ///< time average after the pulse, along the force direction
  double scatter_m_s = 0;            ///< max - min of the averages over the four quarter windows
  double rigid_body_velocity_m_s = 0;  ///< v + omega x r of the rigid body, along the direction
  double relative_difference = 0;     ///< (mean - rigid) / |rigid|
  std::size_t samples = 0;
};

struct CheckResult {
  double fe_mass_kg = 0;               ///< from the mesh (sum of rho V_e)
  double solver_mass_kg = 0;           ///< total mass printed by ccx (EMAS)
  double impulse_Ns = 0;
  double expected_velocity_m_s = 0;    ///< Pi / M_FE
  double fe_velocity_m_s = 0;          ///< P_FE . d / M_FE
  double linear_momentum_relative_error = 0;
  /// Empty for a central hit (|r x d| below 1e-6 of the body size).
  std::optional<double> angular_momentum_relative_error;
  Eigen::Vector3d angular_velocity_fe_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_expected_rad_s = Eigen::Vector3d::Zero();
  std::vector<ProbeResult> probes;
  double solver_wall_time_s = 0;
  int solver_threads = 0;              ///< threads ccx was given
  double momentum_time_s = 0;          ///< time of the all-node velocity print
  double linear_tolerance = 0, angular_tolerance = 0;
  bool passed = false;
  std::vector<std::string> failures;   ///< one line per failed check
};

/// Runs ccx on `deck_dir`/impact.inp (cwd = deck_dir, output in impact.log), then parses
/// impact.dat. Throws InputError when the folder is not a deck, ccx is missing or fails, or the
/// output is incomplete; a check above its tolerance is reported in `passed`/`failures`.
CheckResult run_check(const std::filesystem::path& deck_dir, const CheckOptions& options = {});

/// JSON of a check (keys documented in docs/fem.md).
nlohmann::json to_json(const CheckResult& r);

/// Human-readable lines.
std::string format_check(const CheckResult& r);

}  // namespace impactdeck::fem_export
