#include "impactdeck/study/table1.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/study/cloud.hpp"

namespace impactdeck::study {

namespace {

const std::vector<double> kDecades = {1e-4, 1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3, 1e4};

// Quantities that cancel from the ratio (docs/table1.md); fixed, plausible values. Steel sphere of
// r = 50 mm at 1 m/s, the paper's Eq. 28 modulus.
constexpr double kSphereRadius_m = 0.05;
constexpr double kDensity_kg_m3 = 7850.0;
constexpr double kYoungs_Pa = 2.05e11;
constexpr double kSpeed_m_s = 1.0;

bool same_grid(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - b[i]) > 1e-12 * b[i]) return false;
  return true;
}

void check_ratios(const std::vector<double>& v, const char* what) {
  if (v.empty()) throw InputError("", what, "needs at least one value");
  for (double x : v) {
    if (!(x > 0.0) || !std::isfinite(x)) {
      std::ostringstream s;
      s << "every value must be positive and finite, got " << x;
      throw InputError("", what, s.str());
    }
  }
}

// Semi-axes of the target for a geometric ratio (see Table1Options::size_ratio).
Eigen::Vector3d semi_axes(double g, double size_ratio) {
  const double s = size_ratio * kSphereRadius_m;
  if (g >= 1.0) return {g * s, s, s};
  return {s, s / g, s / g};
}

// Axis-aligned bounding box of a mesh's vertices.
void bounding_box(const geometry::TriangleMesh& m, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = hi = m.vertices_m.front();
  for (const auto& v : m.vertices_m) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

// The cloud of a scene-driven row: the paper grid on a mesh is the projected grid of its box.
std::vector<geometry::SurfacePoint> scene_cloud(const geometry::Shape& t, const Table1Options& o,
                                                const InputContext& ctx) {
  const geometry::MeshShape* mesh = t.triangle_mesh();
  if (!mesh || (o.cloud != CloudKind::paper_grid && o.cloud != CloudKind::both)) {
    return make_cloud(t, o.cloud, o.grid_steps, o.uniform_count, o.seed, ctx);
  }
  Eigen::Vector3d lo, hi;
  bounding_box(mesh->mesh(), lo, hi);
  std::vector<geometry::SurfacePoint> cloud = projected_grid_cloud(t, lo, hi, o.grid_steps, ctx);
  if (o.cloud == CloudKind::both) {
    auto u = area_uniform_cloud(t, o.uniform_count, o.seed, ctx);
    cloud.insert(cloud.end(), u.begin(), u.end());
  }
  return cloud;
}

}  // namespace

std::shared_ptr<const geometry::Shape> stretched_target(const geometry::Shape& target, int axis, double g,
                                                        const InputContext& ctx) {
  if (axis < 0 || axis > 2) throw ctx.error("stretch axis", "must be 0 (x), 1 (y) or 2 (z)");
  if (!(g > 0.0) || !std::isfinite(g)) throw ctx.error("geometric ratio", "must be positive and finite");
  const int ref = (axis + 1) % 3;
  if (const geometry::Ellipsoid* e = target.analytic_ellipsoid()) {
    Eigen::Vector3d semi = e->semi_axes_m();
    semi[axis] = g * semi[ref];
    return std::make_shared<geometry::Ellipsoid>(semi.x(), semi.y(), semi.z(), ctx);
  }
  if (const geometry::MeshShape* m = target.triangle_mesh()) {
    geometry::TriangleMesh mesh = m->mesh();
    Eigen::Vector3d lo, hi;
    bounding_box(mesh, lo, hi);
    const Eigen::Vector3d half = 0.5 * (hi - lo);
    if (!(half[axis] > 0.0) || !(half[ref] > 0.0)) {
      throw ctx.error("stretch axis", "the part is flat along the stretch axis or the next axis");
    }
    // Affine stretch about the centroid (the body frame's origin stays where it was).
    const double factor = g * half[ref] / half[axis];
    const double c = m->volume_properties().centroid_m[axis];
    for (auto& v : mesh.vertices_m) v[axis] = c + factor * (v[axis] - c);
    const geometry::ShellLabels shells = geometry::label_shells(mesh);
    const geometry::MeshMassProperties mass = geometry::compute_mass_properties(mesh, shells);
    return std::make_shared<geometry::MeshShape>(std::move(mesh), mass, m->options());
  }
  throw ctx.error("target", "a " + target.kind() + " cannot be stretched (use an ellipsoid or a mesh)");
}

Table1Options table1_preset(const std::string& name) {
  if (name != "paper") {
    throw InputError("", "--preset", "unknown preset \"" + name + "\" (available: \"paper\")" + did_you_mean(name, {"paper"}));
  }
  Table1Options o;
  o.geometric_ratios = kDecades;
  o.mass_ratios = kDecades;
  o.size_ratio = 20.0;
  o.rule = collision::ContactRule::paper;
  o.cloud = CloudKind::paper_grid;
  o.grid_steps = 8;
  return o;
}

const PaperTable1& paper_table1() {
  // Table 1 of the seed paper as printed (shared/data/paper_table1.csv), transposed to rows g,
  // columns mu. Reference data for the comparison; nothing of it feeds the computation.
  static const PaperTable1 t = [] {
    PaperTable1 p;
    p.geometric_ratios = kDecades;
    p.mass_ratios = kDecades;
    const double by_mu[9][9] = {
        // g:  1e-4   1e-3   1e-2   1e-1  1   1e1    1e2    1e3    1e4
        {0.350, 0.350, 0.351, 0.381, 1, 0.378, 0.345, 0.344, 0.288},  // mu = 1e-4
        {0.351, 0.350, 0.351, 0.381, 1, 0.378, 0.345, 0.344, 0.288},  // 1e-3
        {0.352, 0.352, 0.352, 0.382, 1, 0.379, 0.346, 0.346, 0.288},  // 1e-2
        {0.367, 0.367, 0.367, 0.398, 1, 0.379, 0.361, 0.361, 0.288},  // 1e-1
        {0.482, 0.482, 0.483, 0.517, 1, 0.513, 0.476, 0.456, 0.288},  // 1
        {0.806, 0.806, 0.807, 0.829, 1, 0.821, 0.699, 0.456, 0.288},  // 1e1
        {0.973, 0.973, 0.973, 0.976, 1, 0.922, 0.699, 0.456, 0.288},  // 1e2
        {0.997, 0.997, 0.997, 0.996, 1, 0.922, 0.699, 0.456, 0.288},  // 1e3
        {0.999, 0.999, 0.999, 0.997, 1, 0.922, 0.699, 0.456, 0.288},  // 1e4
    };
    p.ratio.assign(9, std::vector<double>(9));
    for (int g = 0; g < 9; ++g)
      for (int m = 0; m < 9; ++m) p.ratio[g][m] = by_mu[m][g];
    return p;
  }();
  return t;
}

Table1Result run_table1(const Table1Options& o) {
  check_ratios(o.geometric_ratios, "geometric ratios");
  check_ratios(o.mass_ratios, "mass ratios");
  if (!(o.size_ratio > 0.0) || !std::isfinite(o.size_ratio)) {
    throw InputError("", "size ratio", "must be positive and finite");
  }
  if (o.scene) {
    const Table1Scene& sc = *o.scene;
    const double mi = sc.setup.impactor.mass_kg;
    if (!(mi > 0.0) || !std::isfinite(mi)) {
      throw InputError(sc.source, "impactor '" + sc.impactor + "'",
                       "is fixed (infinite mass): the mass ratio target/impactor needs a finite impactor mass");
    }
    if (sc.stretch_axis < 0 || sc.stretch_axis > 2) {
      throw InputError(sc.source, "stretch axis", "must be x, y or z");
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  Table1Result res;
  res.options = o;
  res.options.progress = nullptr;
  const std::size_t ng = o.geometric_ratios.size(), nm = o.mass_ratios.size();
  res.ratio.assign(ng, std::vector<double>(nm));
  res.mass_only.assign(ng, std::vector<double>(nm));

  const double r = kSphereRadius_m;
  auto sphere = std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(r));
  const geometry::VolumeProperties sv = sphere->volume_properties();
  const double m2 = kDensity_kg_m3 * sv.volume_m3;

  // Clouds first (the per-cell count is needed for the progress total).
  std::vector<std::shared_ptr<const geometry::Shape>> targets;
  std::vector<std::vector<geometry::SurfacePoint>> clouds;
  std::size_t total = 0;
  for (double g : o.geometric_ratios) {
    std::shared_ptr<const geometry::Shape> target;
    std::vector<geometry::SurfacePoint> cloud;
    if (o.scene) {
      std::ostringstream place;
      place << "target '" << o.scene->target << "' stretched to g = " << g;
      const InputContext ctx{o.scene->source, place.str()};
      target = stretched_target(*o.scene->setup.target.shape, o.scene->stretch_axis, g, ctx);
      cloud = scene_cloud(*target, o, ctx);
    } else {
      const Eigen::Vector3d e = semi_axes(g, o.size_ratio);
      target = std::make_shared<geometry::Ellipsoid>(e.x(), e.y(), e.z());
      cloud = make_cloud(*target, o.cloud, o.grid_steps, o.uniform_count, o.seed);
    }
    total += cloud.size() * nm;
    targets.push_back(std::move(target));
    clouds.push_back(std::move(cloud));
  }
  res.points_per_cell = clouds.front().size();
  res.sharp_points.assign(ng, 0);
  res.flagged_points.assign(ng, 0);

  std::size_t done_before = 0;
  for (std::size_t gi = 0; gi < ng; ++gi) {
    for (std::size_t mi = 0; mi < nm; ++mi) {
      SweepSetup s;
      if (o.scene) {
        s = o.scene->setup;  // impactor, materials, speed, contact rule
      } else {
        s.impactor = contact::body_of_mass("sphere", sphere, m2);
        s.rule = o.rule;  // "paper": Eq. 26 on the ellipsoid, the sphere's own radius r exactly
        s.effective_modulus_Pa = collision::effective_modulus_Pa(
            {kYoungs_Pa, 0.3}, {kYoungs_Pa, 0.3}, collision::ModulusConvention::paper);
        s.approach_speed_m_s = kSpeed_m_s;
      }
      // F_max does not depend on the restitution: none is evaluated (a scene's energy-flux model
      // with range policy "error" would otherwise fail at extreme mass ratios for nothing).
      s.restitution = collision::RestitutionModel{};
      s.restitution.kind = collision::RestitutionModel::Kind::constant;
      s.restitution.constant = 1.0;
      const double m1 = o.mass_ratios[mi] * s.impactor.mass_kg;
      const std::string name = o.scene ? s.target.name : std::string("ellipsoid");
      s.target = contact::body_of_mass(name, targets[gi], m1, s.target.material);
      SweepOptions so;
      so.threads = o.threads;
      if (o.progress) {
        so.progress = [&](std::size_t done, std::size_t) { o.progress(done_before + done, total); };
      }
      // run_sweep's errors name the scene and the cell (the paper's setting: no file).
      s.context = {};
      if (o.scene) {
        std::ostringstream place;
        place << "cell g = " << o.geometric_ratios[gi] << ", mu = " << o.mass_ratios[mi];
        s.context = {o.scene->source, place.str()};
      }
      const SweepResult sr = run_sweep(s, clouds[gi], so);
      done_before += clouds[gi].size();
      res.ratio[gi][mi] = sr.force_ratio;
      res.mass_only[gi][mi] = sr.mass_only_ratio;
      res.sharp_points[gi] = sr.sharp_count;
      res.flagged_points[gi] = sr.flagged_count;
    }
  }

  // Comparison with the paper, when the grid is the paper's.
  const PaperTable1& p = paper_table1();
  if (!o.scene && same_grid(o.geometric_ratios, p.geometric_ratios) && same_grid(o.mass_ratios, p.mass_ratios)) {
    res.compared = true;
    res.paper = p.ratio;
    res.delta.assign(ng, std::vector<double>(nm));
    double sum = 0.0;
    for (std::size_t gi = 0; gi < ng; ++gi) {
      for (std::size_t mi = 0; mi < nm; ++mi) {
        res.delta[gi][mi] = res.ratio[gi][mi] - p.ratio[gi][mi];
        const double g = o.geometric_ratios[gi], mu = o.mass_ratios[mi];
        if (g == 1.0) continue;
        if (g == kExcludedGeometricRatio && mu == kExcludedMassRatio) {
          res.excluded_cell_model = res.ratio[gi][mi];
          res.excluded_cell_paper = p.ratio[gi][mi];
          continue;
        }
        const double a = std::abs(res.delta[gi][mi]);
        sum += a;
        res.max_abs_delta = std::max(res.max_abs_delta, a);
        ++res.cells_compared;
      }
    }
    res.mean_abs_delta = sum / static_cast<double>(res.cells_compared);
  }

  // Analytic limit (Eq. 39-41): the paper's Case 2 through the core, and Eq. 40 itself.
  const double expo = collision::kHertzExponent / (collision::kHertzExponent + 1.0);
  const std::size_t gmax = static_cast<std::size_t>(
      std::max_element(o.geometric_ratios.begin(), o.geometric_ratios.end()) - o.geometric_ratios.begin());
  res.limit_row_geometric_ratio = o.geometric_ratios[gmax];
  for (std::size_t mi = 0; mi < nm; ++mi) {
    LimitCheckRow row;
    const double mu = o.mass_ratios[mi];
    row.mass_ratio = mu;
    row.eq40 = std::pow((1.0 + mu) / (6.0 + mu), expo);
    // Case 2 (Fig. 10): slender spheroid g = 1e4, mass m = mu m2, hit perpendicular to its axis at
    // its end point, against the central hit; the same k_H in both, so F ~ m_w^(n/(n+1)).
    const double b = 1.0, a = 1e4 * b, m = mu * m2;
    collision::RigidBody rod;
    rod.mass_kg = m;
    rod.inertia_kg_m2 = (m / 5.0) * Eigen::Vector3d(2 * b * b, a * a + b * b, a * a + b * b).asDiagonal();
    collision::RigidBody ball;
    ball.mass_kg = m2;
    ball.inertia_kg_m2 = 0.4 * m2 * r * r * Eigen::Matrix3d::Identity();
    collision::Contact end, centre;
    end.point_m = {a, 0, 0};
    end.normal = {0, 1, 0};
    centre.point_m = {0, b, 0};
    centre.normal = {0, 1, 0};
    ball.center_of_mass_m = end.point_m + r * end.normal;
    const double mw_end = collision::reduced_mass_kg(rod, ball, end);
    ball.center_of_mass_m = centre.point_m + r * centre.normal;
    const double mw_centre = collision::reduced_mass_kg(rod, ball, centre);
    row.case2_core = std::pow(mw_end / mw_centre, expo);
    row.cloud_mass_only = res.mass_only[gmax][mi];
    row.cloud_ratio = res.ratio[gmax][mi];
    res.limit_check.push_back(row);
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace impactdeck::study
