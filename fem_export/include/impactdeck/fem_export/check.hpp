#pragma once
// The momentum check of a deck, run for real by its solver (solver.hpp; CalculiX is the one that
// runs here, ccx 2.20 below): after the pulse a free body must carry
// the impulse as linear momentum, and its moment about the centre of mass as angular momentum.
//
//   linear   P_FE = sum_n m_n v_n   (lumped row sums of the consistent mass matrix: exact for P)
//            compared as P_FE / M_FE . d   vs   Pi / M_FE
//   angular  L_FE = y^T M v with the mass matrix ccx 2.20 builds for C3D4 (one integration point:
//            L_FE = sum_e m_e ybar_e x vbar_e, y = x - c; the fully integrated matrix's formula
//            misses by several %, measured)
//            omega_FE = I_FE^-1 L_FE   vs   omega_ref = I_FE^-1 ((p - c) x Pi d)
// M_FE, c, I_FE are the FE mesh's own mass, centroid and inertia (a coarse mesh is lighter
// than the analytic body: docs/validation.md). Probe nodes' time-averaged velocities are reported with their
// scatter, not checked (docs/validation.md: their elastic vibration exceeds the rigid-body velocity).
//
// Beside this solver self-check, the FE result is compared with the rigid model (deck.json
// "model": the part's exact mass properties and the impact's velocity jumps of the target):
//   model_linear_velocity_relative_error  = |P_FE / M_FE - dv| / |dv|
//   model_angular_velocity_relative_error = |I_FE^-1 L_FE - dw| / |dw|   (null unless the lever arm
//                                           exceeds a tenth of the radius of gyration: decks.hpp)
// and the FE body with the part (volume, mass, inertia, Gmsh gamma floor; decks.hpp
// compare_body). Then the stresses are read back from the solver's results (CalculiX: impact.frd,
// stress.hpp). The solver runs and reads its results; the physics and the verdict are here.
#include <filesystem>
#include <map>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/convergence.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/stress.hpp"

namespace impactdeck::fem_export {

struct CheckOptions {
  /// Each solver's executable by its registry name (Solver::name(): "calculix"); a solver not
  /// named here runs its own default (CalculiX: "ccx", searched in PATH). `fem-check --ccx PATH`
  /// sets "calculix".
  std::map<std::string, std::string> executables;
  /// executables[solver], or `fallback` when not set.
  std::string executable(const std::string& solver, const std::string& fallback) const {
    const auto it = executables.find(solver);
    return it == executables.end() || it->second.empty() ? fallback : it->second;
  }
  bool run_solver = true;            ///< false: only parse an existing impact.dat
  /// Max relative error of the mean velocity; 0: the deck's (deck.json tolerances, default 1e-3).
  double linear_tolerance = 0;
  /// Max relative error of the angular velocity; 0: the deck's (default 1e-2).
  double angular_tolerance = 0;
  bool stresses = true;              ///< read impact.frd back (when present) and write the stress files
  std::ostream* progress = nullptr;  ///< progress lines from the .sta file (e.g. &std::cerr)
  /// OMP_NUM_THREADS and CCX_NPROC_EQUATION_SOLVER for ccx; 0: all cores.
  int threads = 0;
  /// Wall-time limit of the ccx run (--solver-timeout-s): past it ccx's process group is killed
  /// and the check fails with exit 3. 0: default_solver_timeout_s of the deck.
  double timeout_s = 0;
  /// Where ccx runs and writes its results (the deck's impact.inp and mesh.inp are copied there);
  /// empty: the deck folder itself. `fem-check` uses a private folder of its run transaction.
  std::filesystem::path work_dir;
};

/// The default ccx time limit of a deck: 10 times an estimate of its run time (2e-4 s per node and
/// increment, times sqrt(nodes / 1000) above 1000 nodes; measured ccx 2.20 runs take 0.4 to 0.9
/// of the estimate, docs/reliability.md), and at least 300 s.
double default_solver_timeout_s(std::size_t nodes, std::size_t increments);

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
  double solver_timeout_s = 0;         ///< the limit the run had
  std::string solver_timeout_source;   ///< "--solver-timeout-s", or how the default was derived
  /// ccx's output files (impact.dat, .frd, .sta, .cvg, .log, ...) in the work folder.
  std::vector<std::filesystem::path> solver_files;
  int solver_threads = 0;              ///< threads ccx was given
  double momentum_time_s = 0;          ///< time of the all-node velocity print
  double linear_tolerance = 0, angular_tolerance = 0;
  /// FE rigid-body motion against the rigid model (null when the deck carries no model, or the
  /// hit is central for the angular one).
  std::optional<double> model_linear_velocity_relative_error;
  std::optional<double> model_angular_velocity_relative_error;
  Eigen::Vector3d fe_rigid_velocity_m_s = Eigen::Vector3d::Zero();       ///< P_FE / M_FE
  Eigen::Vector3d model_delta_velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d model_delta_angular_velocity_rad_s = Eigen::Vector3d::Zero();
  double model_linear_velocity_tolerance = 0, model_angular_velocity_tolerance = 0;
  BodyComparison body;                 ///< the FE body against the part
  std::optional<StressResult> stress;  ///< when the run wrote impact.frd
  /// The verdict on a second mesh of half the size (`convergence = "two-meshes"`; the caller runs
  /// it and fills this in: convergence.hpp).
  std::optional<MeshConvergence> convergence;
  bool passed = false;
  std::vector<std::string> failures;   ///< one line per failed check
};

/// Runs the deck's solver (the first registered one that can run and whose files the deck has:
/// ccx on `deck_dir`/impact.inp, in options.work_dir or the deck folder, output in impact.log),
/// then reads its results (impact.dat). Throws InputError naming the file, the step and the reason
/// when the folder is not a deck, ccx is missing, fails, is killed by a signal, runs past its
/// timeout, or its output is incomplete (a missing print, a full disk); a check above its
/// tolerance is reported in `passed`/`failures`.
CheckResult run_check(const std::filesystem::path& deck_dir, const CheckOptions& options = {});

/// `fem-check DIR`: run_check as one transaction on the deck folder. The solver runs in a private
/// folder of it, and its files (and the stress files) replace the folder's previous ones when the
/// run completed, whether or not every check passed (a failed check's results are its evidence);
/// a run that throws leaves the folder as it was. `before_commit` (optional) gets the result, its
/// files named at their places in `deck_dir`, just before they are published (the CLI prints
/// there: when it throws, nothing is published). Without options.run_solver the folder's results
/// are only read. InputError when `deck_dir` is not a folder. `warnings` (optional) receives the
/// transaction's warnings.
CheckResult check_deck_folder(const std::filesystem::path& deck_dir, CheckOptions options,
                              std::vector<std::string>* warnings = nullptr,
                              const std::function<void(const CheckResult&)>& before_commit = {});

/// The same for the deck `written` has just written (write_decks / write_deck_files): its
/// description and mesh are taken from memory, not read back from deck.json and mesh.inp.
CheckResult run_check(const DeckResult& written, const CheckOptions& options = {});

/// JSON of a check (keys documented in docs/fem.md).
nlohmann::json to_json(const CheckResult& r);

/// Human-readable lines.
std::string format_check(const CheckResult& r);

}  // namespace impactdeck::fem_export
