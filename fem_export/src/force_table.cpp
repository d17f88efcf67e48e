#include "impactdeck/fem_export/force_table.hpp"

#include <iomanip>

#include "impactdeck/common/version.hpp"

namespace impactdeck::fem_export {

void write_force_table_csv(std::ostream& out, const collision::ForceTable& t,
                           const ForceTableHeader& h) {
  out << "# impactdeck " << kVersion << " force table; units: SI (time in s, force in N)\n";
  if (!h.source.empty()) out << "# scene: " << h.source << "\n";
  if (!h.impact.empty()) out << "# impact: " << h.impact << "\n";
  out << std::setprecision(17);
  const Eigen::Vector3d d = h.direction + Eigen::Vector3d::Zero();  // no "-0" in the file
  out << "# force direction on the target (unit vector): " << d.x() + 0.0 << " " << d.y() + 0.0
      << " " << d.z() + 0.0 << "\n";
  out << "# table impulse " << t.impulse_Ns << " N s, relative error "
      << std::setprecision(3) << t.impulse_relative_error << " against the exact impulse\n";
  out << std::setprecision(17);
  out << "time_s,force_N\n";
  for (std::size_t i = 0; i < t.time_s.size(); ++i) out << t.time_s[i] << "," << t.force_N[i] << "\n";
}

}  // namespace impactdeck::fem_export
