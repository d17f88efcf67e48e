// Drop sequences (sequence/): the flight against closed forms and conservation laws, the contact
// search (never missing a grazing contact), and whole sequences against closed forms and against
// an independent integration written here.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/sequence/sequence.hpp"

namespace {

using namespace impactdeck;
using sequence::BodyState;
using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

// The flight's stated accuracy: rk8pd steps at 1e-13 relative keep the invariants within 1e-10.
constexpr double kFlightTolerance = 1e-10;

const collision::ElasticMaterial kSteel{210e9, 0.3};

contact::PreparedBody ellipsoid_body(double a, double b, double c, double mass) {
  return contact::body_of_mass("part", std::make_shared<geometry::Ellipsoid>(a, b, c), mass, kSteel);
}

contact::PreparedBody floor_body() {
  return contact::body_of_mass("floor", std::make_shared<geometry::Plane>(Vector3d::UnitZ()),
                               std::numeric_limits<double>::infinity(), kSteel);
}

sequence::SequenceInput input_with(const contact::PreparedBody& body, double restitution) {
  sequence::SequenceInput in;
  in.body = body;
  in.floor = floor_body();
  in.gravity_m_s2 = Vector3d(0, 0, -9.81);
  in.effective_modulus_Pa = collision::effective_modulus_Pa(kSteel, kSteel, collision::ModulusConvention::hertz);
  collision::RestitutionModel r;
  r.kind = collision::RestitutionModel::Kind::constant;
  r.constant = restitution;
  in.law = std::make_shared<collision::HertzLaw>(r);
  in.rigid_restitution = restitution;
  return in;
}

// --- flight ---------------------------------------------------------------------------------

TEST(SequenceFlight, SymmetricTopMatchesItsClosedForm) {
  // I1 = I2 != I3: R(t) = exp(t [L/I1]x) R0 exp(t c [e3]x), c = (1/I3 - 1/I1) L3 (L3 = I3 w3, body).
  const double I1 = 2.0, I3 = 0.7;
  const Matrix3d I = Vector3d(I1, I1, I3).asDiagonal();
  const sequence::Flight flight(I, Vector3d(0, 0, -9.81));
  BodyState s;
  s.orientation = Quaterniond(Eigen::AngleAxisd(0.4, Vector3d(1, 2, 0.5).normalized()));
  const Matrix3d R0 = s.orientation.toRotationMatrix();
  const Vector3d w_body(3.0, -1.0, 7.0);
  s.angular_velocity_rad_s = R0 * w_body;
  const Vector3d L = R0 * (I * w_body);
  const double c = (1.0 / I3 - 1.0 / I1) * I3 * w_body.z();
  for (double t : {0.01, 0.3, 2.0, 5.0}) {
    const BodyState e = flight.advance(s, t);
    const Matrix3d expected = Eigen::AngleAxisd(t * L.norm() / I1, L.normalized()).toRotationMatrix() * R0 *
                              Eigen::AngleAxisd(t * c, Vector3d::UnitZ()).toRotationMatrix();
    EXPECT_LT((e.orientation.toRotationMatrix() - expected).norm(), kFlightTolerance) << "t = " << t;
    const Matrix3d R = e.orientation.toRotationMatrix();
    EXPECT_LT((R * I * R.transpose() * e.angular_velocity_rad_s - L).norm(), kFlightTolerance * L.norm());
  }
}

TEST(SequenceFlight, AsymmetricBodyConservesEnergyAndAngularMomentum) {
  // A tumbling box-like body near its unstable middle axis, 100+ radians of rotation.
  auto body = ellipsoid_body(0.1, 0.05, 0.02, 1.0);
  body.angular_velocity_rad_s = Vector3d(0.3, 40.0, 0.2);
  body.velocity_m_s = Vector3d(1.0, 0.0, 2.0);
  const Vector3d g(0, 0, -9.81);
  const sequence::Flight flight(body.inertia_kg_m2, g);
  const BodyState s = sequence::state_of(body);
  const double E0 = sequence::mechanical_energy_J(body, s, g);
  const Vector3d L0 = sequence::angular_momentum(body, s);
  const double scale = 0.5 * body.angular_velocity_rad_s.dot(L0) + 0.5 * body.mass_kg * s.velocity_m_s.squaredNorm();
  for (double t : {0.1, 1.0, 3.0}) {
    const BodyState e = flight.advance(s, t);
    EXPECT_LT(std::abs(sequence::mechanical_energy_J(body, e, g) - E0), kFlightTolerance * scale) << t;
    EXPECT_LT((sequence::angular_momentum(body, e) - L0).norm(), kFlightTolerance * L0.norm()) << t;
    // The centre is exact.
    EXPECT_NEAR(e.centroid_m.z(), s.centroid_m.z() + 2.0 * t - 0.5 * 9.81 * t * t, 1e-14 * (1 + t * t * 10));
  }
}

// --- contact search -------------------------------------------------------------------------

TEST(SequenceSearch, GrazingTipOfASpinningBodyIsNotMissed) {
  // A prolate spheroid spinning about a transverse principal axis (steady) with its centre a - delta
  // above the floor: its tip dips delta = 1e-7 m below the floor for about 1e-5 s per half turn.
  const double a = 0.1, b = 0.02, delta = 1e-7, w = 50.0, g = 1e-3;
  auto body = ellipsoid_body(a, b, b, 1.0);
  body.pose.rotation = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()).toRotationMatrix();  // long axis along z...
  body.pose.rotation = Eigen::AngleAxisd(-M_PI / 2 + 1.0, Vector3d::UnitY()).toRotationMatrix() *
                       Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()).toRotationMatrix();  // ... tilted 1 rad
  body.pose.position_m = Vector3d(0, 0, a - delta);
  body.angular_velocity_rad_s = Vector3d(0, w, 0);
  const sequence::Flight flight(body.inertia_kg_m2, Vector3d(0, 0, -g));
  sequence::Floor floor;
  // Closed form: the long axis makes phi(t) = 1 - w t... with the vertical; support depth
  // s(phi) = sqrt(a^2 cos^2 phi + b^2 sin^2 phi); gap(t) = a - delta - g t^2 / 2 - s(phi(t)).
  const BodyState s0 = sequence::state_of(body);
  auto gap = [&](double t) {
    return sequence::floor_gap_m(*body.shape, body.volume.centroid_m, flight.advance(s0, t), floor);
  };
  auto closed = [&](double t) {
    const Vector3d axis = Eigen::AngleAxisd(w * t, Vector3d::UnitY()) * (body.pose.rotation * Vector3d::UnitX());
    const double cphi = std::abs(axis.z()), sphi = std::sqrt(1 - cphi * cphi);
    return a - delta - 0.5 * g * t * t - std::sqrt(a * a * cphi * cphi + b * b * sphi * sphi);
  };
  EXPECT_NEAR(gap(0.005), closed(0.005), 1e-12);
  // The first root of the closed form: dense scan, then bisection.
  double lo = 0, hi = 0;
  for (double t = 0; t < 0.2; t += 1e-6) {
    if (closed(t) <= 0) {
      hi = t;
      break;
    }
    lo = t;
  }
  ASSERT_GT(hi, 0.0);
  for (int k = 0; k < 80; ++k) (closed(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  const sequence::NextContact nc = sequence::next_contact(body, flight, s0, floor, 1e-10 * body.shape->size_m());
  // The contact time to 1e-9 s (the gap tolerance 2e-11 m over the tip's approach speed ~ 0.03 m/s).
  EXPECT_NEAR(nc.state.time_s, lo, 1e-9);
  EXPECT_GT(gap(nc.state.time_s - 1e-6), 0.0) << "before the contact the tip is above the floor";
  EXPECT_LT(std::abs(nc.gap_m), 1e-10 * body.shape->size_m());
}

// --- sequences ------------------------------------------------------------------------------

TEST(Sequence, SphereBouncesToHeightsEToThe2kH) {
  const double r = 0.01, h = 0.5, e = 0.8, g = 9.81;
  auto ball = ellipsoid_body(r, r, r, 0.1);
  ball.pose.position_m = Vector3d(0.3, -0.2, r + h);
  sequence::SequenceInput in = input_with(ball, e);
  const sequence::SequenceResult res = sequence::run_sequence(in);
  // Approach speeds sqrt(2 g h) e^k fall below 0.05 m/s after k = 18: 19 impacts, after which the
  // kinetic energy is below m (0.05 m/s)^2 / 2: at rest.
  ASSERT_EQ(res.bounces.size(), 19u);
  EXPECT_EQ(res.stop, sequence::StopReason::at_rest);
  // Tolerance: the contact search's gap tolerance (1e-10 x size) and rounding over 19 flights.
  constexpr double kTol = 1e-9;
  const double v0 = std::sqrt(2 * g * h);
  double t = std::sqrt(2 * h / g);
  for (std::size_t k = 0; k < res.bounces.size(); ++k) {
    const auto& b = res.bounces[k];
    const double vk = v0 * std::pow(e, k);
    EXPECT_NEAR(b.approach_velocity_m_s, vk, kTol * v0) << k;
    EXPECT_NEAR(b.time_s, t, kTol * 10) << k;
    const double height = std::pow(b.after.velocity_m_s.z(), 2) / (2 * g);
    EXPECT_NEAR(height, std::pow(e, 2.0 * (k + 1)) * h, kTol * h) << k;
    EXPECT_TRUE(b.impact.has_value());
    EXPECT_GT(b.max_force_N(), 0.0);
    t += 2 * e * vk / g;
  }
  EXPECT_EQ(res.worst_impact_index, 0);
}

TEST(Sequence, DriftingSphereStopsOnTheApproachSpeed) {
  // The same drop with a sideways drift: the kinetic energy stays above the rest threshold, and the
  // sequence stops at the contact whose approach speed falls below min_approach_speed_m_s.
  const double r = 0.01, h = 0.5, e = 0.8;
  auto ball = ellipsoid_body(r, r, r, 0.1);
  ball.pose.position_m = Vector3d(0, 0, r + h);
  ball.velocity_m_s = Vector3d(1.0, 0.0, 0.0);
  const sequence::SequenceResult res = sequence::run_sequence(input_with(ball, e));
  EXPECT_EQ(res.bounces.size(), 19u);
  EXPECT_EQ(res.stop, sequence::StopReason::min_approach_speed);
  for (const auto& b : res.bounces) EXPECT_DOUBLE_EQ(b.after.velocity_m_s.x(), 1.0);  // frictionless
  sequence::SequenceInput few = input_with(ball, e);
  few.max_impacts = 3;
  const sequence::SequenceResult capped = sequence::run_sequence(few);
  EXPECT_EQ(capped.bounces.size(), 3u);
  EXPECT_EQ(capped.stop, sequence::StopReason::max_impacts);
}

TEST(Sequence, SlapdownFarEndInTheFlatLimit) {
  // A thin body with a rod's inertia (I = m L^2 / 12, L = 2a) dropped nearly flat: the near end hits
  // at v0, the far end then slaps down at (1.5 + 0.5 e) v0 (BEYOND_HERTZ.md, "Drop sequences").
  // Tolerance: the tilt (O(theta^2) in the arms), the support point's offset from the tip
  // (O((b / (a theta))^2)) and gravity during the short rotation (O(g dt / v0)).
  constexpr double kFlatLimitTolerance = 5e-3;
  const double a = 0.5, b = 0.0005, theta = 0.05, e = 0.6, h = 20.0;
  auto rod = ellipsoid_body(a, b, b, 1.0);
  rod.inertia_kg_m2 = Vector3d(0.4 * b * b, a * a / 3, a * a / 3).asDiagonal();
  rod.pose.rotation = Eigen::AngleAxisd(theta, Vector3d::UnitY()).toRotationMatrix();  // +x end low
  rod.pose.position_m = Vector3d(1, 2, h + a * std::sin(theta) + b);
  sequence::SequenceInput in = input_with(rod, e);
  in.max_impacts = 2;
  const sequence::SequenceResult res = sequence::run_sequence(in);
  ASSERT_EQ(res.bounces.size(), 2u);
  const double v0 = res.bounces[0].approach_velocity_m_s;
  EXPECT_GT(res.bounces[0].point_own_m.x(), 0.99 * a);   // the low end
  EXPECT_LT(res.bounces[1].point_own_m.x(), -0.99 * a);  // the far end
  EXPECT_NEAR(res.bounces[1].approach_velocity_m_s / v0, 1.5 + 0.5 * e, kFlatLimitTolerance);
  EXPECT_EQ(res.worst_impact_index, 1);
}

TEST(Sequence, EnergyIsConstantBetweenImpacts) {
  auto part = ellipsoid_body(0.125, 0.015, 0.03, 0.5);
  part.pose.rotation = Eigen::AngleAxisd(0.2, Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  part.pose.position_m = Vector3d(-40, 25, 0.8);  // far from the origin
  part.velocity_m_s = Vector3d(0.3, 0.0, 0.0);
  part.angular_velocity_rad_s = Vector3d(2.0, -5.0, 1.0);
  sequence::SequenceInput in = input_with(part, 0.7);
  in.max_impacts = 6;
  const sequence::SequenceResult res = sequence::run_sequence(in);
  ASSERT_GE(res.bounces.size(), 3u);
  const Vector3d g = in.gravity_m_s2;
  const double scale = part.mass_kg * 9.81 * 0.8;  // the drop's energy
  // Between two impacts (the states after one impact up to just before the next).
  double E = sequence::mechanical_energy_J(part, res.trajectory.front().state, g);
  std::size_t checked = 0;
  for (std::size_t k = 1; k < res.trajectory.size(); ++k) {
    const BodyState& s = res.trajectory[k].state;
    const double Ek = sequence::mechanical_energy_J(part, s, g);
    if (s.time_s == res.trajectory[k - 1].state.time_s) {  // an impact: a new flight starts
      E = Ek;
      continue;
    }
    EXPECT_LT(std::abs(Ek - E), kFlightTolerance * scale) << "t = " << s.time_s;
    ++checked;
  }
  EXPECT_GT(checked, 100u);
  // Each impact loses energy, never gains.
  for (const auto& b : res.bounces) {
    EXPECT_LE(sequence::mechanical_energy_J(part, b.after, g), sequence::mechanical_energy_J(part, b.before, g) + 1e-12);
  }
}

// --- energy: never gained, and the rest rule -------------------------------------------------

// The kinetic energy of the body at `s`, J.
double kinetic_J(const contact::PreparedBody& body, const BodyState& s) {
  return 0.5 * body.mass_kg * s.velocity_m_s.squaredNorm() +
         0.5 * s.angular_velocity_rad_s.dot(sequence::angular_momentum(body, s));
}

TEST(SequenceEnergy, BallWithoutMinimumApproachSpeedComesToRestNeverArrivingFasterThanItLeft) {
  // Issue 43: e = 0.5 and min_approach_speed_m_s = 0. The flights shrink as e^2k; once one is shorter
  // than the search resolves the body is at rest (kRestHeightRelative), instead of sinking a gap
  // tolerance into the floor per bounce and arriving at twice its departure speed for ever.
  const double r = 0.01, h = 0.5, e = 0.5, g = 9.81;
  auto ball = ellipsoid_body(r, r, r, 0.1);
  ball.pose.position_m = Vector3d(0, 0, r + h);
  sequence::SequenceInput in = input_with(ball, e);
  in.min_approach_speed_m_s = 0.0;
  in.max_impacts = sequence::kMaxImpactsLimit;
  const sequence::SequenceResult res = sequence::run_sequence(in);
  EXPECT_EQ(res.stop, sequence::StopReason::at_rest);
  EXPECT_NE(res.stop_detail.find("rest_height_m"), std::string::npos) << res.stop_detail;
  const double h_rest = sequence::kRestHeightRelative * 2 * r;
  EXPECT_DOUBLE_EQ(res.rest_height_m, h_rest);
  // The k-th flight rises h e^(2k): the last computed impact is the last whose flight before it
  // rose above h_rest (k <= 12 here: 0.5 m x 0.25^12 = 3e-8 m > 2e-8 m > 0.25^13 x 0.5 m).
  const std::size_t expected = static_cast<std::size_t>(std::floor(std::log(h_rest / h) / std::log(e * e))) + 1;
  EXPECT_EQ(res.bounces.size(), expected);
  const double tol = sequence::kGapToleranceRelative * 2 * r;
  for (std::size_t k = 1; k < res.bounces.size(); ++k) {
    const double left = res.bounces[k - 1].after.velocity_m_s.z(), arrived = -res.bounces[k].before.velocity_m_s.z();
    // A ballistic flight from the floor back to it: the same speed, up to the gap tolerance's fall.
    EXPECT_LE(arrived * arrived, left * left + 2 * g * 2 * tol) << k;
    EXPECT_GE(res.bounces[k].before.centroid_m.z() - r, -tol) << "impact " << k << " is inside the floor";
  }
}

// A box [-h, h] as 12 triangles: sharp corners and edges, flat faces (the rigid impulse).
std::shared_ptr<const geometry::Shape> box_shape(const Vector3d& h) {
  geometry::TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices_m.push_back(Vector3d(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z()));
  for (const std::array<int, 3>& t : std::vector<std::array<int, 3>>{{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                                                     {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                                                     {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}}) {
    m.triangles.push_back(t);
  }
  const auto mass = geometry::compute_mass_properties(m, geometry::label_shells(m));
  return std::make_shared<geometry::MeshShape>(m, mass);
}

TEST(SequenceEnergy, RandomBodiesNeverGainEnergyBounceAfterBounceUntilRest) {
  // Random ellipsoids and boxes, orientations, spins, restitutions in [0, 1] and friction, each
  // dropped with min_approach_speed_m_s = 0 until it rests (or 400 impacts at e = 1, which never
  // rests). The body's mechanical energy (kinetic + potential) may only fall: across every impact
  // to rounding (kImpactRounding), across every flight to the flight's stated accuracy
  // (kFlightTolerance); and no contact lies more than the gap tolerance inside the floor.
  constexpr double kImpactRounding = 1e-12;  // relative to the drop's energy: a few ulps of the sums
  constexpr int kCases = 48;
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  int bounces = 0, at_rest = 0;
  double worst_gain = -std::numeric_limits<double>::infinity(), deepest = 0;
  for (int c = 0; c < kCases; ++c) {
    const bool box = c % 3 == 2;
    const Vector3d axes(0.005 + 0.1 * u(rng), 0.005 + 0.1 * u(rng), 0.005 + 0.1 * u(rng));
    const double mass = 7800 * 4.0 / 3.0 * M_PI * axes.prod();
    auto body = box ? contact::body_of_mass("box", box_shape(axes), mass, kSteel)
                    : ellipsoid_body(axes.x(), axes.y(), axes.z(), mass);
    body.pose.rotation = Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
    body.pose.position_m = Vector3d(u(rng), u(rng), 2 * axes.norm() + 0.5 * u(rng));
    body.velocity_m_s = Vector3d(n(rng), n(rng), -std::abs(n(rng)));
    body.angular_velocity_rad_s = 10 * Vector3d(n(rng), n(rng), n(rng));
    const double e = c == 0 ? 0.0 : c == 1 ? 1.0 : u(rng);
    sequence::SequenceInput in = input_with(body, e);
    in.friction_coefficient = c % 2 ? 0.0 : u(rng);
    in.min_approach_speed_m_s = 0.0;
    in.max_impacts = e == 1.0 ? 400 : sequence::kMaxImpactsLimit;
    const Vector3d g = in.gravity_m_s2;
    const double size = body.shape->size_m(), tol = sequence::kGapToleranceRelative * size;
    const double scale = sequence::mechanical_energy_J(body, sequence::state_of(body), g) + body.mass_kg * 9.81 * size;
    sequence::SequenceResult res;
    try {
      res = sequence::run_sequence(in);
    } catch (const InputError& err) {
      ADD_FAILURE() << "case " << c << ": " << err.what();
      continue;
    }
    const std::string what = "case " + std::to_string(c) + (box ? " (box)" : " (ellipsoid)") + ", e = " +
                             std::to_string(e) + ", mu = " + std::to_string(in.friction_coefficient);
    if (e < 1.0) EXPECT_NE(res.stop, sequence::StopReason::max_impacts) << what;
    at_rest += res.stop == sequence::StopReason::at_rest;
    double E = sequence::mechanical_energy_J(body, res.trajectory.front().state, g);
    for (std::size_t k = 1; k < res.trajectory.size(); ++k) {
      const double Ek = sequence::mechanical_energy_J(body, res.trajectory[k].state, g);
      const bool impact = res.trajectory[k].state.time_s == res.trajectory[k - 1].state.time_s;
      const double gain = (Ek - E) / scale;
      worst_gain = std::max(worst_gain, gain);
      EXPECT_LE(gain, impact ? kImpactRounding : kFlightTolerance) << what << ", t = " << res.trajectory[k].state.time_s;
      E = Ek;
    }
    for (const auto& b : res.bounces) {
      const double gap = sequence::floor_gap_m(*body.shape, body.volume.centroid_m, b.before, sequence::Floor{});
      deepest = std::min(deepest, gap / tol);
      EXPECT_GE(gap, -tol) << what << ": impact at t = " << b.time_s << " inside the floor";
      EXPECT_LE(kinetic_J(body, b.after), kinetic_J(body, b.before) * (1 + kImpactRounding) + kImpactRounding * scale) << what;
    }
    bounces += static_cast<int>(res.bounces.size());
  }
  std::printf("energy property: %d cases, %d bounces, %d at rest, worst relative energy gain %.3g, deepest contact "
              "%.3g gap tolerances\n",
              kCases, bounces, at_rest, worst_gain, -deepest);
}

TEST(Sequence, RefusesBadInput) {
  auto ball = ellipsoid_body(0.01, 0.01, 0.01, 0.1);
  ball.pose.position_m = Vector3d(0, 0, 0.5);
  auto expect_place = [](sequence::SequenceInput in, const std::string& place) {
    try {
      sequence::run_sequence(in);
      ADD_FAILURE() << "no error for " << place;
    } catch (const InputError& e) {
      EXPECT_EQ(e.place(), place) << e.what();
    }
  };
  sequence::SequenceInput in = input_with(ball, 0.5);
  in.gravity_m_s2 = Vector3d(0, 0, 9.81);
  expect_place(in, "gravity_m_s2");
  in.gravity_m_s2 = Vector3d::Zero();
  expect_place(in, "gravity_m_s2");
  in = input_with(ball, 0.5);
  in.friction_coefficient = -0.1;
  expect_place(in, "friction_coefficient");
  in = input_with(ball, 0.5);
  in.floor = ellipsoid_body(1, 1, 1, std::numeric_limits<double>::infinity());
  expect_place(in, "floor");
  in = input_with(ball, 0.5);
  in.body.pose.position_m = Vector3d(0, 0, 0.005);
  expect_place(in, "body");
}

}  // namespace

// --- against an independent integration -----------------------------------------------------

namespace {

// A tilted ellipsoid dropped on z = 0, written out here independently of sequence/: the rotation
// by fixed-step RK4 of R' = [w]x R with w = R I^-1 R^T L (L constant in flight), the contact by a
// scan of the ellipsoid's closed-form depth sqrt(z^T R M R^T z) (M = diag(a^2, b^2, c^2)) and
// bisection, the impulse (1 + e) m_w v_w (Eq. 13, 16-23) with a constant restitution.
struct Reference {
  double m, a, b, c, e, g = 9.81;
  Matrix3d I;  // own frame
  struct State {
    Vector3d x, v;
    Matrix3d R;
    Vector3d L;
  };
  Vector3d omega(const State& s) const { return s.R * I.inverse() * s.R.transpose() * s.L; }
  State step(const State& s, double h) const {
    auto f = [&](const Matrix3d& R) {
      const Vector3d w = R * I.inverse() * R.transpose() * s.L;
      Matrix3d W;
      W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
      return Matrix3d(W * R);
    };
    const Matrix3d k1 = f(s.R), k2 = f(s.R + 0.5 * h * k1), k3 = f(s.R + 0.5 * h * k2), k4 = f(s.R + h * k3);
    State o = s;
    o.R = s.R + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    const Eigen::JacobiSVD<Matrix3d> svd(o.R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    o.R = svd.matrixU() * svd.matrixV().transpose();  // back onto SO(3)
    o.x = s.x + s.v * h + 0.5 * h * h * Vector3d(0, 0, -g);
    o.v = s.v + h * Vector3d(0, 0, -g);
    return o;
  }
  Vector3d lowest(const State& s) const {
    const Matrix3d M = Vector3d(a * a, b * b, c * c).asDiagonal();
    const Vector3d q = s.R * M * s.R.transpose() * Vector3d::UnitZ();
    return s.x - q / std::sqrt(Vector3d::UnitZ().dot(q));
  }
  double gap(const State& s) const { return lowest(s).z(); }
  // Flies from s to the next contact (approaching), scanning with step h.
  State next(State s, double& t, double h) const {
    for (;;) {
      State n = step(s, h);
      const Vector3d r = lowest(n) - n.x;
      if (gap(n) <= 0 && (n.v + omega(n).cross(r)).z() < 0) {
        double lo = 0, hi = h;
        for (int k = 0; k < 60; ++k) (gap(step(s, 0.5 * (lo + hi))) > 0 ? lo : hi) = 0.5 * (lo + hi);
        t += lo;
        return step(s, lo);
      }
      s = n;
      t += h;
    }
  }
  void bounce(State& s) const {
    const Vector3d n = Vector3d::UnitZ(), r = lowest(s) - s.x;
    const Matrix3d Iw_inv = s.R * I.inverse() * s.R.transpose();
    const double inv_mw = 1 / m + r.cross(n).dot(Iw_inv * r.cross(n));
    const double vw = -(s.v + omega(s).cross(r)).dot(n);
    const double P = (1 + e) * vw / inv_mw;
    s.v += P * n / m;
    s.L += r.cross(P * n);  // the impulse's moment about the centroid
  }
};

}  // namespace

TEST(Sequence, TiltedEllipsoidAgreesWithAnIndependentIntegration) {
  const double a = 0.125, b = 0.015, c = 0.03, mass = 0.5, e = 0.6;
  auto part = ellipsoid_body(a, b, c, mass);
  part.pose.rotation = Eigen::AngleAxisd(0.35, Vector3d(1, 0.4, 0.2).normalized()).toRotationMatrix();
  part.pose.position_m = Vector3d(0, 0, 0.5);
  part.angular_velocity_rad_s = Vector3d(1.0, -3.0, 0.5);
  sequence::SequenceInput in = input_with(part, e);
  in.max_impacts = 4;
  const sequence::SequenceResult res = sequence::run_sequence(in);
  ASSERT_EQ(res.bounces.size(), 4u);

  Reference ref{mass, a, b, c, e};
  ref.I = part.inertia_kg_m2;
  Reference::State s{part.pose.position_m, Vector3d::Zero(), part.pose.rotation,
                     part.pose.rotation * part.inertia_kg_m2 * part.pose.rotation.transpose() *
                         part.angular_velocity_rad_s};
  double t = 0;
  // Tolerances: the reference's RK4 at 2e-5 s steps (error ~ (w h)^4 per step) and its bisection.
  constexpr double kTimeTolerance = 1e-8, kVelocityTolerance = 1e-6;
  for (std::size_t k = 0; k < res.bounces.size(); ++k) {
    s = ref.next(s, t, 2e-5);
    const auto& b = res.bounces[k];
    EXPECT_NEAR(b.time_s, t, kTimeTolerance) << k;
    EXPECT_LT((b.contact.point_m - ref.lowest(s)).norm(), 1e-7) << k;
    ref.bounce(s);
    const double scale = std::max(1.0, s.v.norm());
    EXPECT_LT((b.after.velocity_m_s - s.v).norm(), kVelocityTolerance * scale) << k;
    EXPECT_LT((b.after.angular_velocity_rad_s - ref.omega(s)).norm(), kVelocityTolerance * 100 * scale) << k;
  }
}

// --- scenes ---------------------------------------------------------------------------------

namespace {

std::string scene_text(const std::string& body, const std::string& sequence, const std::string& gravity = "[0, 0, -9.81]") {
  return R"(length_unit = "mm"
gravity_m_s2 = )" + gravity + R"(
[materials.steel]
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
density_kg_m3 = 7850
yield_strength_Pa = 3.5e8

[[bodies]]
)" + body + R"(
material = "steel"

[[bodies]]
name = "floor"
shape = "plane"
normal = [0, 0, 1]
material = "steel"

[[sequences]]
name = "drop"
body = "part"
floor = "floor"
)" + sequence;
}

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(d);
  return d;
}

}  // namespace

TEST(SequenceScene, SequencesOnlySceneRunsAndWritesItsFiles) {
  const scene::Scene sc = scene::parse_scene(
      scene_text("name = \"part\"\nshape = \"sphere\"\nradius = 10\nposition = [0, 0, 500]", "restitution = 0.8\n"),
      "seq.toml");
  EXPECT_TRUE(sc.impacts.empty());
  ASSERT_EQ(sc.sequences.size(), 1u);
  const auto out = fresh_dir("impactdeck_test_sequence_files");
  const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{out});
  ASSERT_EQ(r.sequences.size(), 1u);
  EXPECT_EQ(r.sequences[0].result.bounces.size(), 19u);  // e = 0.8 from 0.49 m: as the sphere test above
  const nlohmann::json j = scene::to_json(sc, r);
  ASSERT_EQ(j["sequences"].size(), 1u);
  const auto& q = j["sequences"][0];
  EXPECT_EQ(q["stop_reason"], "at_rest");
  EXPECT_NE(q["stop_detail"].get<std::string>().find("kinetic energy"), std::string::npos) << q["stop_detail"];
  EXPECT_DOUBLE_EQ(q["rest_height_m"].get<double>(), sequence::kRestHeightRelative * 0.02);  // the 20 mm ball
  EXPECT_EQ(q["worst_impact_index"], 0);
  const auto& i0 = q["impacts"][0];
  for (const char* key : {"contact_point_m", "approach_velocity_m_s", "reduced_mass_kg", "max_force_N",
                          "normal_impulse_Ns", "tangential_impulse_Ns", "time_s", "target", "impactor"}) {
    EXPECT_TRUE(i0.contains(key)) << key;
  }
  EXPECT_EQ(i0["target"]["name"], "part");
  EXPECT_TRUE(i0["target"].contains("delta_velocity_m_s"));
  EXPECT_TRUE(i0["target"].contains("delta_angular_velocity_rad_s"));
  EXPECT_EQ(i0["tangential_impulse_Ns"], nlohmann::json::array({0.0, 0.0, 0.0}));
  EXPECT_GT(i0["max_force_N"].get<double>(), 0.0);
  // The sequence's impact is the single impact's writer: a Hertz impact's own figures are there.
  EXPECT_DOUBLE_EQ(i0["impulse_total_Ns"].get<double>(), i0["normal_impulse_Ns"].get<double>());
  const auto stages = j["stages_run"];
  EXPECT_NE(std::find(stages.begin(), stages.end(), "sequence"), stages.end());
  for (const char* f : {"sequence_drop.csv", "sequence_drop.csv.json", "sequence_drop.pvd", "sequence_drop.svg",
                        "report.html", "sequence_drop_frames/frame_0000.vtp"}) {
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  }
  EXPECT_GT(r.sequences[0].vtk_frames, 1u);
  EXPECT_LE(r.sequences[0].vtk_frames, 120u);
}

TEST(SequenceScene, PlasticLawRecordsTheDentOfAnEarlierImpact) {
  // The vertical bounces of a sphere land on the same spot: from the second impact on, inside the
  // first one's dent (the law "jackson-green-sneddon", chosen by "auto" from the yield strength).
  const scene::Scene sc = scene::parse_scene(
      scene_text("name = \"part\"\nshape = \"sphere\"\nradius = 10\nposition = [0, 0, 500]", "max_impacts = 3\n"),
      "seq.toml");
  const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{fresh_dir("impactdeck_test_sequence_dent")});
  const auto& b = r.sequences[0].result.bounces;
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(r.sequences[0].impacts[0].contact_law, "jackson-green-sneddon");
  EXPECT_GT(b[0].dent_radius_m, 0.0);
  EXPECT_EQ(b[0].in_dent_of, -1);
  EXPECT_EQ(b[1].in_dent_of, 0);
  EXPECT_EQ(b[2].in_dent_of, 0);
}

TEST(SequenceScene, MeshPartOnItsCornersGoesOnWithTheRigidImpulse) {
  // A real CAD-like part (tests/data/box_200x100x60mm.stl), rotated and far from the origin: it
  // lands on corners, where no Hertz force exists: flagged, null in JSON, the sequence goes on.
  const std::string part = std::string("name = \"part\"\nshape = \"mesh\"\nmesh = \"") + IMPACTDECK_SOURCE_DIR +
                           "/tests/data/box_200x100x60mm.stl\"\nposition = [-40000, 25000, 300]\n"
                           "orientation_axis = [1, 0.5, 0.2]\norientation_angle_deg = 35";
  const scene::Scene sc = scene::parse_scene(scene_text(part, "restitution = 0.5\nmax_impacts = 6\n"), "seq.toml");
  const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{fresh_dir("impactdeck_test_sequence_mesh")});
  const auto& sr = r.sequences[0];
  ASSERT_GE(sr.result.bounces.size(), 2u);
  std::size_t corners = 0, sharp = 0;
  for (const auto& b : sr.result.bounces) {
    if (!b.not_applicable.empty()) {
      ++corners;
      EXPECT_FALSE(b.impact.has_value());
      EXPECT_TRUE(std::isnan(b.max_force_N()));
      EXPECT_NEAR(b.restitution, 0.5, 0.0);
      EXPECT_GT(b.normal_impulse_Ns, 0.0);
      // Why, in the kernel's words (collision::explain_flag, as run's refusal says it), naming the part.
      if (b.contact.result.flag == collision::ContactFlag::sharp) {
        ++sharp;
        EXPECT_EQ(b.not_applicable.find("the contact point lies on a sharp edge or corner of 'part'"), 0u)
            << b.not_applicable;
      }
    }
  }
  EXPECT_GT(corners, 0u);
  EXPECT_GT(sharp, 0u);
  const nlohmann::json j = scene::to_json(sc, r);
  bool null_force = false;
  for (const auto& i : j["sequences"][0]["impacts"]) null_force = null_force || i["max_force_N"].is_null();
  EXPECT_TRUE(null_force);
  bool warned = false;
  for (const auto& w : r.warnings) warned = warned || w.find("edge_radius") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_EQ(sr.result.worst_impact_reason.find("largest"), 0u);
}

TEST(SequenceScene, BadKeysAreRefusedNamingThem) {
  auto refused = [](const std::string& text, const std::string& key) {
    try {
      scene::parse_scene(text, "seq.toml");
      ADD_FAILURE() << "accepted; expected an error naming " << key;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  const std::string sphere = "name = \"part\"\nshape = \"sphere\"\nradius = 10\nposition = [0, 0, 500]";
  refused(scene_text(sphere, "friction_coefficient = -0.1\n"), "sequences[0].friction_coefficient");
  refused(scene_text(sphere, "max_impacts = 0\n"), "sequences[0].max_impacts");
  refused(scene_text(sphere, "contact_law = \"thornto\"\n"), "sequences[0].contact_law");  // the impacts' reader
  refused(scene_text(sphere, "restitution = 1.5\n"), "sequences[0].restitution");
  refused(scene_text(sphere, "bounce = 1\n"), "sequences[0].bounce");
  std::string no_gravity = scene_text(sphere, "");
  no_gravity.replace(no_gravity.find("gravity_m_s2"), std::string("gravity_m_s2 = [0, 0, -9.81]").size(), "");
  refused(no_gravity, "gravity_m_s2");
}

// --- friction (collision::solve_frictional_impact in apply_bounce) ----------------------------

TEST(SequenceFriction, SphereSlidingOnARoughFloorSpinsAsTheClosedForm) {
  // A solid sphere (R 20 mm) with a sideways drift lands on a rough floor (mu 0.1, e 0.6): in gross
  // slip the first bounce gives it the spin 2.5 mu (1 + e) V_n / R about the axis n x drift
  // (BEYOND_HERTZ.md), its drift drops by mu (1 + e) V_n, and no bounce gains energy.
  const double R = 0.02, mu = 0.1, e = 0.6;
  auto body = ellipsoid_body(R, R, R, 0.5);
  body.pose.position_m = Vector3d(3.0, -2.0, 0.3);
  body.velocity_m_s = Vector3d(2.0, 0.0, 0.0);
  sequence::SequenceInput in = input_with(body, e);
  in.friction_coefficient = mu;
  in.max_impacts = 4;
  const sequence::SequenceResult r = sequence::run_sequence(in);
  ASSERT_GE(r.bounces.size(), 2u);
  const sequence::Bounce& b = r.bounces[0];
  ASSERT_TRUE(b.friction.has_value());
  const double vn = b.approach_velocity_m_s;
  // The closed forms hold to the frictional solver's closed-form (constant slip direction) rounding.
  constexpr double kClosedFormRel = 1e-9;
  EXPECT_NEAR(b.after.angular_velocity_rad_s.y(), 2.5 * mu * (1 + e) * vn / R, kClosedFormRel * vn / R);
  EXPECT_NEAR(b.after.angular_velocity_rad_s.x(), 0.0, kClosedFormRel * vn / R);
  EXPECT_NEAR(b.after.velocity_m_s.x(), 2.0 - mu * (1 + e) * vn, kClosedFormRel * vn);
  EXPECT_NEAR(b.after.velocity_m_s.z(), e * vn, kClosedFormRel * vn);
  EXPECT_NEAR(b.tangential_impulse_Ns.x(), mu * b.normal_impulse_Ns, kClosedFormRel * b.normal_impulse_Ns);
  ASSERT_FALSE(b.friction->slip_history.empty());
  EXPECT_EQ(b.friction->slip_history.front(), collision::SlipEvent::slides);
  for (const auto& x : r.bounces) EXPECT_GE(x.energy_lost_J, 0.0);
  // Frictionless, the same drop keeps its drift and gets no spin.
  in.friction_coefficient = 0;
  const sequence::SequenceResult f = sequence::run_sequence(in);
  EXPECT_EQ(f.bounces[0].after.velocity_m_s.x(), 2.0);
  EXPECT_EQ(f.bounces[0].after.angular_velocity_rad_s.norm(), 0.0);
}
