// first_contact on large parts: a meshed 3:2:1 ellipsoid (icosphere, 20*4^N triangles) dropped
// at an angle onto a floor, hit by an analytic sphere, and hit by a second meshed part, each
// from several directions. Plain timer; the index (MeshShape) is built once beforehand.
//   bench_first_contact [subdivisions=6 (81 920 triangles)] [repeats=5]
// Goal (issue 12): well under a second per call at 1e5-1e6 triangles.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/contact/first_contact.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/plane.hpp"

using namespace impactdeck::geometry;
using namespace impactdeck::contact;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Smallest of `repeats` timings of f (s).
template <class F>
double best_of(int repeats, F&& f) {
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    const auto t = Clock::now();
    f();
    best = std::min(best, since(t));
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 6;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  auto t = Clock::now();
  const TriangleMesh m = make_ellipsoid_mesh(0.3, 0.2, 0.1, n);
  const MeshMassProperties mass = compute_mass_properties(m, label_shells(m));
  const MeshShape part(m, mass), other(m, mass);
  std::printf("part: %zu triangles, index built in %.3f s (twice: %.3f s)\n", m.triangle_count(), since(t) / 2,
              since(t));

  const Plane floor(Eigen::Vector3d(0, 0, 1));
  const Ellipsoid ball = Ellipsoid::sphere(0.05);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g(0.0, 1.0);
  const int directions = 8;
  std::vector<double> on_floor, by_ball, by_part;
  for (int k = 0; k < directions; ++k) {
    Pose pp;
    pp.rotation = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    pp.position_m = {100, 200, 1.0};
    const Eigen::Vector3d down = Eigen::Vector3d(0.3 * g(rng), 0.3 * g(rng), -1).normalized();
    on_floor.push_back(best_of(repeats, [&] { first_contact({&floor, Pose()}, {&part, pp}, down); }));
    const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    Pose pb;
    pb.position_m = pp.position_m - 1.0 * d + 0.05 * d.unitOrthogonal();
    by_ball.push_back(best_of(repeats, [&] { first_contact({&part, pp}, {&ball, pb}, d); }));
    Pose po;
    po.rotation = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    po.position_m = pp.position_m - 1.0 * d + 0.1 * d.unitOrthogonal();
    by_part.push_back(best_of(repeats, [&] { first_contact({&part, pp}, {&other, po}, d); }));
  }
  auto report = [&](const char* what, std::vector<double> v) {
    std::sort(v.begin(), v.end());
    std::printf("%-34s median %8.3f ms, max %8.3f ms over %d directions\n", what, 1e3 * v[v.size() / 2],
                1e3 * v.back(), directions);
  };
  report("part dropped on a floor", on_floor);
  report("sphere onto the part", by_ball);
  report("part onto a second part", by_part);
  return 0;
}
