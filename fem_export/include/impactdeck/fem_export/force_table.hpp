#pragma once
// The force table handed to an FEM code: the impactor replaced by F(t) at the contact node.
#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/collision/force_history.hpp"

namespace impactdeck::fem_export {

/// What the CSV's JSON sidecar says about the table.
struct ForceTableHeader {
  std::string source;  ///< scene file
  std::string impact;  ///< impact name
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< unit direction of the force on the target
};

/// Writes the header line `time_s,force_N` and one row per sample with 17 significant digits (no
/// comment lines: numpy and VTK read it as is).
void write_force_table_csv(std::ostream& out, const collision::ForceTable& table);

/// The sidecar's metadata: scene, impact, force direction, the table's impulse and its error.
std::vector<std::pair<std::string, std::string>> force_table_metadata(const collision::ForceTable& table,
                                                                       const ForceTableHeader& header);

/// Writes `csv` atomically and its JSON sidecar `csv`.json (common/csv_sidecar.hpp).
void write_force_table_files(const std::filesystem::path& csv, const collision::ForceTable& table,
                             const ForceTableHeader& header);

}  // namespace impactdeck::fem_export
