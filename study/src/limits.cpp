#include "impactdeck/study/limits.hpp"

#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::study {

double cloud_size(const geometry::Shape& target, CloudKind kind, int grid_steps, std::size_t count) {
  if (kind == CloudKind::vertices) {
    const geometry::MeshShape* m = target.triangle_mesh();
    return m ? static_cast<double>(m->mesh().vertices_m.size()) : 0.0;
  }
  double n = 0;
  const double side = 2.0 * grid_steps + 1.0;
  if (kind != CloudKind::area_uniform) n += 2.0 * side * side;
  if (kind != CloudKind::paper_grid) n += static_cast<double>(count);
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

}  // namespace impactdeck::study
