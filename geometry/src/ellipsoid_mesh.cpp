#include "impactdeck/geometry/ellipsoid_mesh.hpp"

#include <cmath>
#include <map>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck::geometry {

TriangleMesh make_ellipsoid_mesh(double a, double b, double c, int subdivisions) {
  if (!(a > 0 && b > 0 && c > 0) || !std::isfinite(a * b * c)) {
    std::ostringstream s;
    s << "semi-axes must be positive and finite, got (" << a << ", " << b << ", " << c << ")";
    throw InputError("", "semi_axes", s.str());
  }
  if (subdivisions < 0 || subdivisions > 10) {
    throw InputError("", "subdivisions", "must lie in 0..10 (20·4^N triangles), got " +
                                             std::to_string(subdivisions));
  }
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, p, 0}, {1, p, 0},  {-1, -p, 0}, {1, -p, 0},
                                    {0, -1, p}, {0, 1, p},  {0, -1, -p}, {0, 1, -p},
                                    {p, 0, -1}, {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  for (auto& x : v) x.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int i, int j) {
      const auto key = std::minmax(i, j);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[i] + v[j]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> g;
    g.reserve(f.size() * 4);
    for (const auto& t : f) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      g.push_back({t[0], ab, ca});
      g.push_back({t[1], bc, ab});
      g.push_back({t[2], ca, bc});
      g.push_back({ab, bc, ca});
    }
    f.swap(g);
  }
  TriangleMesh m;
  m.vertices_m.reserve(v.size());
  const Eigen::Vector3d e(a, b, c);
  for (const auto& x : v) m.vertices_m.push_back(x.cwiseProduct(e));
  m.triangles = std::move(f);
  return m;
}

TriangleMesh make_unit_cube_mesh() {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices_m.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  // Two outward triangles per face.
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

void transform_mesh(TriangleMesh& mesh, const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  for (auto& v : mesh.vertices_m) v = r * v + t;
}

}  // namespace impactdeck::geometry
