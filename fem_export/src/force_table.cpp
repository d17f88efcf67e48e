#include "impactdeck/fem_export/force_table.hpp"

#include <iomanip>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"

namespace impactdeck::fem_export {

void write_force_table_csv(std::ostream& out, const collision::ForceTable& t) {
  out << std::setprecision(17);
  out << "time_s,force_N\n";
  for (std::size_t i = 0; i < t.time_s.size(); ++i) out << t.time_s[i] << "," << t.force_N[i] << "\n";
}

std::vector<std::pair<std::string, std::string>> force_table_metadata(const collision::ForceTable& t,
                                                                       const ForceTableHeader& h) {
  std::vector<std::pair<std::string, std::string>> d = {{"title", "impactdeck force table"}};
  if (!h.source.empty()) d.push_back({"scene", h.source});
  if (!h.impact.empty()) d.push_back({"impact", h.impact});
  std::ostringstream dir, impulse;
  const Eigen::Vector3d v = h.direction + Eigen::Vector3d::Zero();  // no "-0" in the file
  dir << std::setprecision(17) << v.x() + 0.0 << " " << v.y() + 0.0 << " " << v.z() + 0.0;
  d.push_back({"force_direction_on_target", dir.str()});
  impulse << std::setprecision(17) << t.impulse_Ns << " N s, relative error " << std::setprecision(3)
          << t.impulse_relative_error << " against the exact impulse";
  d.push_back({"table_impulse", impulse.str()});
  return d;
}

void write_force_table_files(const std::filesystem::path& csv, const collision::ForceTable& t,
                             const ForceTableHeader& h) {
  write_file_atomically(csv, [&](std::ostream& out) { write_force_table_csv(out, t); });
  write_csv_sidecar(csv, {"time_s", "force_N"}, force_table_metadata(t, h));
}

}  // namespace impactdeck::fem_export
