#pragma once
// The FEM solver interface. A solver writes its deck files from a solver-neutral description of the
// hybrid model (DeckInput) and, if it can run here, runs them and reads back what the check needs
// (SolverOutput). Everything else stays outside the solvers: meshing, MED, the force table,
// deck.json, the physics check of the results and the verdict (decks.hpp, check.hpp).
//
// Implementations, one folder each (docs/extending.md, "A solver"):
//   src/calculix/    CalculiX: impact.inp + mesh.inp, the ccx run, impact.dat / impact.frd reading
//   src/code_aster/  Code_Aster: mesh.med + impact.comm + impact.export (written only)
// The built-in ones are registered in src/solvers.cpp, one line each.
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/stress.hpp"

namespace impactdeck::fem_export {

struct CheckOptions;  // check.hpp

/// What every solver's deck is written from. Units: the mesh and the request are SI (metres);
/// request.options.units is the unit system the deck files must use.
struct DeckInput {
  const DeckRequest& request;  ///< material, force table, direction, options (units, time, tolerances)
  /// The mesh, in metres: tetrahedra (group BODY), node groups LOAD, PROBE1..., and LP1... for a
  /// hertz-patch load (in the order of patch->nodes).
  const TetMesh& mesh;
  const PatchLoad* patch;         ///< the hertz-patch nodal forces; nullptr: F(t) on LOAD
  const TimeSchedule& schedule;   ///< the increments (deck_schedule(request))
};

/// A run of a deck (Solver::run): where it is and what the check knows about it.
struct SolverJob {
  std::filesystem::path deck_dir;  ///< the deck folder (its files as write_deck wrote them)
  std::filesystem::path work_dir;  ///< where to run and write results (may be deck_dir)
  const TetMesh& mesh;             ///< the deck's mesh, metres (node i is the solver's node i + 1)
  DeckUnits units;
  double end_time_s = 0;
  std::vector<std::string> probes;  ///< the probe node groups (PROBE1, ...)
  double timeout_s = 0;             ///< wall-time limit of the run
  std::string timeout_source;       ///< how the limit was set (named when it passes)
  const CheckOptions& options;
};

/// What a run gives the check, solver-neutral (SI; nodes 0-based unless said).
struct SolverOutput {
  double wall_time_s = 0;
  int threads = 0;
  std::vector<std::filesystem::path> files;  ///< the solver's own output files in the work folder
  std::filesystem::path results_file;        ///< the file the results come from (named in errors)
  double momentum_time_s = 0;                ///< time of node_velocity_m_s (after the pulse)
  std::vector<Eigen::Vector3d> node_velocity_m_s;  ///< every node of the mesh, free body after the pulse
  double total_mass_kg = 0;                  ///< the solver's own total mass
  /// Each probe's velocity history: its 1-based solver node and (time, velocity) pairs.
  std::map<std::string, std::pair<int, std::vector<std::pair<double, Eigen::Vector3d>>>> probe_velocity;
};

class Solver {
 public:
  virtual ~Solver() = default;
  /// The registry's name: DeckOptions::solvers, the deck.json key that says a deck has its files.
  virtual std::string name() const = 0;
  /// For messages: "CalculiX", "Code_Aster".
  virtual std::string title() const = 0;
  /// Writes the deck files into `folder` (the staging folder of the deck: write with
  /// common/atomic_file.hpp; a failure throws and the whole folder is dropped). Returns the file
  /// names, in writing order, for deck.json's file list.
  virtual std::vector<std::string> write_deck(const DeckInput& in, const std::filesystem::path& folder) const = 0;
  /// Adds its entries to deck.json (called for every registered solver; `selected`: its files were
  /// written). The default writes `"<name>": selected`.
  virtual void describe(const DeckInput& in, bool selected, nlohmann::json& deck) const;
  /// Whether run() works (the solver is an executable here). false: decks are only written.
  virtual bool can_run() const { return false; }
  /// Reads the mesh back from a deck folder (fem-check on a folder). Only for solvers that can run.
  virtual TetMesh read_mesh(const std::filesystem::path& deck_dir, const DeckUnits& units) const;
  /// The mesh file of its deck, named when the mesh is degenerate.
  virtual std::string mesh_file() const { return "mesh"; }
  /// Runs the deck in job.work_dir (or, with options.run_solver false, only reads the results
  /// there) and reads the results back. Throws InputError naming the file, the step and the reason.
  virtual SolverOutput run(const SolverJob& job) const;
  /// The stress history of the run in job.work_dir, when it wrote one (nullopt: none).
  virtual std::optional<StressResult> stresses(const SolverJob& job, const StressInputs& in) const;
};

/// The registered solvers, in registration order (the built-in ones first: src/solvers.cpp). The
/// order is the order their files are written and listed.
std::vector<const Solver*> solvers();
/// The solver of that name, or nullptr.
const Solver* find_solver(const std::string& name);
/// Adds a solver (a test's, a plugin's). Throws std::invalid_argument when the name is taken or empty.
void register_solver(std::unique_ptr<Solver> solver);

}  // namespace impactdeck::fem_export
