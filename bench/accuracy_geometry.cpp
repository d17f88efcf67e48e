// Generated geometry accuracy (issue #7 item 1): error of a meshed part against the analytic
// ellipsoid it approximates, and what each resolution costs, measured in this process.
//   (a) ellipsoid mesh resolution: make_ellipsoid_mesh(3:2:1, N), rotated and translated, written
//       as binary STL and read back through load_part (what a user's part goes through) ->
//       volume, inertia, centroid, principal-curvature and F_max errors, and load + index time;
//   (b) curvature neighbourhood size (MeshShapeOptions::curvature_rings) -> curvature error and
//       time per query.
// References are exact: the ellipsoid's volume 4/3 pi abc, inertia V/5 diag(b^2+c^2, ...),
// closed-form shape operator (geometry::Ellipsoid), and the same impact computed on the analytic
// ellipsoid. Times are medians of repeated runs. Usage: accuracy_geometry (Markdown on stdout).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/mesh_validation.hpp"
#include "impactdeck/geometry/part.hpp"

using namespace impactdeck;
using namespace impactdeck::geometry;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The part: ellipsoid 0.3 x 0.2 x 0.1 m (3:2:1), rotated and translated (kept within a metre of
// the origin so that STL's float32 coordinates, ~3e-8 m there, stay far below the errors shown).
const Eigen::Vector3d kAxes_m(0.3, 0.2, 0.1);
const Eigen::Vector3d kShift_m(0.5, -0.2, 0.7);
Eigen::Matrix3d rotation() {
  return (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) *
          Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

// Steel part and a steel ball (r = 20 mm) hitting it at 1 m/s along the inward normal.
constexpr double kDensity_kg_m3 = 7850.0;
constexpr double kBallRadius_m = 0.02;
constexpr double kSpeed_m_s = 1.0;
double effective_modulus() {
  collision::ElasticMaterial steel;
  steel.youngs_modulus_Pa = 2.05e11;
  steel.poisson_ratio = 0.3;
  return collision::effective_modulus_Pa(steel, steel, collision::ModulusConvention::hertz);
}

// 24 points: Fibonacci directions mapped onto the ellipsoid (its own frame).
std::vector<SurfacePoint> local_points(const Ellipsoid& e, int n = 24) {
  std::vector<SurfacePoint> pts;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) * 2.0 / n, r = std::sqrt(1 - z * z);
    const Eigen::Vector3d u(r * std::cos(golden * i), r * std::sin(golden * i), z);
    pts.push_back(e.closest_point(u.cwiseProduct(e.semi_axes_m())));
  }
  return pts;
}

double rel(double x, double ref) { return std::abs(x - ref) / std::abs(ref); }

// Max over k1 and k2 of |dk|/k at one point.
double curvature_error(const Curvature& got, const Curvature& exact) {
  return std::max(rel(got.k1_per_m, exact.k1_per_m), rel(got.k2_per_m, exact.k2_per_m));
}

// F_max of the ball hitting a free body (mass properties given) at `p` with outward normal `n`,
// elliptical Hertz contact from the body's curvature there.
double impact_max_force_N(double volume_m3, const Eigen::Vector3d& centroid_m, const Eigen::Matrix3d& inertia_per_density_m5,
                          const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Curvature& k, double E_star) {
  collision::RigidBody target, ball;
  target.mass_kg = kDensity_kg_m3 * volume_m3;
  target.inertia_kg_m2 = kDensity_kg_m3 * inertia_per_density_m5;
  target.center_of_mass_m = centroid_m;
  const double ball_volume = 4.0 / 3.0 * M_PI * std::pow(kBallRadius_m, 3);
  ball.mass_kg = kDensity_kg_m3 * ball_volume;
  ball.inertia_kg_m2 = Eigen::Matrix3d::Identity() * (0.4 * ball.mass_kg * kBallRadius_m * kBallRadius_m);
  ball.center_of_mass_m = p + kBallRadius_m * n;
  collision::Contact c;
  c.point_m = p;
  c.normal = n;
  const double mw = collision::reduced_mass_kg(target, ball, c);
  const double kb = 1.0 / kBallRadius_m;
  const auto rc = collision::relative_curvatures(k.k1_per_m, k.k2_per_m, k.d1, k.d2, kb, kb, k.d1, k.d2, n);
  const double R = collision::elliptical_contact(rc).equivalent_radius_m;
  return collision::solve_compression(mw, kSpeed_m_s, collision::hertz_constant(E_star, R)).max_force_N;
}

struct Reference {
  Ellipsoid e{kAxes_m.x(), kAxes_m.y(), kAxes_m.z()};
  Eigen::Matrix3d R = rotation();
  double volume_m3 = 0;
  Eigen::Matrix3d inertia_m5;  // per density, about the centroid, global axes
  std::vector<SurfacePoint> local;  // the 24 points in the ellipsoid's frame
  std::vector<Curvature> k;
  std::vector<double> fmax_N;
};

Reference make_reference(double E_star) {
  Reference r;
  const Eigen::Vector3d& a = kAxes_m;
  r.volume_m3 = 4.0 / 3.0 * M_PI * a.prod();
  const Eigen::Vector3d d(a.y() * a.y() + a.z() * a.z(), a.x() * a.x() + a.z() * a.z(), a.x() * a.x() + a.y() * a.y());
  r.inertia_m5 = r.R * Eigen::Matrix3d((r.volume_m3 / 5.0) * d.asDiagonal()) * r.R.transpose();
  r.local = local_points(r.e);
  for (const auto& sp : r.local) {
    Curvature k = r.e.curvature(sp);
    k.d1 = r.R * k.d1;
    k.d2 = r.R * k.d2;
    r.k.push_back(k);
    r.fmax_N.push_back(impact_max_force_N(r.volume_m3, kShift_m, r.inertia_m5, r.R * sp.point_m + kShift_m,
                                          r.R * sp.normal, k, E_star));
  }
  return r;
}

struct PointErrors {
  double curvature = 0, fmax = 0;
  int failed = 0;  // points where the mesh gave no curvature (sharp feature or too coarse)
};

PointErrors point_errors(const MeshShape& shape, const Reference& ref, double E_star) {
  PointErrors out;
  const VolumeProperties& v = shape.volume_properties();
  for (std::size_t i = 0; i < ref.local.size(); ++i) {
    const Eigen::Vector3d q = ref.R * ref.local[i].point_m + kShift_m;
    try {
      const SurfacePoint sp = shape.closest_point(q);
      const Curvature k = shape.curvature(sp);
      if (k.sharp_feature) { ++out.failed; continue; }
      out.curvature = std::max(out.curvature, curvature_error(k, ref.k[i]));
      const double f = impact_max_force_N(v.volume_m3, v.centroid_m, v.inertia_per_density_m5, sp.point_m, sp.normal, k, E_star);
      out.fmax = std::max(out.fmax, rel(f, ref.fmax_N[i]));
    } catch (const InputError&) {
      ++out.failed;
    }
  }
  return out;
}

TriangleMesh part_mesh(int subdivisions) {
  TriangleMesh m = make_ellipsoid_mesh(kAxes_m.x(), kAxes_m.y(), kAxes_m.z(), subdivisions);
  transform_mesh(m, rotation(), kShift_m);
  return m;
}

void resolution_section(const Reference& ref, double E_star) {
  std::printf("## Generated geometry: ellipsoid mesh resolution\n\n");
  std::printf("Part: `make_ellipsoid_mesh(0.3, 0.2, 0.1 m, N)` (3:2:1, 20·4^N triangles), rotated (two\n"
              "axis-angle rotations) and translated by (0.5, −0.2, 0.7) m, written as binary STL and read\n"
              "back with `load_part` (load, validation with the self-intersection test, mass properties,\n"
              "surface index). References exact: V = 4/3 π abc, inertia V/5 diag(b²+c², a²+c², a²+b²)\n"
              "rotated, centroid = the translation, principal curvatures of the closed-form shape operator\n"
              "at 24 points (Fibonacci directions mapped onto the surface), and F_max of a steel ball\n"
              "(r = 20 mm, 1 m/s, E = 205 GPa, ν = 0.3, Hertz E*) hitting the free steel part along the\n"
              "normal at each of those points, computed with the analytic ellipsoid's mass properties,\n"
              "normal and curvature tensor (elliptical Hertz contact) against the same computation with\n"
              "the mesh's. Inertia error: largest |ΔI_ij| over the nine components / largest exact moment;\n"
              "curvature error: max over points of |Δk|/k for k1 and k2; F_max error: max over points.\n"
              "Time: median of the `load_part` wall time (and its `curvature_index` stage) over repeats.\n\n");
  std::printf("| N | triangles | volume rel. error | inertia rel. error | centroid error / c | max curvature rel. error | max F_max rel. error | points without curvature | load_part, s | of which index, s | repeats |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  char tmpl[] = "/tmp/impactdeck_accuracy_geometry_XXXXXX";
  const char* dir = mkdtemp(tmpl);
  if (!dir) throw std::runtime_error("mkdtemp failed");
  for (int n = 2; n <= 6; ++n) {
    const auto file = std::filesystem::path(dir) / ("ellipsoid_" + std::to_string(n) + ".stl");
    write_stl_binary(file, part_mesh(n));
    const int repeats = n <= 4 ? 7 : (n == 5 ? 5 : 3);
    std::vector<double> total, index;
    Part part;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = Clock::now();
      Part p = load_part(file, PartOptions{});
      total.push_back(since(t0));
      double ix = 0;
      for (const auto& st : p.stages)
        if (st.name == "curvature_index") ix += st.seconds;
      index.push_back(ix);
      if (r + 1 == repeats) part = std::move(p);
    }
    const VolumeProperties& v = part.shape->volume_properties();
    const double inertia_err = (v.inertia_per_density_m5 - ref.inertia_m5).cwiseAbs().maxCoeff() / ref.inertia_m5.diagonal().maxCoeff();
    const double centroid_err = (v.centroid_m - kShift_m).norm() / kAxes_m.z();
    const PointErrors pe = point_errors(*part.shape, ref, E_star);
    std::printf("| %d | %zu | %.3e | %.3e | %.1e | %.3e | %.3e | %d / %zu | %.4f | %.4f | %d |\n", n,
                part.shape->mesh().triangle_count(), rel(v.volume_m3, ref.volume_m3), inertia_err, centroid_err,
                pe.curvature, pe.fmax, pe.failed, ref.local.size(), median(total), median(index), repeats);
    std::fflush(stdout);
    std::filesystem::remove(file);
  }
  std::filesystem::remove(dir);
  std::printf("\nThe STL stores float32 coordinates (relative round-off ~6e-8, ~4e-8 m here): below every\n"
              "error shown. Volume and inertia converge at order 2 (the inscribed polyhedron's O(h²)\n"
              "deficit: a factor ~4 per N); F_max ∝ R^(1/5) m_w^(3/5) is far less sensitive than the\n"
              "curvature it depends on.\n\n");
}

void neighbourhood_section(const Reference& ref, double E_star) {
  const int n = 5;
  const TriangleMesh mesh = part_mesh(n);
  const MeshMassProperties mass = compute_mass_properties(mesh, label_shells(mesh));
  std::printf("## Generated geometry: curvature neighbourhood size\n\n");
  std::printf("Same part at N = %d (%zu triangles), built in memory; `MeshShapeOptions::curvature_rings`\n"
              "(geodesic rings around the hit triangle's corners in the cubic jet fit; the error estimate\n"
              "refits with one ring more, so a query is three fits: lift, result, estimate). Error: max\n"
              "over the same 24 points of |Δk|/k (k1, k2) against the closed-form shape operator, and the\n"
              "F_max error as above. Time per query: `Shape::curvature` at a projected point, median over\n"
              "repeats of the 24-point loop.\n\n",
              n, mesh.triangle_count());
  std::printf("| rings | max curvature rel. error | max F_max rel. error | points without curvature | time per query, µs | repeats |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|\n");
  std::vector<SurfacePoint> at;
  for (int rings = 1; rings <= 5; ++rings) {
    MeshShapeOptions o;
    o.curvature_rings = rings;
    try {
      const MeshShape shape(mesh, mass, o);
      if (at.empty())
        for (const auto& sp : ref.local) at.push_back(shape.closest_point(ref.R * sp.point_m + kShift_m));
      const PointErrors pe = point_errors(shape, ref, E_star);
      const int repeats = 15;
      std::vector<double> per_query;
      double checksum = 0;
      for (int r = 0; r < repeats; ++r) {
        const auto t0 = Clock::now();
        for (const auto& sp : at) {
          try {
            checksum += shape.curvature(sp).k1_per_m;
          } catch (const InputError&) {
          }
        }
        per_query.push_back(since(t0) / static_cast<double>(at.size()));
      }
      std::printf("| %d | %.3e | %.3e | %d / %zu | %.1f | %d |\n", rings, pe.curvature, pe.fmax, pe.failed,
                  ref.local.size(), 1e6 * median(per_query), repeats);
      if (!std::isfinite(checksum)) std::printf("(non-finite curvature)\n");
    } catch (const InputError& e) {
      std::printf("| %d | fails: %s | | | | |\n", rings, e.reason().c_str());
    }
    std::fflush(stdout);
  }
  std::printf("\nThe default is 2 rings. A neighbourhood with fewer than 1.5× the jet's unknowns is widened\n"
              "ring by ring before the fit (MeshShape), so 1 ring runs as 2 on this mesh; wider\n"
              "neighbourhoods add model error of the cubic jet faster than they average out noise.\n\n");
}

}  // namespace

int main() {
  try {
    const double E_star = effective_modulus();
    const Reference ref = make_reference(E_star);
    resolution_section(ref, E_star);
    neighbourhood_section(ref, E_star);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accuracy_geometry: %s\n", e.what());
    return 1;
  }
  return 0;
}
