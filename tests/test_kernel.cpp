// The physics kernel (collision::solve_kernel): conforming and concave Hertz contacts against
// closed forms, the flags where Hertz does not apply, both bodies eccentric, restitution tables
// and the validity report.
#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/collision/kernel.hpp"
#include "impactdeck/collision/validity.hpp"
#include "impactdeck/common/error.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::collision;

namespace {

RestitutionModel constant(double R) {
  RestitutionModel m;
  m.kind = RestitutionModel::Kind::constant;
  m.constant = R;
  return m;
}

// A steel ball of radius r (m) against a fixed target, at 1 m/s along -z; both surfaces given.
KernelInput ball_on_fixed(double r, const ContactCurvature& target, const ContactLaw& law) {
  RigidBody wall;
  wall.mass_kg = INFINITY;
  RigidBody ball;
  ball.mass_kg = 7850 * 4.0 / 3.0 * M_PI * r * r * r;
  ball.inertia_kg_m2 = 0.4 * ball.mass_kg * r * r * Eigen::Matrix3d::Identity();
  ball.velocity_m_s = {0, 0, -1};
  KernelInput in;
  in.target = kernel_body(wall);
  in.impactor = kernel_body(ball);
  in.impactor.velocity_m_s = ball.velocity_m_s;
  in.impactor.lever_arm_m = {0, 0, -r};
  in.target.curvature = target;
  in.impactor.curvature = ContactCurvature::sphere(r);
  in.normal = {0, 0, 1};
  in.effective_modulus_Pa = 1.1e11;
  in.law = &law;
  return in;
}

ContactCurvature principal(double k1, double k2) {
  ContactCurvature c;
  c.k1_per_m = k1;
  c.k2_per_m = k2;
  c.d1 = {1, 0, 0};
  c.d2 = {0, 1, 0};
  return c;
}

}  // namespace

TEST(Kernel, BallInAConcaveCupIsAConformingHertzContact) {
  // Ball r = 10 mm in a spherical cup of radius 50 mm: 1/R* = 1/r - 1/R_cup (Johnson, Sect. 4.2),
  // R* = r R / (R - r) = 12.5 mm, under every rule that uses curvatures.
  const HertzLaw rm(constant(0.5));
  for (ContactRule rule : {ContactRule::elliptical, ContactRule::mean}) {
    KernelInput in = ball_on_fixed(0.01, principal(-20.0, -20.0), rm);
    in.rule = rule;
    const KernelResult r = solve_kernel(in);
    ASSERT_EQ(r.flag, ContactFlag::none) << to_string(rule);
    EXPECT_NEAR(r.effective_radius_m, 0.0125, 1e-15) << to_string(rule);
    EXPECT_NEAR(r.relative_curvature_A_per_m, 40.0, 1e-12);
    // Against a wall the reduced mass at the ball's pole is the ball's mass.
    EXPECT_NEAR(r.reduced_mass_kg, 7850 * 4.0 / 3.0 * M_PI * 1e-6, 1e-15);
  }
  // A ball larger than the cup does not fit: a ring contact, flagged.
  const KernelResult big = solve_kernel(ball_on_fixed(0.06, principal(-20.0, -20.0), rm));
  EXPECT_EQ(big.flag, ContactFlag::no_fit);
  EXPECT_STREQ(flag_word(big.flag), "no-fit");
}

TEST(Kernel, FlagsWhereHertzDoesNotApply) {
  const HertzLaw rm(constant(0.5));
  // A saddle k = (10, -30) 1/m: a ball of 1/r = 20 is outweighed along the concave direction...
  EXPECT_EQ(solve_kernel(ball_on_fixed(0.05, principal(10.0, -30.0), rm)).flag, ContactFlag::saddle);
  // ... a ball of 1/r = 40 fits: A = (40 - 30)/2 = 5, B = (40 + 10)/2 = 25.
  const KernelResult fits = solve_kernel(ball_on_fixed(0.025, principal(10.0, -30.0), rm));
  ASSERT_EQ(fits.flag, ContactFlag::none);
  EXPECT_NEAR(fits.relative_curvature_A_per_m, 5.0, 1e-12);
  EXPECT_NEAR(fits.relative_curvature_B_per_m, 25.0, 1e-12);
  EXPECT_NEAR(std::abs(fits.direction_A.y()), 1.0, 1e-12);  // the concave direction
  EXPECT_GT(fits.contact_ellipse_axis_ratio, 1.0);
  // Sharp edge.
  ContactCurvature sharp;
  sharp.sharp = true;
  EXPECT_EQ(solve_kernel(ball_on_fixed(0.01, sharp, rm)).flag, ContactFlag::sharp);
  // A flat impactor on a cylinder: line contact; flat on flat: flat contact.
  KernelInput line = ball_on_fixed(0.01, principal(10.0, 0.0), rm);
  line.impactor.curvature = ContactCurvature::flat();
  EXPECT_EQ(solve_kernel(line).flag, ContactFlag::line);
  KernelInput flat = line;
  flat.target.curvature = ContactCurvature::flat();
  EXPECT_EQ(solve_kernel(flat).flag, ContactFlag::flat);
  // Receding bodies.
  KernelInput away = ball_on_fixed(0.01, principal(20.0, 20.0), rm);
  away.impactor.velocity_m_s = {0, 0, 1};
  EXPECT_EQ(solve_kernel(away).flag, ContactFlag::no_approach);
  // Overflow: flagged, never a NaN or an infinity.
  KernelInput fast = ball_on_fixed(0.01, principal(20.0, 20.0), rm);
  fast.impactor.velocity_m_s = {0, 0, -1e300};
  const KernelResult d = solve_kernel(fast);
  EXPECT_EQ(d.flag, ContactFlag::degenerate);
  EXPECT_FALSE(std::isnan(d.max_force_N));
  EXPECT_NE(explain_flag(fast, d).find("under- or overflows"), std::string::npos);
  // An absurdly soft material is computable (in logs) but far outside Hertz's assumptions: the
  // validity report says so (a 1e120 m indentation must never pass silently).
  KernelInput soft = ball_on_fixed(0.01, principal(20.0, 20.0), rm);
  soft.effective_modulus_Pa = 1e-300;
  const KernelResult s = solve_kernel(soft);
  ASSERT_EQ(s.flag, ContactFlag::none);
  const ValidityReport v = assess_validity(soft, s, std::nullopt, std::nullopt);
  EXPECT_FALSE(v.ok);
  EXPECT_GT(v.indentation_over_radius, 1e100);
  // Every flag has a distinct word; none is empty but "none".
  for (int f = 1; f < kContactFlagCount; ++f) EXPECT_STRNE(flag_word(static_cast<ContactFlag>(f)), "");
}

TEST(Kernel, BothBodiesEccentricMatchTheClosedFormAndConserveMomentum) {
  // Two free rotated boxes-of-inertia with lever arms on both sides and spins: the kernel's m_w
  // is the tensor form of Eq. 21 for both bodies; after the impulse the normal relative velocity
  // is -R v_w, linear momentum and angular momentum about the contact point are conserved.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const HertzLaw rm(constant(0.6));
  for (int trial = 0; trial < 200; ++trial) {
    RigidBody a, b;
    auto random_body = [&](RigidBody& body) {
      body.mass_kg = 1.0 + 9.0 * (u(rng) + 1.0);
      const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
                                    .toRotationMatrix();
      const Eigen::Vector3d moments(1.0 + u(rng) * 0.5, 2.0 + u(rng) * 0.5, 3.0 + u(rng) * 0.5);
      body.inertia_kg_m2 = R * moments.asDiagonal() * R.transpose();
      body.center_of_mass_m = {1e3 + u(rng), -2e3 + u(rng), u(rng)};  // far from the origin
      body.velocity_m_s = {u(rng), u(rng), u(rng)};
      body.angular_velocity_rad_s = {u(rng), u(rng), u(rng)};
    };
    random_body(a);
    random_body(b);
    Contact c;
    c.point_m = 0.5 * (a.center_of_mass_m + b.center_of_mass_m) + Eigen::Vector3d(u(rng), u(rng), u(rng));
    c.normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    // Make the bodies approach at the point along the normal.
    b.velocity_m_s -= (3.0 + std::abs(approach_velocity_m_s(a, b, c))) * c.normal;
    KernelInput in;
    in.target = kernel_body(a);
    in.impactor = kernel_body(b);
    in.target.lever_arm_m = c.point_m - a.center_of_mass_m;
    in.impactor.lever_arm_m = c.point_m - b.center_of_mass_m;
    in.target.curvature = ContactCurvature::sphere(0.2);
    in.impactor.curvature = ContactCurvature::sphere(0.1);
    in.normal = c.normal;
    in.effective_modulus_Pa = 2e11;
    in.law = &rm;
    const KernelResult r = solve_kernel(in);
    ASSERT_EQ(r.flag, ContactFlag::none);
    EXPECT_NEAR(r.reduced_mass_kg, reduced_mass_kg(a, b, c), test::kReducedMassRel * r.reduced_mass_kg);
    EXPECT_NEAR(r.approach_velocity_m_s, approach_velocity_m_s(a, b, c), 1e-12 * r.approach_velocity_m_s);
    RigidBody a2 = a, b2 = b;
    a2.velocity_m_s += r.target_jump.delta_velocity_m_s;
    a2.angular_velocity_rad_s += r.target_jump.delta_angular_velocity_rad_s;
    b2.velocity_m_s += r.impactor_jump.delta_velocity_m_s;
    b2.angular_velocity_rad_s += r.impactor_jump.delta_angular_velocity_rad_s;
    EXPECT_NEAR(approach_velocity_m_s(a2, b2, c), -0.6 * r.approach_velocity_m_s, 1e-10 * r.approach_velocity_m_s);
    const Eigen::Vector3d p0 = a.mass_kg * a.velocity_m_s + b.mass_kg * b.velocity_m_s;
    const Eigen::Vector3d p1 = a2.mass_kg * a2.velocity_m_s + b2.mass_kg * b2.velocity_m_s;
    EXPECT_LT((p1 - p0).norm(), 1e-10 * r.impulse_total_Ns);
    auto L = [&](const RigidBody& x) {
      return Eigen::Vector3d((x.center_of_mass_m - c.point_m).cross(x.mass_kg * x.velocity_m_s) +
                             x.inertia_kg_m2 * x.angular_velocity_rad_s);
    };
    EXPECT_LT((L(a2) + L(b2) - L(a) - L(b)).norm(), 1e-9 * r.impulse_total_Ns * 1e3);
  }
}

namespace {

// Eq. 30's restitution, clamped (with a warning) outside its range.
RestitutionModel energy_flux_warn() {
  RestitutionModel m;
  m.kind = RestitutionModel::Kind::energy_flux;
  m.range_policy = RangePolicy::warn;
  return m;
}

// Every field of two kernel results, bit for bit (flag, numbers, directions, jumps).
bool same_bits(const KernelResult& a, const KernelResult& b) {
  const double x[] = {a.reduced_mass_kg, a.approach_velocity_m_s, a.relative_curvature_A_per_m,
                      a.relative_curvature_B_per_m, a.effective_radius_m, a.contact_ellipse_axis_ratio,
                      a.hertz_constant, a.max_indentation_m, a.max_force_N, a.compression_time_s,
                      a.restitution.coefficient, a.impulse_total_Ns, a.contact_semi_axis_a_m,
                      a.contact_semi_axis_b_m, a.peak_pressure_Pa, a.contact_time_s, a.unloading_time_s,
                      a.residual_indentation_m};
  const double y[] = {b.reduced_mass_kg, b.approach_velocity_m_s, b.relative_curvature_A_per_m,
                      b.relative_curvature_B_per_m, b.effective_radius_m, b.contact_ellipse_axis_ratio,
                      b.hertz_constant, b.max_indentation_m, b.max_force_N, b.compression_time_s,
                      b.restitution.coefficient, b.impulse_total_Ns, b.contact_semi_axis_a_m,
                      b.contact_semi_axis_b_m, b.peak_pressure_Pa, b.contact_time_s, b.unloading_time_s,
                      b.residual_indentation_m};
  return a.flag == b.flag && a.restitution.clamped == b.restitution.clamped &&
         std::memcmp(x, y, sizeof x) == 0 && a.direction_A == b.direction_A &&
         a.target_jump.delta_velocity_m_s == b.target_jump.delta_velocity_m_s &&
         a.target_jump.delta_angular_velocity_rad_s == b.target_jump.delta_angular_velocity_rad_s &&
         a.impactor_jump.delta_velocity_m_s == b.impactor_jump.delta_velocity_m_s &&
         a.impactor_jump.delta_angular_velocity_rad_s == b.impactor_jump.delta_angular_velocity_rad_s;
}

}  // namespace

TEST(Kernel, PerPointFormReadsThePointAndWritesEveryField) {
  // solve_kernel(invariants, point, result), the form a sweep calls per point: the per-point fields
  // of `invariants` (normal, lever arms, velocities, surfaces) are not read, `result` is fully
  // written (a slot holding another point's numbers), and the numbers are those of
  // solve_kernel(KernelInput), bit for bit: valid and flagged points.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const HertzLaw flux(energy_flux_warn());
  int valid = 0, flagged = 0;
  for (const ContactRule rule : {ContactRule::elliptical, ContactRule::mean, ContactRule::paper}) {
    for (int trial = 0; trial < 100; ++trial) {
      RigidBody a, b;
      for (RigidBody* body : {&a, &b}) {
        body->mass_kg = 1.0 + 9.0 * (u(rng) + 1.0);
        body->inertia_kg_m2 = Eigen::Vector3d(1.0 + 0.5 * u(rng), 2.0, 3.0 + 0.5 * u(rng)).asDiagonal();
        body->velocity_m_s = {u(rng), u(rng), u(rng)};
        body->angular_velocity_rad_s = {u(rng), u(rng), u(rng)};
      }
      KernelInput in;
      in.target = kernel_body(a);
      in.impactor = kernel_body(b);
      in.normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Vector3d t1 = in.normal.unitOrthogonal(), t2 = in.normal.cross(t1);
      in.target.lever_arm_m = {u(rng), u(rng), u(rng)};
      in.impactor.lever_arm_m = {u(rng), u(rng), u(rng)};
      in.target.curvature = {10.0 + 5.0 * u(rng), 10.0 * u(rng), t1, t2, 8.0 + u(rng), trial % 17 == 0};
      in.impactor.curvature = ContactCurvature::sphere(0.05 + 0.04 * u(rng));
      in.impactor.velocity_m_s -= 2.0 * u(rng) * in.normal;  // some approach, some do not
      in.rule = rule;
      in.effective_modulus_Pa = 1e11;
      in.law = &flux;
      const KernelResult whole = solve_kernel(in);

      KernelInput invariants = in;  // its per-point fields scrambled: they must not be read
      const double nan = std::nan("");
      for (KernelBody* k : {&invariants.target, &invariants.impactor}) {
        k->lever_arm_m.setConstant(nan);
        k->velocity_m_s.setConstant(nan);
        k->curvature = ContactCurvature::sphere(nan);
      }
      invariants.normal.setConstant(nan);
      KernelResult slot = whole;
      slot.flag = ContactFlag::degenerate;
      slot.max_force_N = slot.target_jump.delta_velocity_m_s.x() = nan;
      solve_kernel(invariants, KernelPoint::of(in), slot);
      EXPECT_TRUE(same_bits(slot, whole)) << to_string(rule) << " trial " << trial << ": " << flag_word(whole.flag);
      (whole.flag == ContactFlag::none ? valid : flagged) += 1;
    }
  }
  EXPECT_GT(valid, 50);
  EXPECT_GT(flagged, 20);  // sharp and no-approach points, their later fields left 0
}

TEST(Kernel, GroupedFormIsTheOnePointFormBitForBit) {
  // solve_kernel(invariants, points, results, count) runs each step over up to kKernelLanes points
  // before the next: every point must get the one-point numbers bit for bit, whatever its group
  // holds (valid points next to sharp, no-approach and saddle ones) and however the count falls on
  // the groups.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const HertzLaw flux(energy_flux_warn());
  RigidBody a, b;
  a.mass_kg = 12.0;
  a.inertia_kg_m2 = Eigen::Vector3d(1.2, 2.0, 3.1).asDiagonal();
  a.angular_velocity_rad_s = {0.3, -0.2, 0.1};
  b.mass_kg = 3.0;
  b.inertia_kg_m2 = Eigen::Vector3d(0.4, 0.5, 0.6).asDiagonal();
  b.angular_velocity_rad_s = {0.0, 0.0, 4.0};
  KernelInput invariants;
  invariants.target = kernel_body(a);
  invariants.impactor = kernel_body(b);
  invariants.effective_modulus_Pa = 1e11;
  invariants.law = &flux;
  const std::size_t n = 203;  // not a multiple of kKernelLanes
  struct Point {
    Eigen::Vector3d normal, target_arm, impactor_arm, target_velocity, impactor_velocity;
    ContactCurvature target_curvature, impactor_curvature;
  };
  std::vector<Point> pts(n);
  for (std::size_t k = 0; k < n; ++k) {
    Point& p = pts[k];
    p.normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Eigen::Vector3d t1 = p.normal.unitOrthogonal(), t2 = p.normal.cross(t1);
    p.target_arm = {u(rng), u(rng), u(rng)};
    p.impactor_arm = {u(rng), u(rng), u(rng)};
    p.target_velocity = {0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)};
    p.impactor_velocity = -2.0 * u(rng) * p.normal;  // some approach, some do not
    // Convex, saddle (k2 < 0 beyond the ball's curvature) or sharp.
    p.target_curvature = {10.0 + 5.0 * u(rng), k % 9 == 4 ? -40.0 : 10.0 * u(rng), t1, t2, 8.0 + u(rng), k % 13 == 0};
    p.impactor_curvature = ContactCurvature::sphere(0.05 + 0.04 * u(rng));
  }
  std::vector<KernelPoint> points;
  for (const Point& p : pts) {
    points.push_back({&p.normal, &p.target_arm, &p.impactor_arm, &p.target_velocity, &p.impactor_velocity,
                      &p.target_curvature, &p.impactor_curvature});
  }
  for (const ContactRule rule : {ContactRule::elliptical, ContactRule::mean, ContactRule::paper}) {
    invariants.rule = rule;
    std::vector<KernelResult> one(n), grouped(n);
    for (std::size_t k = 0; k < n; ++k) solve_kernel(invariants, points[k], one[k]);
    for (KernelResult& r : grouped) r.max_force_N = r.reduced_mass_kg = std::nan("");  // slots to overwrite
    std::vector<KernelResult*> slots;
    for (KernelResult& r : grouped) slots.push_back(&r);
    // Runs of 1 to 2 kKernelLanes + 1 points: groups cut short anywhere.
    for (std::size_t i = 0, len = 1; i < n; i += len, len = len % (2 * kKernelLanes + 1) + 1) {
      solve_kernel(invariants, &points[i], &slots[i], std::min(len, n - i));
    }
    std::array<int, kContactFlagCount> flags{};
    for (std::size_t k = 0; k < n; ++k) {
      EXPECT_TRUE(same_bits(grouped[k], one[k]))
          << to_string(rule) << " point " << k << ": " << flag_word(one[k].flag);
      ++flags[static_cast<int>(one[k].flag)];
    }
    // The groups mixed valid and flagged points.
    EXPECT_GT(flags[static_cast<int>(ContactFlag::none)], 60) << to_string(rule);
    EXPECT_GT(flags[static_cast<int>(ContactFlag::sharp)], 5) << to_string(rule);
    EXPECT_GT(flags[static_cast<int>(ContactFlag::no_approach)], 30) << to_string(rule);
  }
}

TEST(Kernel, RestitutionTableInterpolatesAndObeysThePolicy) {
  RestitutionModel rm;
  rm.kind = RestitutionModel::Kind::table;
  rm.table.approach_speed_m_s = {0.5, 1.0, 3.0};
  rm.table.value = {0.9, 0.8, 0.4};
  validate_restitution_table(rm.table);
  auto at = [&](double v) { return evaluate_restitution(rm, 1.0, v, 0.01); };
  EXPECT_DOUBLE_EQ(at(1.0).coefficient, 0.8);
  EXPECT_NEAR(at(2.0).coefficient, 0.6, 1e-15);
  EXPECT_NEAR(at(0.75).coefficient, 0.85, 1e-15);
  EXPECT_FALSE(at(2.0).outside_range);
  rm.range_policy = RangePolicy::warn;
  EXPECT_TRUE(at(5.0).clamped);
  EXPECT_DOUBLE_EQ(at(5.0).coefficient, 0.4);
  rm.range_policy = RangePolicy::extrapolate;
  EXPECT_NEAR(at(4.0).coefficient, 0.2, 1e-15);
  EXPECT_TRUE(at(6.0).invalid);  // 0.4 - 0.2 * 3 < 0
  rm.range_policy = RangePolicy::error;
  EXPECT_TRUE(at(0.1).refused);
  // Through the kernel: the flag and its message.
  const HertzLaw law(rm);
  KernelInput in = ball_on_fixed(0.01, principal(20.0, 20.0), law);
  in.impactor.velocity_m_s = {0, 0, -10};
  const KernelResult r = solve_kernel(in);
  EXPECT_EQ(r.flag, ContactFlag::restitution_range);
  EXPECT_NE(explain_flag(in, r).find("outside the restitution table's range [0.5, 3] m/s"), std::string::npos)
      << explain_flag(in, r);
  // Bad tables.
  RestitutionTable t{{1.0, 1.0}, {0.5, 0.4}};
  EXPECT_THROW(validate_restitution_table(t), InputError);
  t = {{1.0, 2.0}, {0.5, 1.2}};
  EXPECT_THROW(validate_restitution_table(t), InputError);
  t = {{1.0}, {0.5}};
  EXPECT_THROW(validate_restitution_table(t), InputError);
  t = {{1.0, 2.0, 3.0}, {0.5, 0.4}};
  EXPECT_THROW(validate_restitution_table(t), InputError);
}

TEST(Kernel, ValidityReportAgainstHertzClosedForms) {
  // Sphere on a flat, fixed target: a = sqrt(R x_max) (Hertz), p0 = 3F/(2 pi a^2), and the yield
  // onset 1.60 sigma_y of the weaker material (Johnson, Sect. 6.2).
  const HertzLaw rm(constant(1.0));
  KernelInput in = ball_on_fixed(0.01, ContactCurvature::flat(), rm);
  in.impactor.velocity_m_s = {0, 0, -3};
  const KernelResult r = solve_kernel(in);
  ASSERT_EQ(r.flag, ContactFlag::none);
  EXPECT_NEAR(r.contact_semi_axis_a_m, std::sqrt(0.01 * r.max_indentation_m), 1e-12 * r.contact_semi_axis_a_m);
  EXPECT_NEAR(r.peak_pressure_Pa, 3 * r.max_force_N / (2 * M_PI * r.contact_semi_axis_a_m * r.contact_semi_axis_a_m),
              1e-12 * r.peak_pressure_Pa);
  const ValidityReport ok = assess_validity(in, r, std::nullopt, 1e12);
  EXPECT_TRUE(ok.ok) << (ok.warnings.empty() ? "" : ok.warnings[0]);
  EXPECT_EQ(ok.yielding_body, "impactor");
  EXPECT_NEAR(*ok.yield_onset_pressure_Pa, 1.6e12, 1e-3);
  EXPECT_NEAR(ok.smallest_curvature_radius_m, 0.01, 1e-15);
  // A soft target yields: the warning names the quantity.
  const ValidityReport soft = assess_validity(in, r, 1e8, 1e12);
  EXPECT_FALSE(soft.ok);
  EXPECT_EQ(soft.yielding_body, "target");
  ASSERT_EQ(soft.warnings.size(), 1u);
  EXPECT_NE(soft.warnings[0].find("peak Hertz pressure"), std::string::npos);
  // A fast impact indents too deeply and makes a patch large against the ball.
  in.impactor.velocity_m_s = {0, 0, -400};
  const KernelResult fast = solve_kernel(in);
  const ValidityReport v = assess_validity(in, fast, std::nullopt, std::nullopt);
  EXPECT_FALSE(v.ok);
  ASSERT_EQ(v.warnings.size(), 2u);
  EXPECT_NE(v.warnings[0].find("max indentation"), std::string::npos);
  EXPECT_NE(v.warnings[1].find("contact ellipse semi-axis"), std::string::npos);
}
