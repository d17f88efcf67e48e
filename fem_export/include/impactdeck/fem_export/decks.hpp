#pragma once
// FEM decks of the hybrid approach: the target body alone, meshed, with the impactor replaced by
// the Hertz force history at the load node. One folder per impact holds everything a solver needs
// (files listed in docs/fem.md); it appears complete or not at all.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {

/// The job name of every deck: impact.inp (CalculiX), impact.comm / impact.export (Code_Aster).
inline constexpr const char* kJobName = "impact";

struct DeckMaterial {
  double youngs_modulus_Pa = 0;
  double poisson_ratio = 0;
  double density_kg_m3 = 0;
};

enum class BodyKind { ellipsoid, stl };

struct DeckBody {
  BodyKind kind = BodyKind::ellipsoid;
  Eigen::Vector3d semi_axes_m = Eigen::Vector3d::Zero();  ///< ellipsoid, centred at the origin
  std::filesystem::path stl;                             ///< stl
  double stl_unit_m = 1e-3;                              ///< metres per STL coordinate unit
};

/// CalculiX's equation solver for the implicit dynamic steps (`*DYNAMIC, DIRECT[, SOLVER=...]`).
enum class CcxSolver {
  automatic,  ///< by deck size: `iterative` from kIterativeSolverMinNodes nodes, else `spooles`
  spooles,    ///< ccx's default sparse direct solver (SPOOLES)
  iterative,  ///< SOLVER=ITERATIVE SCALING (diagonally scaled conjugate gradients)
};
/// From this many nodes `automatic` takes the iterative solver. Measured (bench/bench_ccx.cpp,
/// docs/fem.md): on decks of 173 to 5,108 nodes it ran 2.5 to 22 times faster per increment than
/// SPOOLES with the same momentum and probe stresses (to 4e-8); smaller decks, too coarse for
/// stresses and cheap either way, keep the direct solver.
inline constexpr std::size_t kIterativeSolverMinNodes = 150;
const char* to_string(CcxSolver s);
/// The solver a deck of `nodes` nodes is written with (`automatic` resolved).
CcxSolver ccx_solver_for(CcxSolver requested, std::size_t nodes);

struct DeckOptions {
  double end_time_s = 0.02;    ///< simulated time (the paper: 0.02 s)
  double time_step_s = 1e-5;   ///< solver step after the contact (the paper: 1e-5 s)
  /// Increments across the contact: while the force acts the step is contact_end / this (when
  /// smaller than time_step_s). The solver samples the force at its increments: measured on the
  /// paper's case (69 us pulse), 7 steps of 1e-5 s miss 0.5 % of the impulse, 40 steps 5.4e-4,
  /// 160 steps 1.1e-4. 0 turns the refined phase off.
  int pulse_increments = 100;
  bool code_aster = true;      ///< write impact.comm, impact.export and mesh.med
  bool calculix = true;        ///< write impact.inp and mesh.inp
  CcxSolver solver = CcxSolver::automatic;  ///< impact.inp's equation solver
  MeshOptions mesh;
};

struct DeckRequest {
  std::string source;   ///< scene file named in the headers
  std::string impact;   ///< impact name
  DeckBody body;
  DeckMaterial material;
  collision::ForceTable force;  ///< F(t) on the target, N vs s; first and last force 0
  double impulse_Ns = 0;        ///< exact impulse of the force history (the checks' reference)
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();     ///< unit direction of the force
  Eigen::Vector3d load_point_m = Eigen::Vector3d::Zero();  ///< target frame
  DeckOptions options;
};

struct DeckResult {
  std::filesystem::path folder;
  std::vector<std::filesystem::path> files;  ///< every file of the folder, in writing order
  MeshQuality quality;
  std::size_t node_count = 0, tet_count = 0;
  double mesh_seconds = 0;  ///< wall time of the meshing part
};

/// The time stepping of a deck: a refined phase through the end of the contact, then the user's
/// step through end_time_s (its step adjusted down so that it divides the remaining time).
struct TimeSchedule {
  std::size_t pulse_increments = 0;  ///< 0: no refined phase
  double pulse_step_s = 0, pulse_end_s = 0;
  std::size_t main_increments = 0;
  double main_step_s = 0;
};
TimeSchedule time_schedule(const DeckOptions& options, double contact_end_s);

/// Meshes the body and writes the decks into `folder` (created; its parent must exist). The files
/// are first written into a hidden sibling folder which is renamed to `folder` only when all
/// succeeded; a previous `folder` is replaced then. Throws InputError on bad input or a meshing
/// failure, leaving `folder` as it was.
DeckResult write_decks(const DeckRequest& request, const std::filesystem::path& folder);

/// Text of the Code_Aster command file (exposed for tests).
std::string code_aster_comm(const DeckRequest& request, const TetMesh& mesh);
/// Text of the run_aster .export file.
std::string code_aster_export(const DeckRequest& request, const TetMesh& mesh);
/// Text of the CalculiX main deck and of its included mesh.
std::string calculix_inp(const DeckRequest& request, const TetMesh& mesh);
std::string calculix_mesh_inp(const TetMesh& mesh);

}  // namespace impactdeck::fem_export
