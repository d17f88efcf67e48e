// The Hertz-patch load (see patch_load.hpp).
#include "impactdeck/fem_export/patch_load.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::fem_export {
namespace {

constexpr double kPi = 3.14159265358979323846;
/// Sub-triangles per edge of each boundary triangle for the pressure integral (64 per triangle).
constexpr int kSubdivisions = 8;
/// Largest number of loaded nodes (Code_Aster group names LP1..LP9999 stay within 8 characters).
constexpr std::size_t kMaxLoadedNodes = 9999;

// Squared distance from the origin to the triangle (a, b, c) of the plane.
double dist2_origin_to_triangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  auto cross = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q) { return p.x() * q.y() - p.y() * q.x(); };
  const double s1 = cross(b - a, -a), s2 = cross(c - b, -b), s3 = cross(a - c, -c);
  if ((s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0)) return 0.0;
  auto seg = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    const Eigen::Vector2d e = q - p;
    const double l2 = e.squaredNorm();
    const double t = l2 > 0 ? std::clamp(-p.dot(e) / l2, 0.0, 1.0) : 0.0;
    return (p + t * e).squaredNorm();
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

// Quadrature points of one boundary triangle in the tangent plane: (u, v) and the weights
// dA N_k(u, v) of its three corners.
struct QuadPoint {
  double u, v;
  double w[3];
};

std::vector<QuadPoint> quadrature(const Eigen::Vector2d p[3]) {
  const double area = 0.5 * std::abs((p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x());
  const int n = kSubdivisions;
  const double sub = area / (n * n) / 3.0;  // 3 points per sub-triangle, equal weights
  std::vector<QuadPoint> q;
  q.reserve(3 * n * n);
  auto add_sub = [&](const Eigen::Vector3d& b0, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2) {
    // Degree-2 rule: barycentric (2/3, 1/6, 1/6) and permutations.
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d bk = k == 0 ? b0 : (k == 1 ? b1 : b2);
      const Eigen::Vector3d bl = k == 0 ? b1 : (k == 1 ? b2 : b0);
      const Eigen::Vector3d bm = k == 0 ? b2 : (k == 1 ? b0 : b1);
      const Eigen::Vector3d bar = (2.0 / 3.0) * bk + (1.0 / 6.0) * (bl + bm);
      const Eigen::Vector2d x = bar[0] * p[0] + bar[1] * p[1] + bar[2] * p[2];
      q.push_back({x.x(), x.y(), {sub * bar[0], sub * bar[1], sub * bar[2]}});
    }
  };
  auto B = [&](int i, int j) { return Eigen::Vector3d(1.0 - double(i + j) / n, double(i) / n, double(j) / n); };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; i + j < n; ++j) {
      add_sub(B(i, j), B(i + 1, j), B(i, j + 1));
      if (i + j < n - 1) add_sub(B(i + 1, j), B(i + 1, j + 1), B(i, j + 1));
    }
  }
  return q;
}

}  // namespace

PatchLoad hertz_patch_load(const TetMesh& mesh, int contact_node, const Eigen::Vector3d& direction,
                           const ContactPatch& patch, const collision::ForceTable& force,
                           const InputContext& ctx) {
  const std::string where = "hertz-patch load";
  if (!(patch.a_max_m > 0) || !(patch.b_max_m > 0) || !(patch.a_max_m >= patch.b_max_m) ||
      !std::isfinite(patch.a_max_m) || !(patch.max_force_N > 0) || !std::isfinite(patch.max_force_N)) {
    std::ostringstream m;
    m << "contact ellipse must have a_max >= b_max > 0 and a positive force (a_max " << patch.a_max_m
      << " m, b_max " << patch.b_max_m << " m, F " << patch.max_force_N << " N)";
    throw ctx.error(where, m.str());
  }
  if (contact_node < 0 || contact_node >= static_cast<int>(mesh.nodes_m.size())) {
    throw ctx.error(where, "contact node is not a node of the mesh");
  }
  const Eigen::Vector3d d = direction.normalized();
  Eigen::Vector3d ta = patch.axis_a - patch.axis_a.dot(d) * d;
  if (ta.norm() < 1e-9) ta = d.unitOrthogonal();
  ta.normalize();
  const Eigen::Vector3d tb = d.cross(ta);
  const Eigen::Vector3d c = mesh.nodes_m[contact_node];
  auto uv = [&](int node) {
    const Eigen::Vector3d r = mesh.nodes_m[node] - c;
    return Eigen::Vector2d(r.dot(ta), r.dot(tb));
  };

  // The boundary triangles the largest ellipse covers, reached from the contact node across edges.
  const std::vector<std::array<int, 3>> tris = boundary_triangles(mesh);
  std::map<std::pair<int, int>, std::vector<int>> edge_tris;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = tris[t][k], b = tris[t][(k + 1) % 3];
      edge_tris[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(t));
    }
  }
  auto facing = [&](int t) {
    const auto& f = tris[t];
    const Eigen::Vector3d n =
        (mesh.nodes_m[f[1]] - mesh.nodes_m[f[0]]).cross(mesh.nodes_m[f[2]] - mesh.nodes_m[f[0]]);
    return n.norm() > 0 && n.normalized().dot(d) < -0.5;
  };
  auto covered = [&](int t) {
    Eigen::Vector2d p[3];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d x = uv(tris[t][k]);
      p[k] = Eigen::Vector2d(x.x() / patch.a_max_m, x.y() / patch.b_max_m);
    }
    return dist2_origin_to_triangle(p[0], p[1], p[2]) < 1.0;
  };
  std::vector<char> seen(tris.size(), 0);
  std::vector<int> region, stack;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const auto& f = tris[t];
    if ((f[0] == contact_node || f[1] == contact_node || f[2] == contact_node) && facing(static_cast<int>(t))) {
      seen[t] = 1;
      stack.push_back(static_cast<int>(t));
    }
  }
  if (stack.empty()) throw ctx.error(where, "no boundary triangle faces the load at the contact node");
  while (!stack.empty()) {
    const int t = stack.back();
    stack.pop_back();
    region.push_back(t);
    for (int k = 0; k < 3; ++k) {
      const int a = tris[t][k], b = tris[t][(k + 1) % 3];
      for (int nb : edge_tris[{std::min(a, b), std::max(a, b)}]) {
        if (seen[nb]) continue;
        seen[nb] = 1;
        if (facing(nb) && covered(nb)) stack.push_back(nb);
      }
    }
  }
  std::sort(region.begin(), region.end());

  // Local numbering of the region's nodes (contact node first) and the quadrature.
  std::map<int, int> local;
  std::vector<int> nodes{contact_node};
  local[contact_node] = 0;
  double edge_sum = 0;
  std::vector<std::array<int, 3>> corner(region.size());
  std::vector<std::vector<QuadPoint>> quad(region.size());
  for (std::size_t r = 0; r < region.size(); ++r) {
    const auto& f = tris[region[r]];
    Eigen::Vector2d p[3];
    for (int k = 0; k < 3; ++k) {
      auto [it, added] = local.emplace(f[k], static_cast<int>(nodes.size()));
      if (added) nodes.push_back(f[k]);
      corner[r][k] = it->second;
      p[k] = uv(f[k]);
      edge_sum += (mesh.nodes_m[f[(k + 1) % 3]] - mesh.nodes_m[f[k]]).norm();
    }
    quad[r] = quadrature(p);
  }
  if (nodes.size() > kMaxLoadedNodes) {
    throw ctx.error(where, "the largest contact ellipse covers " + std::to_string(nodes.size()) +
                                    " surface nodes (at most 9999): lower contact_elements");
  }
  const std::size_t nn = nodes.size();
  std::vector<Eigen::Vector2d> node_uv(nn);
  for (std::size_t i = 0; i < nn; ++i) node_uv[i] = uv(nodes[i]);

  PatchLoad out;
  out.patch_triangles = region.size();
  out.largest_ellipse_elements = 2.0 * patch.b_max_m / (edge_sum / (3.0 * static_cast<double>(region.size())));
  out.time_s = force.time_s;
  const std::size_t nt = force.time_s.size();
  std::vector<std::vector<double>> w_all(nn, std::vector<double>(nt, 0.0));
  std::vector<double> q(nn);
  for (std::size_t k = 0; k < nt; ++k) {
    const double F = force.force_N[k];
    if (!(F > 0)) continue;
    const double s = std::cbrt(F / patch.max_force_N);
    const double a = s * patch.a_max_m, b = s * patch.b_max_m;
    const double p0 = collision::hertz_peak_pressure_Pa(F, a, b);
    std::fill(q.begin(), q.end(), 0.0);
    for (std::size_t r = 0; r < region.size(); ++r) {
      for (const QuadPoint& qp : quad[r]) {
        const double rho2 = (qp.u / a) * (qp.u / a) + (qp.v / b) * (qp.v / b);
        if (rho2 >= 1.0) continue;
        const double p = p0 * std::sqrt(1.0 - rho2);
        for (int m = 0; m < 3; ++m) q[corner[r][m]] += p * qp.w[m];
      }
    }
    // Tilt-correct so that the sum is F and the moment about c vanishes; drop nodes the tilt makes
    // negative and solve again; too few nodes left: the point load on the contact node.
    std::vector<double> w(nn, 0.0);
    bool ok = false;
    for (int iter = 0; iter < 6 && !ok; ++iter) {
      std::size_t support = 0;
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < nn; ++i) {
        if (!(q[i] > 0)) continue;
        ++support;
        const Eigen::Vector3d ai(1.0, node_uv[i].x() / a, node_uv[i].y() / b);
        H += q[i] * ai * ai.transpose();
        sum += q[i] * ai;
      }
      if (support < 3) break;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H);
      if (!(es.eigenvalues()[0] > 1e-10 * es.eigenvalues()[2])) break;
      const Eigen::Vector3d lambda = H.ldlt().solve(Eigen::Vector3d(F, 0, 0) - sum);
      bool negative = false;
      for (std::size_t i = 0; i < nn; ++i) {
        w[i] = 0;
        if (!(q[i] > 0)) continue;
        const Eigen::Vector3d ai(1.0, node_uv[i].x() / a, node_uv[i].y() / b);
        w[i] = q[i] * (1.0 + ai.dot(lambda));
        if (w[i] < 0) negative = true, q[i] = 0;
      }
      ok = !negative;
    }
    if (!ok) {
      std::fill(w.begin(), w.end(), 0.0);
      w[0] = F;
      ++out.point_load_samples;
    }
    std::size_t loaded = 0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    double total = 0;
    for (std::size_t i = 0; i < nn; ++i) {
      w_all[i][k] = w[i];
      if (w[i] != 0) ++loaded;
      total += w[i];
      moment += (mesh.nodes_m[nodes[i]] - c).cross(w[i] * d);
    }
    out.max_nodes_loaded_at_once = std::max(out.max_nodes_loaded_at_once, loaded);
    out.max_sum_relative_error = std::max(out.max_sum_relative_error, std::abs(total - F) / F);
    out.max_moment_relative = std::max(out.max_moment_relative, moment.norm() / (patch.max_force_N * patch.a_max_m));
  }
  // Keep the nodes that carry force at some time (the contact node always).
  for (std::size_t i = 0; i < nn; ++i) {
    const bool used = i == 0 || std::any_of(w_all[i].begin(), w_all[i].end(), [](double x) { return x != 0; });
    if (!used) continue;
    out.nodes.push_back(nodes[i]);
    out.force_N.push_back(std::move(w_all[i]));
  }
  return out;
}

}  // namespace impactdeck::fem_export
