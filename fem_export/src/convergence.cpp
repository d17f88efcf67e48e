// The verdict's mesh convergence (convergence.hpp).
#include "impactdeck/fem_export/convergence.hpp"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace impactdeck::fem_export {

void judge_convergence(MeshConvergence& c) {
  const double a = c.coarse.verdict.governing.von_mises_Pa, b = c.fine.verdict.governing.von_mises_Pa;
  c.relative_change = a > 0 ? (b - a) / a : b > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  const bool same_kind = c.coarse.verdict.kind == c.fine.verdict.kind;
  const bool within = std::abs(c.relative_change) <= c.tolerance;
  c.holds = same_kind && within;
  std::ostringstream s;
  s << std::setprecision(3);
  if (c.holds) {
    s << "holds: the same verdict (" << to_string(c.fine.verdict.kind) << ") on both meshes, governing stress within "
      << 100 * c.tolerance << " %";
  } else {
    s << "moves with the mesh: ";
    if (!same_kind) {
      s << to_string(c.coarse.verdict.kind) << " on the first mesh, " << to_string(c.fine.verdict.kind)
        << " on the refined one";
      if (!within) s << "; ";
    }
    if (!within) s << "the governing stress changes by more than " << 100 * c.tolerance << " %";
    s << " (refine the mesh, or judge the stress farther from the load)";
  }
  c.statement = s.str();
}

void not_established(MeshConvergence& c, const std::string& why) {
  c.established = false;
  c.holds = false;
  c.statement = "not established: " + why;
}

namespace {

nlohmann::json mesh_json(const ConvergenceMesh& m) {
  nlohmann::json j = {{"mesh_size_m", m.mesh_size_m},
                      {"load_mesh_size_m", m.load_mesh_size_m},
                      {"node_count", m.node_count},
                      {"tet_count", m.tet_count},
                      {"governing_von_mises_Pa", m.verdict.governing.von_mises_Pa},
                      {"governing_point_m", {m.verdict.governing.point_m.x(), m.verdict.governing.point_m.y(),
                                             m.verdict.governing.point_m.z()}},
                      {"governing_time_s", m.verdict.governing.time_s},
                      {"verdict", to_string(m.verdict.kind)},
                      {"safety_factor", nullptr},
                      {"solver_wall_time_s", m.solver_wall_time_s}};
  if (m.verdict.yield_strength_Pa) j["safety_factor"] = m.verdict.safety_factor;
  return j;
}

}  // namespace

nlohmann::json to_json(const MeshConvergence& c) {
  return {{"method", "two-meshes"},
          {"coarse", mesh_json(c.coarse)},
          {"fine", c.refined_ran ? mesh_json(c.fine) : nlohmann::json()},
          {"evaluation_radius_m", c.evaluation_radius_m},
          // JSON has no infinity: a change from a zero stress is null (and does not hold); so is
          // the change when the refined mesh did not run.
          {"relative_change", c.refined_ran && std::isfinite(c.relative_change) ? nlohmann::json(c.relative_change)
                                                                                 : nlohmann::json()},
          {"tolerance", c.tolerance},
          {"holds", c.holds},
          {"established", c.established},
          {"statement", c.statement},
          {"folder", c.folder.empty() ? nlohmann::json() : nlohmann::json(c.folder)}};
}

std::string format_convergence(const MeshConvergence& c) {
  std::ostringstream s;
  if (!c.refined_ran) {
    s << std::setprecision(4) << "governing von Mises " << c.coarse.verdict.governing.von_mises_Pa / 1e6 << " MPa (mesh "
      << c.coarse.mesh_size_m * 1e3 << " mm, " << c.coarse.node_count << " nodes); the verdict's convergence is "
      << c.statement;
    return s.str();
  }
  s << std::setprecision(4) << "governing von Mises " << c.coarse.verdict.governing.von_mises_Pa / 1e6
    << " MPa (mesh " << c.coarse.mesh_size_m * 1e3 << " mm, " << c.coarse.node_count << " nodes) -> "
    << c.fine.verdict.governing.von_mises_Pa / 1e6 << " MPa (mesh " << c.fine.mesh_size_m * 1e3 << " mm, "
    << c.fine.node_count << " nodes), outside " << c.evaluation_radius_m * 1e3 << " mm of the contact point, change "
    << std::showpos << std::setprecision(3) << 100 * c.relative_change << std::noshowpos << " %: the verdict "
    << c.statement;
  return s.str();
}

}  // namespace impactdeck::fem_export
