// Placed bodies, planes, first contact and the new impact keys through the whole scene pipeline,
// against quantities computed independently in the test (closed forms in world coordinates).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::scene;
using namespace impactdeck::contact;
namespace fs = std::filesystem;

namespace {

std::string num(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

std::string vec(const Eigen::Vector3d& v) {
  char b[200];
  std::snprintf(b, sizeof b, "[%.17g, %.17g, %.17g]", v.x(), v.y(), v.z());
  return b;
}

void expect_error(const std::string& text, const std::string& re) {
  try {
    run_scene(parse_scene(text, "bad.toml"));
    FAIL() << "no error; expected /" << re << "/";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected /" << re << "/";
  }
}

const char* kMaterials = R"(length_unit = "m"
[materials.steel]
youngs_modulus_Pa = 2.0e11
poisson_ratio = 0.3
density_kg_m3 = 7800
yield_strength_Pa = 3.5e8
)";

// An ellipsoid (a, b, c) rotated by `axis`/`angle` and placed at `p`, falling with velocity v and
// spinning with w, dropped on the floor z = floor_z.
std::string drop_scene(const Eigen::Vector3d& semi, const Eigen::Vector3d& p, const Eigen::Vector3d& axis,
                       double angle_deg, const Eigen::Vector3d& v, const Eigen::Vector3d& w, double floor_z) {
  return std::string(kMaterials) + "[[bodies]]\nname = \"part\"\nshape = \"ellipsoid\"\nsemi_axes = " + vec(semi) +
         "\nmaterial = \"steel\"\nposition = " + vec(p) + "\norientation_axis = " + vec(axis) +
         "\norientation_angle_deg = " + num(angle_deg) + "\nvelocity_m_s = " + vec(v) +
         "\nangular_velocity_rad_s = " + vec(w) +
         "\n[[bodies]]\nname = \"floor\"\nshape = \"plane\"\nnormal = [0, 0, 1]\nmaterial = \"steel\"\nposition = " +
         vec({0, 0, floor_z}) +
         "\n[[impacts]]\nname = \"drop\"\ntarget = \"part\"\nimpactor = \"floor\"\npoint = \"first-contact\"\n"
         "restitution = 0.5\n";
}

}  // namespace

TEST(Placed, RotatedEllipsoidDroppedOnAFloorAgainstClosedForms) {
  const Eigen::Vector3d semi(0.2, 0.05, 0.08), p(1e3, -2e3, 0.5), axis(1, 2, 0.5);
  const double angle = 37.0;
  const Eigen::Vector3d v(0.3, -0.2, -4.0), w(1.0, -2.0, 0.5);
  const double floor_z = 0.1;
  const RunReport rep = run_scene(parse_scene(drop_scene(semi, p, axis, angle, v, w, floor_z), "drop.toml"));
  const ImpactReport& ir = rep.impacts.at(0);

  // Independent reference: support point c + M d / sqrt(d^T M d), M = R diag(a^2, b^2, c^2) R^T.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  const Eigen::Matrix3d M = R * semi.cwiseProduct(semi).asDiagonal() * R.transpose();
  const Eigen::Vector3d d(0, 0, -1);
  const Eigen::Vector3d support = p + M * d / std::sqrt(d.dot(M * d));
  EXPECT_LT((ir.contact.point_m - support).norm(), 1e-12 * semi.maxCoeff()) << ir.contact.point_m.transpose();
  EXPECT_LT((ir.contact.normal - d).norm(), 1e-12);
  // The floor moves along the relative velocity u = 0 - v until it touches: the gap over u's
  // vertical share.
  const double travel = (support.z() - floor_z) * v.norm() / -v.z();
  EXPECT_NEAR(ir.contact.travel_m, travel, 1e-12);

  // Reduced mass against the fixed floor: 1/m + (r x n)^T I^-1 (r x n), I = R I0 R^T.
  const double m = 7800 * 4.0 / 3.0 * M_PI * semi.prod();
  const Eigen::Vector3d I0 = m / 5.0 * Eigen::Vector3d(semi.y() * semi.y() + semi.z() * semi.z(),
                                                       semi.x() * semi.x() + semi.z() * semi.z(),
                                                       semi.x() * semi.x() + semi.y() * semi.y());
  const Eigen::Matrix3d I = R * I0.asDiagonal() * R.transpose();
  const Eigen::Vector3d r = support - p, rxn = r.cross(d);
  const double mw = 1.0 / (1.0 / m + rxn.dot(I.inverse() * rxn));
  EXPECT_NEAR(ir.result.reduced_mass_kg, mw, 1e-12 * mw);
  // Approach speed includes the spin: v_w = -n . (0 - (v + w x r)).
  const double vw = d.dot(v + w.cross(r));
  EXPECT_NEAR(ir.result.approach_velocity_m_s, vw, 1e-12 * vw);
  // Jumps: dv = -Pi n / m, dw = I^-1 (r x -Pi n), Pi = (1 + R) m_w v_w.
  const double Pi = 1.5 * mw * vw;
  EXPECT_LT((ir.result.target_jump.delta_velocity_m_s + Pi * d / m).norm(), 1e-12 * Pi / m);
  const Eigen::Vector3d dw = I.inverse() * r.cross(-Pi * d);
  EXPECT_LT((ir.result.target_jump.delta_angular_velocity_rad_s - dw).norm(), 1e-10 * dw.norm());
  EXPECT_EQ(ir.result.impactor_jump.delta_velocity_m_s.norm(), 0.0);  // the floor does not move
  EXPECT_TRUE(rep.all_checks_passed());

  // JSON: world vectors, travel, lever arms, validity with the yield check.
  const nlohmann::json j = to_json(parse_scene(drop_scene(semi, p, axis, angle, v, w, floor_z), "drop.toml"), rep);
  const auto& ji = j["impacts"][0];
  EXPECT_EQ(ji["contact_mode"], "first-contact");
  EXPECT_NEAR(ji["travel_m"].get<double>(), travel, 1e-12);
  EXPECT_NEAR(ji["target"]["lever_arm_m"][2].get<double>(), r.z(), 1e-12);
  EXPECT_EQ(ji["target"]["name"], "part");
  EXPECT_EQ(ji["impactor"]["name"], "floor");
  EXPECT_TRUE(ji["validity"].contains("peak_pressure_Pa"));
  EXPECT_NEAR(ji["validity"]["yield_onset_pressure_Pa"].get<double>(), 1.6 * 3.5e8, 1.0);
}

TEST(Placed, MovingTheWholeSceneChangesNoScalarAndRotatesEveryVector) {
  // The paper's point-mode impact, and the same with target and impactor rotated and moved
  // together (velocities rotated too): the same numbers, vectors rotated.
  const std::string base = std::string(kMaterials) + R"([[bodies]]
name = "target"
shape = "ellipsoid"
semi_axes = [2, 0.5, 0.4]
material = "steel"
PLACE
[[bodies]]
name = "ball"
shape = "ellipsoid"
semi_axes = [0.05, 0.03, 0.04]
material = "steel"
VELOCITY
IMPACTOR_ORIENTATION
[[impacts]]
target = "target"
impactor = "ball"
point = [1.2, 0.35, 0.1]
restitution = 0.7
)";
  auto make = [&](const std::string& place, const std::string& vel, const std::string& orient) {
    std::string s = base;
    s.replace(s.find("PLACE"), 5, place);
    s.replace(s.find("VELOCITY"), 8, vel);
    s.replace(s.find("IMPACTOR_ORIENTATION"), 20, orient);
    return run_scene(parse_scene(s, "m.toml"));
  };
  const Eigen::Vector3d axis(0.3, -1, 2);
  const double angle = 71.0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  const Eigen::Vector3d v0(0.5, -3, -1);
  const RunReport a = make("", "velocity_m_s = " + vec(v0), "orientation_axis = [0, 0, 1]\norientation_angle_deg = 0");
  const RunReport b = make("position = [5e3, -7e3, 2e3]\norientation_axis = " + vec(axis) +
                               "\norientation_angle_deg = " + std::to_string(angle),
                           "velocity_m_s = " + vec(R * v0),
                           "orientation_axis = " + vec(axis) + "\norientation_angle_deg = " + std::to_string(angle));
  const auto &ra = a.impacts[0].result, &rb = b.impacts[0].result;
  for (auto [x, y] : {std::pair{ra.reduced_mass_kg, rb.reduced_mass_kg}, {ra.effective_radius_m, rb.effective_radius_m},
                      {ra.history.compression.max_force_N, rb.history.compression.max_force_N},
                      {ra.history.contact_time_s(), rb.history.contact_time_s()}}) {
    EXPECT_NEAR(y, x, 1e-9 * std::abs(x));
  }
  EXPECT_LT((b.impacts[0].contact.normal - R * a.impacts[0].contact.normal).norm(), 1e-12);
  EXPECT_LT((rb.target_jump.delta_angular_velocity_rad_s - R * ra.target_jump.delta_angular_velocity_rad_s).norm(),
            1e-9 * ra.target_jump.delta_angular_velocity_rad_s.norm());
  // The ellipsoidal impactor touches with its support point: its lever arm is not along n.
  const Eigen::Vector3d arm = a.impacts[0].contact.input.impactor.lever_arm_m;
  EXPECT_GT(arm.cross(a.impacts[0].contact.normal).norm(), 1e-3 * arm.norm());
  EXPECT_GT(ra.impactor_jump.delta_angular_velocity_rad_s.norm(), 0.0);  // both bodies eccentric
}

TEST(Placed, PaperRuleGivesASphereItsRadius) {
  // An off-axis hit: the ball touches at a point that is not on its axes; its radius is still r.
  const std::string s = std::string(kMaterials) + R"([[bodies]]
name = "target"
shape = "ellipsoid"
semi_axes = [2, 0.5, 0.5]
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 0.05
material = "steel"
velocity_m_s = [0, -1, 0]
[[impacts]]
target = "target"
impactor = "ball"
point = [1.5, 0.3, 0.2]
contact_radius = "paper"
)";
  const RunReport r = run_scene(parse_scene(s, "p.toml"));
  EXPECT_DOUBLE_EQ(r.impacts[0].contact.input.impactor.curvature.paper_curvature_per_m, 20.0);
}

TEST(Placed, RestitutionTableFromTheScene) {
  const std::string s = std::string(kMaterials) + R"([[bodies]]
name = "target"
shape = "sphere"
radius = 0.5
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 0.05
material = "steel"
velocity_m_s = [0, -2, 0]
[[impacts]]
target = "target"
impactor = "ball"
point = [0, 0.5, 0]
restitution = { approach_speed_m_s = [1, 3], value = [0.8, 0.6] }
)";
  const RunReport r = run_scene(parse_scene(s, "t.toml"));
  EXPECT_NEAR(r.impacts[0].result.restitution.coefficient, 0.7, 1e-12);
  const nlohmann::json j = to_json(parse_scene(s, "t.toml"), r);
  EXPECT_EQ(j["impacts"][0]["restitution_model"], "table");
}

TEST(Placed, TheFastPaperSampleWarnsAboutValidity) {
  const Scene sc = load_scene(std::string(IMPACTDECK_SOURCE_DIR) + "/samples/paper_table2.toml");
  const RunReport r = run_scene(sc);
  EXPECT_FALSE(r.impacts[0].validity.ok);
  bool indentation = false, patch = false;
  for (const auto& w : r.warnings) {
    indentation = indentation || w.find("max indentation") != std::string::npos;
    patch = patch || w.find("contact ellipse semi-axis") != std::string::npos;
  }
  EXPECT_TRUE(indentation && patch);
  EXPECT_GT(r.impacts[0].validity.indentation_over_radius, 0.25);
}

TEST(Placed, BadInputsNameTheKey) {
  const Eigen::Vector3d semi(0.2, 0.05, 0.08);
  // The bodies never meet: the part moves away from the floor.
  expect_error(drop_scene(semi, {0, 0, 1}, {0, 0, 1}, 0, {0, 0, 3}, {0, 0, 0}, 0.0),
               R"(bad\.toml: line \d+, key 'impacts\[0\]\.point': impact 'drop': first contact of 'floor' with 'part': .*never touch)");
  // They already overlap: the floor cuts the part.
  expect_error(drop_scene(semi, {0, 0, 0.01}, {0, 0, 1}, 0, {0, 0, -3}, {0, 0, 0}, 0.0),
               R"(impact 'drop': first contact of 'floor' with 'part': .*already overlap)");
  std::string zero_normal = drop_scene(semi, {0, 0, 1}, {0, 0, 1}, 0, {0, 0, -3}, {0, 0, 0}, 0.0);
  zero_normal.replace(zero_normal.find("normal = [0, 0, 1]"), 18, "normal = [0, 0, 0]");
  expect_error(zero_normal, R"(bad\.toml: line \d+, key 'bodies\[1\]\.normal': must be a non-zero vector)");
  expect_error(drop_scene(semi, {0, 0, 1}, {0, 0, 0}, 30, {0, 0, -3}, {0, 0, 0}, 0.0),
               R"(key 'bodies\[0\]\.orientation_axis': must have a non-zero length)");
  std::string table = drop_scene(semi, {0, 0, 1}, {0, 0, 1}, 0, {0, 0, -3}, {0, 0, 0}, 0.0);
  table.replace(table.find("restitution = 0.5"), 17,
                "restitution = { approach_speed_m_s = [1, 3, 2], value = [0.8, 0.6, 0.5] }");
  expect_error(table, R"(key 'impacts\[0\]\.restitution': approach_speed_m_s must be strictly increasing: element 2)");
  std::string moving_plane = drop_scene(semi, {0, 0, 1}, {0, 0, 1}, 0, {0, 0, -3}, {0, 0, 0}, 0.0);
  moving_plane.replace(moving_plane.find("normal = [0, 0, 1]"), 18, "normal = [0, 0, 1]\nvelocity_m_s = [0, 0, 1]");
  expect_error(moving_plane, R"(key 'bodies\[1\]\.velocity_m_s': a plane is fixed)");
  // A concave-hit error names the point, the curvatures and the reason.
  expect_error(std::string(kMaterials) + R"([[bodies]]
name = "floor"
shape = "plane"
normal = [0, 0, 1]
material = "steel"
[[bodies]]
name = "wall"
shape = "plane"
normal = [0, 0, -1]
material = "steel"
[[impacts]]
target = "floor"
impactor = "wall"
point = [0, 0, 0]
)",
               R"(both bodies are fixed)");
}

namespace {

// Support function and point of an ellipsoid centred at c with M = R diag(a^2, b^2, c^2) R^T.
struct PlacedEllipsoid {
  Eigen::Vector3d c;
  Eigen::Matrix3d M;
  double h(const Eigen::Vector3d& u) const { return c.dot(u) + std::sqrt(u.dot(M * u)); }
  Eigen::Vector3d p(const Eigen::Vector3d& u) const { return c + M * u / std::sqrt(u.dot(M * u)); }
};

// First contact of `mover` translating along unit d into `target`, by the last separating plane:
// the entry of the ray s d into D = T - I is s* = max over u (d.u < 0) of h_D(u)/(d.u), with
// h_D(u) = h_T(u) + h_I(-u). With u = -d + x e1 + y e2 this is min over (x, y) of the convex
// h_D(u), whose gradient in u is p_T(u) - p_I(-u): Newton on the 2-D gradient (Hessian by central
// differences of the exact gradient). Written independently of contact::first_contact.
struct SeparatingPlane {
  Eigen::Vector3d normal, point;
  double travel;
};
SeparatingPlane last_separating_plane(const PlacedEllipsoid& T, const PlacedEllipsoid& I, const Eigen::Vector3d& d) {
  const Eigen::Vector3d e1 = d.unitOrthogonal(), e2 = d.cross(e1);
  auto grad = [&](const Eigen::Vector2d& q) {
    const Eigen::Vector3d u = -d + q.x() * e1 + q.y() * e2;
    const Eigen::Vector3d g = T.p(u) - I.p(-u);
    return Eigen::Vector2d(g.dot(e1), g.dot(e2));
  };
  auto value = [&](const Eigen::Vector2d& q) {
    const Eigen::Vector3d u = -d + q.x() * e1 + q.y() * e2;
    return T.h(u) + I.h(-u);
  };
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
  for (int it = 0; it < 200; ++it) {
    const Eigen::Vector2d g = grad(q);
    Eigen::Matrix2d H;
    const double eps = 1e-6 * (1.0 + q.norm());
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d dq = Eigen::Vector2d::Zero();
      dq[k] = eps;
      H.col(k) = (grad(q + dq) - grad(q - dq)) / (2 * eps);
    }
    Eigen::Vector2d step = H.ldlt().solve(-g);
    if (!step.allFinite() || step.dot(g) >= 0) step = -g;  // not a descent direction: gradient
    // Backtracking on the convex objective itself (Newton alone can overshoot far from the minimum).
    const double f0 = value(q);
    double t = 1.0;
    while (t > 1e-12 && value(q + t * step) > f0 + 1e-4 * t * g.dot(step)) t *= 0.5;
    const Eigen::Vector2d next = q + t * step;
    if ((next - q).norm() <= 1e-16 * (1.0 + q.norm())) break;
    q = next;
  }
  const Eigen::Vector3d u = (-d + q.x() * e1 + q.y() * e2).normalized();
  SeparatingPlane s;
  s.normal = u;
  s.point = T.p(u);
  s.travel = (T.p(u) - I.p(-u)).dot(d);
  return s;
}

std::string ellipsoid_body(const std::string& name, const Eigen::Vector3d& semi, const Eigen::Vector3d& p,
                           const Eigen::Vector3d& axis, double angle_deg, const Eigen::Vector3d& v,
                           const Eigen::Vector3d& w) {
  return "[[bodies]]\nname = \"" + name + "\"\nshape = \"ellipsoid\"\nsemi_axes = " + vec(semi) +
         "\nmaterial = \"steel\"\nposition = " + vec(p) + "\norientation_axis = " + vec(axis) +
         "\norientation_angle_deg = " + num(angle_deg) + "\nvelocity_m_s = " + vec(v) +
         "\nangular_velocity_rad_s = " + vec(w) + "\n";
}

}  // namespace

TEST(Placed, TwoFreeSpinningEllipsoidsAgainstTheLastSeparatingPlane) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int cases = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector3d sa(0.3 + 0.2 * u(rng), 0.12 + 0.05 * u(rng), 0.08 + 0.03 * u(rng));
    const Eigen::Vector3d sb(0.1 + 0.05 * u(rng), 0.07 + 0.03 * u(rng), 0.05 + 0.02 * u(rng));
    const Eigen::Vector3d ax_a(u(rng), u(rng), u(rng)), ax_b(u(rng), u(rng), u(rng));
    const double ang_a = 180 * u(rng), ang_b = 180 * u(rng);
    const Eigen::Vector3d pa(4e3 + u(rng), -3e3 + u(rng), 2e3 + u(rng));  // far from the origin
    const Eigen::Vector3d pb = pa + Eigen::Vector3d(1.5, 0.1 * u(rng), 0.1 * u(rng));
    const Eigen::Vector3d va(0.5 * u(rng), 0.3 * u(rng), 0.3 * u(rng)), vb(-4 + 0.5 * u(rng), 0.2 * u(rng), 0.2 * u(rng));
    const Eigen::Vector3d wa(3 * u(rng), 3 * u(rng), 3 * u(rng)), wb(5 * u(rng), 5 * u(rng), 5 * u(rng));
    const std::string text = std::string(kMaterials) + ellipsoid_body("a", sa, pa, ax_a, ang_a, va, wa) +
                             ellipsoid_body("b", sb, pb, ax_b, ang_b, vb, wb) +
                             "[[impacts]]\nname = \"pair\"\ntarget = \"a\"\nimpactor = \"b\"\npoint = \"first-contact\"\n"
                             "restitution = 0.55\n";
    // The reference, from the placements alone.
    auto placed = [](const Eigen::Vector3d& semi, const Eigen::Vector3d& p, const Eigen::Vector3d& axis, double deg) {
      const Eigen::Matrix3d R = Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
      return std::pair{PlacedEllipsoid{p, R * semi.cwiseProduct(semi).asDiagonal() * R.transpose()}, R};
    };
    const auto [A, Ra] = placed(sa, pa, ax_a, ang_a);
    const auto [B, Rb] = placed(sb, pb, ax_b, ang_b);
    const Eigen::Vector3d d = (vb - va).normalized();
    // Both bodies shifted by -pa (D = T - I does not change): the reference's sums stay small.
    SeparatingPlane sp = last_separating_plane({A.c - pa, A.M}, {B.c - pa, B.M}, d);
    sp.point += pa;
    if (!(sp.travel > 0)) continue;  // this placement misses: the run must say so (checked below)
    auto inertia = [](const Eigen::Vector3d& semi, const Eigen::Matrix3d& R, double m) {
      const Eigen::Vector3d I0 = m / 5.0 * Eigen::Vector3d(semi.y() * semi.y() + semi.z() * semi.z(),
                                                           semi.x() * semi.x() + semi.z() * semi.z(),
                                                           semi.x() * semi.x() + semi.y() * semi.y());
      return Eigen::Matrix3d(R * I0.asDiagonal() * R.transpose());
    };
    const double ma = 7800 * 4.0 / 3.0 * M_PI * sa.prod(), mb = 7800 * 4.0 / 3.0 * M_PI * sb.prod();
    const Eigen::Matrix3d Ia = inertia(sa, Ra, ma), Ib = inertia(sb, Rb, mb);
    const Eigen::Vector3d n = sp.normal, ra = sp.point - pa, rb = sp.point - (pb + sp.travel * d);
    const double mw = 1.0 / (1 / ma + 1 / mb + ra.cross(n).dot(Ia.inverse() * ra.cross(n)) +
                             rb.cross(n).dot(Ib.inverse() * rb.cross(n)));
    const double vw = -n.dot((vb + wb.cross(rb)) - (va + wa.cross(ra)));
    RunReport rep;
    try {
      rep = run_scene(parse_scene(text, "pair.toml"));
    } catch (const InputError& e) {
      // Receding at the first contact (the spins can do that): the reference agrees.
      EXPECT_LE(vw, 0.0) << e.what();
      continue;
    }
    ++cases;
    const ImpactReport& ir = rep.impacts.at(0);
    EXPECT_LT((ir.contact.point_m - sp.point).norm(), 1e-9 * sa.maxCoeff()) << trial;
    EXPECT_LT((ir.contact.normal - n).norm(), 1e-9) << trial;
    EXPECT_NEAR(ir.contact.travel_m, sp.travel, 1e-9 * sa.maxCoeff()) << trial;
    const double Pi = 1.55 * mw * vw;
    EXPECT_NEAR(ir.result.reduced_mass_kg, mw, 1e-6 * mw) << trial;
    EXPECT_NEAR(ir.result.approach_velocity_m_s, vw, 1e-6 * vw) << trial;
    const Eigen::Vector3d dva = -Pi * n / ma, dvb = Pi * n / mb;
    const Eigen::Vector3d dwa = Ia.inverse() * ra.cross(-Pi * n), dwb = Ib.inverse() * rb.cross(Pi * n);
    EXPECT_LT((ir.result.target_jump.delta_velocity_m_s - dva).norm(), 1e-6 * dva.norm()) << trial;
    EXPECT_LT((ir.result.impactor_jump.delta_velocity_m_s - dvb).norm(), 1e-6 * dvb.norm()) << trial;
    EXPECT_LT((ir.result.target_jump.delta_angular_velocity_rad_s - dwa).norm(), 1e-6 * dwa.norm()) << trial;
    EXPECT_LT((ir.result.impactor_jump.delta_angular_velocity_rad_s - dwb).norm(), 1e-6 * dwb.norm()) << trial;
  }
  EXPECT_GE(cases, 6);
  RecordProperty("cases", cases);
}

TEST(Placed, MeshedEllipsoidDropConvergesToTheAnalyticDrop) {
  // The drop of RotatedEllipsoidDroppedOnAFloor with the part as a mesh (the same placement):
  // m_w, the spin jump and F_max converge to the analytic values as the triangles grow.
  const Eigen::Vector3d semi(0.2, 0.05, 0.08), p(1e3, -2e3, 0.5), axis(1, 2, 0.5);
  const Eigen::Vector3d v(0.3, -0.2, -4.0), w(1.0, -2.0, 0.5);
  const std::string analytic = drop_scene(semi, p, axis, 37.0, v, w, 0.1);
  const RunReport ra = run_scene(parse_scene(analytic, "drop.toml"));
  const auto& a = ra.impacts[0].result;
  const fs::path dir = fs::temp_directory_path() / "impactdeck_mesh_drop";
  fs::create_directories(dir);
  double previous = INFINITY;
  std::printf("triangles  m_w_rel  dw_rel  F_max_rel  contact_point_m\n");
  for (int sub : {3, 4, 5, 6}) {
    const geometry::TriangleMesh mesh = geometry::make_ellipsoid_mesh(semi.x(), semi.y(), semi.z(), sub);
    const fs::path stl = dir / ("e" + std::to_string(sub) + ".stl");
    geometry::write_stl_binary(stl, mesh);
    std::string text = analytic;
    const std::string from = "shape = \"ellipsoid\"\nsemi_axes = " + vec(semi);
    text.replace(text.find(from), from.size(), "shape = \"mesh\"\nmesh = \"" + stl.string() + "\"");
    const RunReport rm = run_scene(parse_scene(text, "mdrop.toml"));
    const auto& m = rm.impacts[0].result;
    const double e_mw = std::abs(m.reduced_mass_kg / a.reduced_mass_kg - 1);
    const double e_dw = (m.target_jump.delta_angular_velocity_rad_s - a.target_jump.delta_angular_velocity_rad_s).norm() /
                        a.target_jump.delta_angular_velocity_rad_s.norm();
    const double e_f = std::abs(m.history.compression.max_force_N / a.history.compression.max_force_N - 1);
    const double e_p = (rm.impacts[0].contact.point_m - ra.impacts[0].contact.point_m).norm();
    std::printf("%9zu  %.2e  %.2e  %.2e  %.2e\n", mesh.triangle_count(), e_mw, e_dw, e_f, e_p);
    RecordProperty("m_w_rel_" + std::to_string(mesh.triangle_count()), test::sci(e_mw));
    RecordProperty("F_max_rel_" + std::to_string(mesh.triangle_count()), test::sci(e_f));
    // The contact point (the smoothed surface's support point) converges at about second order;
    // m_w and the jumps follow it, with the volume integrals' O(h^2) on top (their sign changes
    // between levels, so only the point is asked to shrink at every level).
    EXPECT_LT(e_p, previous) << sub;
    previous = e_p;
    if (sub == 6) {  // measured at 81 920 triangles: 1.0e-4, 8.2e-5, 3.3e-4, 1.1e-5 m
      EXPECT_LT(e_mw, 5e-4);
      EXPECT_LT(e_dw, 5e-4);
      EXPECT_LT(e_f, 2e-3);  // F_max also carries the curvature fit's error
      EXPECT_LT(e_p, 5e-5);
    }
  }
  fs::remove_all(dir);
}
