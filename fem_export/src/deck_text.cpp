// Helpers of the deck writers (see deck_text.hpp).
#include "deck_text.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/common/version.hpp"

namespace impactdeck::fem_export::detail {

std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(12) << v + 0.0;  // + 0.0: no "-0"
  std::string t = s.str();
  if (t.find_first_of(".eE") == std::string::npos && t != "inf" && t != "nan") t += ".0";
  return t;
}

std::size_t increments(const DeckOptions& o) {
  return static_cast<std::size_t>(std::ceil(o.end_time_s / o.time_step_s - 1e-9));
}

// See deck_text.hpp.
std::size_t output_every(const DeckOptions& o, const TimeSchedule& ts, std::size_t nodes) {
  const double work = static_cast<double>(nodes) * static_cast<double>(ts.main_increments);
  if (!(o.stress_output_budget > 0) || work <= o.stress_output_budget) return 1;
  return static_cast<std::size_t>(std::ceil(work / o.stress_output_budget));
}

std::string header_lines(const std::string& c, const DeckRequest& r, const std::string& what) {
  std::ostringstream h;
  h << c << " impactdeck " << kVersion << ": " << what << "\n"
    << c << " Hybrid approach: the impactor is replaced by its Hertz force history at node group LOAD.\n"
    << c << " Units: " << r.options.units.description() << ".\n"
    << c << " Scene: " << (r.source.empty() ? "(none)" : r.source) << "; impact: " << r.impact << "\n"
    << c << " Impulse " << num(r.impulse_Ns) << " N s along (" << num(r.direction.x()) << ", "
    << num(r.direction.y()) << ", " << num(r.direction.z()) << "); contact ends at "
    << num(r.force.time_s.back()) << " s.\n";
  return h.str();
}

std::vector<std::string> probe_groups(const TetMesh& m) {
  std::vector<std::string> p;
  for (const auto& [g, n] : m.node_groups)
    if (g.rfind("PROBE", 0) == 0) p.push_back(g);
  return p;
}

std::string read_text(const std::filesystem::path& p, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) throw InputError(p.string(), "file", what + " does not exist");
  return read_input_file(p, what, available_memory_bytes() / 4, "a quarter of the free memory");
}

}  // namespace impactdeck::fem_export::detail
