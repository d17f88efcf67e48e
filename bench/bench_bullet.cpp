// The same drops in Bullet, a rigid-body engine users know (Debian's libbullet-dev, double
// precision: bullet-float64), against our event-driven sequence and the closed forms (issue 31
// item 7). Bullet resolves a contact inside fixed time steps with Newton restitution; we find each
// contact's instant and apply the impact's jump there.
//   1. A steel sphere (radius 20 mm) dropped 1 m onto a floor, e = 0.8: impact k approaches at
//      v_k = sqrt(2 g h) e^k, jumps by (1 + e) v_k, and rebounds to e^(2k) h.
//   2. A slender rod (a 300 x 2 x 2 mm ellipsoid here, a capsule of the same length in Bullet)
//      dropped nearly flat (2 deg) from 0.2 m, e = 0.5: the first impact at its low end, then the
//      slapdown of its far end, each against the flat limit for the body's own inertia (a rod's:
//      (1.5 + 0.5 e) v0).
// Bullet settings: btDefaultCollisionConfiguration, btCollisionDispatcher, btDbvtBroadphase,
// btSequentialImpulseConstraintSolver (10 iterations, its default), split impulse on (default),
// fixed steps 1/240 s and 1e-4 s (stepSimulation(dt, 0): no interpolation), restitution = the
// product of both bodies' (floor 1, body e), friction 0, no damping, no sleeping, the shapes'
// own margins (a sphere's and a capsule's margin is their radius: exact).
// Impacts in Bullet: runs of steps where the centre's vertical velocity rises above free fall
// (bullet_impacts).
//   bench_bullet     (Markdown on stdout)
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <btBulletDynamicsCommon.h>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/contact/body.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/sequence/sequence.hpp"

using namespace impactdeck;

namespace {

constexpr double kG = 9.81;
const collision::ElasticMaterial kSteel{210e9, 0.3};

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// One Bullet world: a floor at z = 0 and one body.
struct World {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  btStaticPlaneShape floor_shape{btVector3(0, 0, 1), 0};
  btRigidBody floor{btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &floor_shape)};
  std::unique_ptr<btCollisionShape> shape;
  std::unique_ptr<btRigidBody> body;

  World(std::unique_ptr<btCollisionShape> s, double mass, const btTransform& pose, double e) : shape(std::move(s)) {
    world.setGravity(btVector3(0, 0, -kG));
    floor.setRestitution(1.0);
    floor.setFriction(0.0);
    world.addRigidBody(&floor);
    btVector3 inertia(0, 0, 0);
    shape->calculateLocalInertia(mass, inertia);
    btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape.get(), inertia);
    info.m_startWorldTransform = pose;
    info.m_restitution = e;
    info.m_friction = 0.0;
    body = std::make_unique<btRigidBody>(info);
    body->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(body.get());
  }
  ~World() {
    world.removeRigidBody(body.get());
    world.removeRigidBody(&floor);
  }
};

// Bullet's impacts: runs of steps in which the centre's vertical velocity rises above free fall
// (by more than 1e-9 m/s: a contact resolved over several steps is one impact). Each: the centre's
// vertical jump (its rise above free fall, summed over the run) and the vertical velocity of the
// point `end` (body frame) just before the run.
struct BulletImpact {
  double jump = 0, end_velocity_before = 0;
};
std::vector<BulletImpact> bullet_impacts(World& w, double dt, int impacts, double duration_s, const btVector3& end) {
  std::vector<BulletImpact> out;
  bool in_contact = false;
  double v_prev = w.body->getLinearVelocity().z(), end_prev = 0;
  for (long step = 0; step < static_cast<long>(duration_s / dt); ++step) {
    w.world.stepSimulation(dt, 0);
    const btVector3 vc = w.body->getLinearVelocity();
    const double excess = vc.z() - v_prev + kG * dt;
    const btVector3 arm = w.body->getWorldTransform().getBasis() * end;
    const double v_end = (vc + w.body->getAngularVelocity().cross(arm)).z();
    if (excess > 1e-9) {
      if (!in_contact) {
        if (static_cast<int>(out.size()) == impacts) break;
        out.push_back({0.0, end_prev});
      }
      out.back().jump += excess;
      in_contact = true;
    } else {
      in_contact = false;
    }
    v_prev = vc.z();
    end_prev = v_end;
  }
  if (in_contact) out.pop_back();  // still in contact at the end: not a whole impact
  return out;
}

sequence::SequenceInput our_input(contact::PreparedBody body, double e, int impacts) {
  sequence::SequenceInput in;
  in.body = std::move(body);
  in.floor = contact::body_of_mass("floor", std::make_shared<geometry::Plane>(Eigen::Vector3d::UnitZ()),
                                   std::numeric_limits<double>::infinity(), kSteel);
  in.gravity_m_s2 = Eigen::Vector3d(0, 0, -kG);
  in.effective_modulus_Pa = collision::effective_modulus_Pa(kSteel, kSteel, collision::ModulusConvention::hertz);
  collision::RestitutionModel r;
  r.kind = collision::RestitutionModel::Kind::constant;
  r.constant = e;
  in.law = std::make_shared<collision::HertzLaw>(r);
  in.rigid_restitution = e;
  in.max_impacts = impacts;
  in.min_approach_speed_m_s = 1e-3;
  return in;
}

void sphere_section() {
  const double R = 0.02, h = 1.0, e = 0.8, mass = 7850 * 4.0 / 3.0 * M_PI * R * R * R;
  const int impacts = 5;
  std::printf("## A sphere bouncing vertically (R = 20 mm steel, h = 1 m to its lowest point, e = 0.8)\n\n"
              "Velocity jump of impact k, m/s (closed form (1 + e) sqrt(2 g h) e^k), and the relative error of each.\n\n");
  std::vector<double> exact;
  for (int k = 0; k < impacts; ++k) exact.push_back((1 + e) * std::sqrt(2 * kG * h) * std::pow(e, k));

  // Ours.
  auto ball = contact::body_of_mass("ball", std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(R)), mass, kSteel);
  ball.pose.position_m = Eigen::Vector3d(0, 0, h + R);
  const auto in = our_input(ball, e, impacts);
  double t0 = now_s();
  const auto res = sequence::run_sequence(in);
  const double ours_s = now_s() - t0;
  std::vector<double> ours;
  for (const auto& b : res.bounces) ours.push_back(b.after.velocity_m_s.z() - b.before.velocity_m_s.z());

  std::printf("| impact | closed form | ours | error | Bullet 240 Hz | error | Bullet 10 kHz | error |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<std::vector<double>> bullet;
  std::vector<double> bullet_s;
  for (double dt : {1.0 / 240, 1e-4}) {
    btTransform pose;
    pose.setIdentity();
    pose.setOrigin(btVector3(0, 0, h + R));
    World w(std::make_unique<btSphereShape>(R), mass, pose, e);
    std::vector<double> jumps;
    t0 = now_s();
    for (const auto& i : bullet_impacts(w, dt, impacts, 6.0, btVector3(0, 0, 0))) jumps.push_back(i.jump);
    bullet_s.push_back(now_s() - t0);
    bullet.push_back(jumps);
  }
  auto cell = [](const std::vector<double>& v, int k, double ref) {
    char b[64];
    if (k < static_cast<int>(v.size())) std::snprintf(b, sizeof b, "%.6f | %.1e", v[k], std::abs(v[k] - ref) / ref);
    else std::snprintf(b, sizeof b, "- | -");
    return std::string(b);
  };
  for (int k = 0; k < impacts; ++k)
    std::printf("| %d | %.6f | %s | %s | %s |\n", k, exact[k], cell(ours, k, exact[k]).c_str(), cell(bullet[0], k, exact[k]).c_str(),
                cell(bullet[1], k, exact[k]).c_str());
  std::printf("\nWall time for the %d impacts: ours %.2f ms, Bullet 240 Hz %.2f ms, Bullet 10 kHz %.2f ms.\n\n", impacts,
              1e3 * ours_s, 1e3 * bullet_s[0], 1e3 * bullet_s[1]);
}

void rod_section() {
  // A needle: 300 mm long, 2 mm thick, tilted 2 deg, so that the ellipsoid touches near its tip.
  const double a = 0.15, r = 0.001, h = 0.2, e = 0.5, tilt = 2.0 * M_PI / 180;
  const double mass = 7850 * 4.0 / 3.0 * M_PI * a * r * r;
  const double v0 = std::sqrt(2 * kG * h);
  // The flat limit of a body of gyration radius k touching at distance d from its centre: the
  // centre jumps by (1 + e) v0 / (1 + d^2/k^2); the far end (at -d) then approaches at
  // v0 (1 + (1 + e)(d^2/k^2 - 1)/(1 + d^2/k^2)); a uniform rod (d^2/k^2 = 3): (1.5 + 0.5 e) v0.
  auto flat = [&](double d2_over_k2) {
    return std::pair<double, double>{(1 + e) * v0 / (1 + d2_over_k2), v0 * (1 + (1 + e) * (d2_over_k2 - 1) / (1 + d2_over_k2))};
  };
  std::printf("## A slender rod's slapdown (300 mm long, 2 mm thick, tilted 2 deg, lowest point 0.2 m up, e = 0.5)\n\n"
              "First impact: the centre's vertical jump; second impact: the far end's approach speed. Closed forms: the "
              "flat limit for the body's own d and k (a rod: (1.5 + 0.5 e) v0 = %.4f m/s, v0 = %.4f m/s).\n\n",
              (1.5 + 0.5 * e) * v0, v0);
  std::printf("| model | first: centre jump, m/s | flat limit | second: far end approach, m/s | flat limit | wall time |\n"
              "|---|---:|---:|---:|---:|---:|\n");
  const Eigen::Matrix3d Rt = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()).toRotationMatrix();
  {  // Ours: the ellipsoid needle, k^2 = (a^2 + r^2)/5, d the x of its support point.
    auto rod = contact::body_of_mass("rod", std::make_shared<geometry::Ellipsoid>(a, r, r), mass, kSteel);
    rod.pose.rotation = Rt;
    const auto low = rod.shape->support_point(Rt.transpose() * Eigen::Vector3d(0, 0, -1));
    rod.pose.position_m = Eigen::Vector3d(0, 0, h) - Rt * low->point_m;
    const double d = low->point_m.x(), k2 = (a * a + r * r) / 5;
    const auto in = our_input(rod, e, 2);
    const double t0 = now_s();
    const auto res = sequence::run_sequence(in);
    const double s = now_s() - t0;
    const auto [jump, far] = flat(d * d / k2);
    if (res.bounces.size() >= 2) {
      const auto& b0 = res.bounces[0];
      std::printf("| ours, event-driven (ellipsoid; contact at x = %.3f a, then %.3f a) | %.4f | %.4f | %.4f | %.4f | %.2f ms |\n",
                  d / a, res.bounces[1].point_own_m.x() / a, (b0.after.velocity_m_s - b0.before.velocity_m_s).z(), jump,
                  res.bounces[1].approach_velocity_m_s, far, 1e3 * s);
    }
  }
  for (double dt : {1.0 / 240, 1e-4}) {  // Bullet: a capsule of the same length and thickness.
    const double L = 2 * a;
    btTransform pose;
    pose.setIdentity();
    const Eigen::Quaterniond q(Rt * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix());
    pose.setRotation(btQuaternion(q.x(), q.y(), q.z(), q.w()));
    // The low end's cap touches at Rt (L/2 - r, 0, 0) - (0, 0, r) from the centre.
    const Eigen::Vector3d c = Eigen::Vector3d(0, 0, h + r) - Rt * Eigen::Vector3d(L / 2 - r, 0, 0);
    pose.setOrigin(btVector3(c.x(), c.y(), c.z()));
    World w(std::make_unique<btCapsuleShapeZ>(r, L - 2 * r), mass, pose, e);
    btVector3 inertia;
    w.shape->calculateLocalInertia(mass, inertia);
    const double d = L / 2 - r, k2 = inertia.x() / mass;
    const double t0 = now_s();
    const auto imp = bullet_impacts(w, dt, 2, 2.0, btVector3(0, 0, -d));  // the far end: local -z
    const double s = now_s() - t0;
    const auto [jump, far] = flat(d * d / k2);
    std::printf("| Bullet %s (capsule, d^2/k^2 = %.2f) | %s | %.4f | %s | %.4f | %.2f ms |\n", dt > 1e-3 ? "240 Hz" : "10 kHz",
                d * d / k2, imp.size() > 0 ? std::to_string(imp[0].jump).c_str() : "-", jump,
                imp.size() > 1 ? std::to_string(-imp[1].end_velocity_before).c_str() : "-", far, 1e3 * s);
  }
  std::printf("\n");
}

}  // namespace

int main() {
  std::printf("Bullet %d (double precision), settings in bench/bench_bullet.cpp's header.\n\n", btGetVersion());
  sphere_section();
  rod_section();
  return 0;
}
