// The solver registry and the Solver defaults (solver.hpp).
#include "impactdeck/fem_export/solver.hpp"

#include <mutex>
#include <stdexcept>

#include "calculix/calculix.hpp"
#include "code_aster/code_aster.hpp"

namespace impactdeck::fem_export {
namespace {

struct Registry {
  std::mutex mutex;
  std::vector<std::unique_ptr<Solver>> solvers;
};

Registry& registry() {
  static Registry* r = [] {
    auto* reg = new Registry;  // never destroyed: solvers may be looked up during static destruction
    // The built-in solvers, one line each; their order is the order of the deck's files.
    reg->solvers.push_back(std::make_unique<calculix::CalculixSolver>());
    reg->solvers.push_back(std::make_unique<code_aster::CodeAsterSolver>());
    return reg;
  }();
  return *r;
}

}  // namespace

void Solver::describe(const DeckInput&, bool selected, nlohmann::json& deck) const { deck[name()] = selected; }

TetMesh Solver::read_mesh(const std::filesystem::path& deck_dir, const DeckUnits&) const {
  throw std::logic_error(title() + " cannot read its mesh back (" + deck_dir.string() + "): it does not run here");
}

SolverOutput Solver::run(const SolverJob& job) const {
  throw std::logic_error(title() + " decks are written, not run (" + job.deck_dir.string() + ")");
}

std::optional<StressResult> Solver::stresses(const SolverJob&, const StressInputs&) const { return std::nullopt; }

std::vector<const Solver*> solvers() {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<const Solver*> out;
  for (const auto& s : r.solvers) out.push_back(s.get());
  return out;
}

const Solver* find_solver(const std::string& name) {
  for (const Solver* s : solvers())
    if (s->name() == name) return s;
  return nullptr;
}

void register_solver(std::unique_ptr<Solver> solver) {
  if (!solver || solver->name().empty()) throw std::invalid_argument("register_solver: a solver needs a name");
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (const auto& s : r.solvers) {
    if (s->name() == solver->name()) throw std::invalid_argument("register_solver: '" + s->name() + "' is taken");
  }
  r.solvers.push_back(std::move(solver));
}

}  // namespace impactdeck::fem_export
