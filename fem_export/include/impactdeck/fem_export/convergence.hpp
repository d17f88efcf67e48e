#pragma once
// The verdict's mesh convergence (`[outputs.fem] convergence = "two-meshes"`, docs/fem.md): the
// same deck on a second mesh of half the element size, its governing stress judged at the same
// distance from the contact point as the first mesh's (the first mesh's contact zone radius: at
// least 2 of its load elements, so both meshes resolve the stress there; under a point load the
// stress at the load node itself grows without bound as the mesh is refined), and whether the
// verdict holds: the same verdict and a governing stress within the tolerance on both meshes.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/stress.hpp"

namespace impactdeck::fem_export {

/// Largest relative change of the governing stress (and so of the safety factor's inverse)
/// between the mesh and its half-size refinement for the verdict to hold: 10 %, the change a
/// first-order (C3D4) stress makes when h halves once its error is below ~20 % (the error of a
/// linear tetrahedron's stress falls as h, so it halves with h).
inline constexpr double kConvergenceTolerance = 0.10;

/// The governing stress of one mesh of the pair.
struct ConvergenceMesh {
  double mesh_size_m = 0, load_mesh_size_m = 0;
  std::size_t node_count = 0, tet_count = 0;
  Verdict verdict;
  double solver_wall_time_s = 0;
};

struct MeshConvergence {
  ConvergenceMesh coarse, fine;
  /// Both governing stresses are judged outside this radius of the contact point (the coarse
  /// mesh's contact zone radius, used on the fine mesh too).
  double evaluation_radius_m = 0;
  double relative_change = 0;  ///< (fine - coarse) / coarse governing von Mises
  double tolerance = kConvergenceTolerance;
  bool holds = false;          ///< established, the same verdict kind and |relative_change| <= tolerance
  /// False when the refined mesh gave no verdict to compare (its deck or run failed: `fine` is
  /// empty) or its FE checks failed: then holds is false and the statement says why.
  bool established = true;
  bool refined_ran = true;     ///< false: the refined mesh's deck or run failed (`fine` is empty)
  std::string statement;       ///< "holds", "moves with the mesh" or "not established", with why
  std::string folder;          ///< the fine deck's folder, relative to the first deck's
  std::vector<std::filesystem::path> files;  ///< the fine deck's files and its solver's results
};

/// Compares the two meshes' verdicts (coarse.verdict, fine.verdict filled): relative_change, holds
/// and statement. A coarse governing stress of 0 makes any fine one a change of +inf (moves), both 0
/// a change of 0.
void judge_convergence(MeshConvergence& c);
/// The refined mesh gave no verdict that can be compared: established and holds false, the
/// statement "not established: <why>".
void not_established(MeshConvergence& c, const std::string& why);

nlohmann::json to_json(const MeshConvergence& c);
/// One line: "governing von Mises A MPa (mesh h1 mm) -> B MPa (h2 mm), change
/// +x %: the verdict holds (within 10 %)" or "... moves with the mesh".
std::string format_convergence(const MeshConvergence& c);

}  // namespace impactdeck::fem_export
