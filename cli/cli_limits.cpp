#include "cli_limits.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::cli {

double cloud_size(const geometry::Shape& target, study::CloudKind kind, int grid_steps, std::size_t count) {
  if (kind == study::CloudKind::vertices) {
    const auto* m = dynamic_cast<const geometry::MeshShape*>(&target);
    return m ? static_cast<double>(m->mesh().vertices_m.size()) : 0.0;
  }
  double n = 0;
  const double side = 2.0 * grid_steps + 1.0;
  if (kind != study::CloudKind::area_uniform) n += 2.0 * side * side;
  if (kind != study::CloudKind::paper_grid) n += static_cast<double>(count);
  return n;
}

void check_points(double evaluations, std::size_t limit, const std::string& where, const std::string& option,
                  const std::string& what) {
  if (evaluations <= static_cast<double>(limit)) return;
  std::ostringstream m;
  m.precision(4);
  m << what << " make " << evaluations << " impact evaluations, more than --max-points = " << limit
    << " (raise --max-points to allow it)";
  throw InputError(where, option, m.str());
}

void check_curve_samples(double points, std::size_t samples, std::size_t limit, const std::string& where) {
  const double total = points * static_cast<double>(samples);
  if (total <= static_cast<double>(limit)) return;
  std::ostringstream m;
  m.precision(4);
  m << points << " curves of " << samples << " samples make " << total << " samples, more than --max-curve-samples = "
    << limit << " (raise --max-curve-samples, or lower --curve-samples)";
  throw InputError(where, "--curve-samples", m.str());
}

void check_threads(unsigned threads) {
  if (threads > kMaxThreads) {
    throw UsageError("--threads " + std::to_string(threads) + ": at most " + std::to_string(kMaxThreads));
  }
}

CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || !(v > 0)) {
          return "must be a finite number > 0, got '" + text + "'";
        }
        return "";
      },
      "POSITIVE");
}

}  // namespace impactdeck::cli
