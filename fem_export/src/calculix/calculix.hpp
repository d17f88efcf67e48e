#pragma once
// CalculiX behind the solver interface (solver.hpp), private to fem_export: its deck dialect
// (impact.inp, mesh.inp), the ccx run and the reading of impact.dat / impact.frd.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/solver.hpp"

namespace impactdeck::fem_export::calculix {

/// ccx's executable when CheckOptions::executables does not name one (searched in PATH).
inline constexpr const char* kCcx = "ccx";

/// Plastic decks, steps after the contact: ccx may cut an increment down to this fraction of the
/// step (automatic incrementation; deck.cpp says why) ...
inline constexpr double kPlasticMinIncrementFraction = 1e-4;
/// ... and may take this many times the step's increments (its INC bound).
inline constexpr std::size_t kPlasticIncrementHeadroom = 20;

class CalculixSolver final : public Solver {
 public:
  std::string name() const override { return "calculix"; }
  std::string title() const override { return "CalculiX"; }
  std::vector<std::string> write_deck(const DeckInput& in, const std::filesystem::path& folder) const override;
  void describe(const DeckInput& in, bool selected, nlohmann::json& deck) const override;
  bool can_run() const override { return true; }
  TetMesh read_mesh(const std::filesystem::path& deck_dir, const DeckUnits& units) const override;
  std::string mesh_file() const override { return "mesh.inp"; }
  SolverOutput run(const SolverJob& job) const override;
  std::optional<StressResult> stresses(const SolverJob& job, const StressInputs& in) const override;
};

/// ccx's .frd as solver-neutral nodal results (stress.hpp): DISP, STRESS and PE blocks (frd.cpp).
/// The constructor checks the file (InputError when missing or unreadable).
class FrdResults final : public NodalResults {
 public:
  explicit FrdResults(std::filesystem::path frd);
  const std::filesystem::path& file() const override { return frd_; }
  std::size_t read(const NodalResultsVisitor& visitor, std::size_t node_count) const override;

 private:
  std::filesystem::path frd_;
};

/// The *MATERIAL card `name` of `m` with *ELASTIC, *DENSITY and, for MaterialModel::plastic, the
/// *PLASTIC rows of hardening_table(m, yield_Pa); values times per_Pa (stresses) and per_kg_m3
/// (density) into the deck's units. The one writer of both the hybrid deck and the contact model.
std::string material_cards(const std::string& name, const DeckMaterial& m, double yield_Pa, double per_Pa,
                           double per_kg_m3);

/// Text of the CalculiX main deck (`patch`: the hertz-patch nodal forces, nullptr: the point load
/// on LOAD) and of its included mesh (exposed for tests).
std::string calculix_inp(const DeckRequest& request, const TetMesh& mesh, const PatchLoad* patch = nullptr);
std::string calculix_mesh_inp(const TetMesh& mesh, const DeckUnits& units = {});

/// Runs ccx on `dir`/`job`.inp (cwd = dir, output in `job`.log, progress from `job`.sta up to
/// `end_time_s`) with options.timeout_s, or default_solver_timeout_s(nodes, solves); returns the
/// wall time in s. Throws InputError when ccx is missing, fails or times out. The runner of the
/// hybrid check and of the full-contact model (contact_model.hpp).
double run_ccx_job(const std::filesystem::path& dir, const CheckOptions& options, double end_time_s,
                   std::size_t nodes, std::size_t solves, const std::string& job = kJobName);

}  // namespace impactdeck::fem_export::calculix
