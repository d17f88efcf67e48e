#pragma once
// The force table handed to an FEM code: the impactor replaced by F(t) at the contact node.
#include <ostream>
#include <string>

#include <Eigen/Dense>

#include "impactdeck/collision/force_history.hpp"

namespace impactdeck::fem_export {

/// What the CSV header comment says about the table.
struct ForceTableHeader {
  std::string source;  ///< scene file
  std::string impact;  ///< impact name
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< unit direction of the force on the target
};

/// Writes `# ...` comment lines (units, source, direction, impulse and its error), then
/// `time_s,force_N` and one row per sample with 17 significant digits.
void write_force_table_csv(std::ostream& out, const collision::ForceTable& table,
                           const ForceTableHeader& header);

}  // namespace impactdeck::fem_export
