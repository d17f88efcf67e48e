#pragma once
// Code_Aster behind the solver interface (solver.hpp), private to fem_export: mesh.med,
// impact.comm and impact.export. Written only (Code_Aster is not installable here: can_run false).
#include <filesystem>
#include <string>
#include <vector>

#include "impactdeck/fem_export/solver.hpp"

namespace impactdeck::fem_export::code_aster {

class CodeAsterSolver final : public Solver {
 public:
  std::string name() const override { return "code_aster"; }
  std::string title() const override { return "Code_Aster"; }
  std::vector<std::string> write_deck(const DeckInput& in, const std::filesystem::path& folder) const override;
};

/// Text of the Code_Aster command file (exposed for tests). `patch`: the hertz-patch nodal forces
/// (nullptr: the point load on LOAD); its nodes are the mesh's groups LP1, LP2, ... in order.
std::string code_aster_comm(const DeckRequest& request, const TetMesh& mesh, const PatchLoad* patch = nullptr);
/// Text of the run_aster .export file.
std::string code_aster_export(const DeckRequest& request, const TetMesh& mesh);

}  // namespace impactdeck::fem_export::code_aster
