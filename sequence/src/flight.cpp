#include "impactdeck/sequence/flight.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::sequence {
namespace {

// GSL's default handler aborts; every status is checked here.
struct GslHandlerOff {
  GslHandlerOff() { gsl_set_error_handler_off(); }
};
const GslHandlerOff gsl_handler_off;

// The rotation in scaled time tau = Omega t, with u = omega_body / Omega (Omega: |omega| at the
// segment's start): y = (q_w, q_x, q_y, q_z, u_x, u_y, u_z),
//   dq/dtau = q (x) (0, u) / 2,   du/dtau = I^-1 ((I u) x u)   (Euler's equations, torque free).
struct Rotation {
  const Eigen::Matrix3d* inertia;
  const Eigen::Matrix3d* inverse;
};

int rotation_rhs(double /*tau*/, const double y[], double dydt[], void* params) {
  const auto& r = *static_cast<const Rotation*>(params);
  const Eigen::Vector3d qv(y[1], y[2], y[3]), u(y[4], y[5], y[6]);
  const double qw = y[0];
  dydt[0] = -0.5 * qv.dot(u);
  const Eigen::Vector3d dqv = 0.5 * (qw * u + qv.cross(u));
  const Eigen::Vector3d du = *r.inverse * ((*r.inertia * u).cross(u));
  for (int k = 0; k < 3; ++k) {
    dydt[1 + k] = dqv[k];
    dydt[4 + k] = du[k];
  }
  return GSL_SUCCESS;
}

}  // namespace

geometry::Pose BodyState::pose(const Eigen::Vector3d& centroid_own_m) const {
  geometry::Pose p;
  p.rotation = orientation.toRotationMatrix();
  p.position_m = centroid_m - p.rotation * centroid_own_m;
  return p;
}

BodyState state_of(const contact::PreparedBody& body) {
  BodyState s;
  s.centroid_m = body.centroid_world_m();
  s.velocity_m_s = body.velocity_m_s;
  s.orientation = Eigen::Quaterniond(body.pose.rotation).normalized();
  s.angular_velocity_rad_s = body.angular_velocity_rad_s;
  return s;
}

contact::PreparedBody placed(const contact::PreparedBody& body, const BodyState& s) {
  contact::PreparedBody b = body;
  b.pose = s.pose(body.volume.centroid_m);
  b.velocity_m_s = s.velocity_m_s;
  b.angular_velocity_rad_s = s.angular_velocity_rad_s;
  return b;
}

Eigen::Vector3d angular_momentum(const contact::PreparedBody& body, const BodyState& s) {
  const Eigen::Matrix3d R = s.orientation.toRotationMatrix();
  return R * (body.inertia_kg_m2 * (R.transpose() * s.angular_velocity_rad_s));
}

double mechanical_energy_J(const contact::PreparedBody& body, const BodyState& s, const Eigen::Vector3d& g) {
  return 0.5 * body.mass_kg * s.velocity_m_s.squaredNorm() +
         0.5 * s.angular_velocity_rad_s.dot(angular_momentum(body, s)) - body.mass_kg * g.dot(s.centroid_m);
}

Flight::Flight(const Eigen::Matrix3d& inertia, const Eigen::Vector3d& g, const InputContext& ctx) : g_(g), ctx_(ctx) {
  const double trace = inertia.trace();
  if (!(trace > 0.0) || !std::isfinite(trace)) throw ctx.error("inertia", "the body's inertia is not finite and positive");
  inertia_ = inertia / trace;  // scale-free: Euler's equations only see ratios
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(inertia_);
  if (!(es.eigenvalues().minCoeff() > 0.0)) throw ctx.error("inertia", "the body's inertia is not positive definite");
  inverse_ = inertia_.inverse();
  if (!g.allFinite()) throw ctx.error("gravity_m_s2", "must be finite");
}

BodyState Flight::advance(const BodyState& s, double dt) const {
  BodyState out = s;
  out.time_s = s.time_s + dt;
  // The centre: exact ballistic flight.
  out.centroid_m = s.centroid_m + s.velocity_m_s * dt + 0.5 * dt * dt * g_;
  out.velocity_m_s = s.velocity_m_s + g_ * dt;
  const double omega = s.angular_velocity_rad_s.norm();
  if (!(dt > 0.0) || !(omega > 0.0)) return out;
  // The rotation in the body frame, scaled by |omega|.
  const Eigen::Quaterniond q = s.orientation.normalized();
  const Eigen::Vector3d u = q.conjugate() * s.angular_velocity_rad_s / omega;
  double y[7] = {q.w(), q.x(), q.y(), q.z(), u.x(), u.y(), u.z()};
  Rotation r{&inertia_, &inverse_};
  gsl_odeiv2_system sys{rotation_rhs, nullptr, 7, &r};
  const double tau1 = omega * dt;
  gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, std::min(0.1, tau1),
                                                       kFlightRelativeTolerance, kFlightRelativeTolerance);
  if (!d) throw ctx_.error("flight", "cannot allocate the ODE driver");
  gsl_odeiv2_driver_set_nmax(d, kMaxFlightSteps);
  double tau = 0.0;
  const int status = gsl_odeiv2_driver_apply(d, &tau, tau1, y);
  gsl_odeiv2_driver_free(d);
  if (status != GSL_SUCCESS) {
    throw ctx_.error("flight", std::string("the rotation's integration failed (") + gsl_strerror(status) + ") over " +
                                   std::to_string(dt) + " s at " + std::to_string(omega) + " rad/s");
  }
  out.orientation = Eigen::Quaterniond(y[0], y[1], y[2], y[3]).normalized();
  out.angular_velocity_rad_s = out.orientation * (omega * Eigen::Vector3d(y[4], y[5], y[6]));
  return out;
}

double floor_gap_m(const geometry::Shape& shape, const Eigen::Vector3d& centroid_own, const BodyState& s,
                   const Floor& floor, geometry::SurfacePoint* support, double* rate) {
  const geometry::Pose pose = s.pose(centroid_own);
  const Eigen::Vector3d down_own = pose.direction_to_own(-floor.normal);
  std::optional<geometry::SurfacePoint> sp = shape.support_point(down_own);
  if (!sp) throw InputError("", "body", "the body is unbounded: it has no lowest point");
  sp->normal = down_own.normalized();
  const Eigen::Vector3d x = pose.to_world(sp->point_m);
  if (support) *support = *sp;
  if (rate) *rate = floor.normal.dot(s.velocity_m_s + s.angular_velocity_rad_s.cross(x - s.centroid_m));
  return floor.normal.dot(x - floor.point_m);
}

double max_radius_m(const geometry::Shape& shape, const Eigen::Vector3d& c) {
  if (const geometry::Ellipsoid* e = shape.analytic_ellipsoid()) return e->semi_axes_m().maxCoeff() + c.norm();
  if (const geometry::MeshShape* m = shape.triangle_mesh()) {
    double r = 0.0;
    for (const Eigen::Vector3d& v : m->mesh().vertices_m) r = std::max(r, (v - c).norm());
    return r;
  }
  return std::sqrt(3.0) * shape.size_m();
}

NextContact next_contact(const contact::PreparedBody& body, const Flight& flight, const BodyState& start,
                         const Floor& floor, double tol, const InputContext& ctx, double rest_height_m) {
  const geometry::Shape& shape = *body.shape;
  const Eigen::Vector3d& c_own = body.volume.centroid_m;
  const double r_max = max_radius_m(shape, c_own);
  // |omega| is bounded by the rotational energy (constant in flight) over the smallest moment.
  const Eigen::Matrix3d R0 = start.orientation.toRotationMatrix();
  const Eigen::Matrix3d I_world = R0 * body.inertia_kg_m2 * R0.transpose();
  const double rotational = start.angular_velocity_rad_s.dot(I_world * start.angular_velocity_rad_s);
  const double i_min = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(body.inertia_kg_m2).eigenvalues().minCoeff();
  const double omega_max = std::max(start.angular_velocity_rad_s.norm(), std::sqrt(std::max(0.0, rotational) / i_min));
  const double g_n = std::abs(floor.normal.dot(flight.gravity()));
  // A fall from the rest height and back: a body hovering within it longer never left the floor.
  const double rest_time = rest_height_m > 0.0 && g_n > 0.0 ? 2.0 * std::sqrt(2.0 * rest_height_m / g_n) : 0.0;
  NextContact nc;
  BodyState s = start, prev = start;
  for (long step = 0; step < kMaxSearchSteps; ++step) {
    double rate = 0.0;
    geometry::SurfacePoint sp;
    double h = floor_gap_m(shape, c_own, s, floor, &sp, &rate);
    if (!std::isfinite(h)) throw ctx.error("", "the body's gap to the floor is not finite");
    if (h < -tol && step > 0) {
      // A step within the rest band (below) passed the floor: back to the crossing by bisection
      // between the last state above it and this one, to |h| <= tol, so that a contact is always
      // found within the gap tolerance.
      BodyState lo = prev, hi = s;
      for (int it = 0; it < 200 && std::abs(h) > tol; ++it) {
        const BodyState mid = flight.advance(lo, 0.5 * (hi.time_s - lo.time_s));
        h = floor_gap_m(shape, c_own, mid, floor, &sp, &rate);
        (h > 0.0 ? lo : hi) = mid;
        s = mid;
      }
    }
    nc.max_gap_m = step == 0 ? h : std::max(nc.max_gap_m, h);
    if (rest_time > 0.0 && nc.max_gap_m <= rest_height_m && s.time_s - start.time_s > rest_time) {
      nc.state = s;
      nc.support = sp;
      nc.gap_m = h;
      nc.steps = step;
      nc.resting = true;
      return nc;
    }
    const double a = std::abs(floor.normal.dot(s.velocity_m_s)) + omega_max * r_max;
    if (h <= tol && rate < 0.0) {
      // Newton from s (h >= 0 up to rounding: advancement never passes the floor) on the exact rate.
      BodyState base = s, best = s;
      geometry::SurfacePoint best_sp = sp;
      double best_h = h, delta = 0.0, hk = h, rk = rate;
      for (int it = 0; it < 20 && rk < 0.0; ++it) {
        const double next = delta - hk / rk;
        if (!(next >= 0.0) || std::abs(next - delta) <= 1e-15) break;
        delta = next;
        const BodyState t = flight.advance(base, delta);
        geometry::SurfacePoint tsp;
        hk = floor_gap_m(shape, c_own, t, floor, &tsp, &rk);
        if (std::abs(hk) < std::abs(best_h)) {
          best = t;
          best_h = hk;
          best_sp = tsp;
        }
        if (std::abs(hk) <= 1e-3 * tol) break;
      }
      nc.state = best;
      nc.support = best_sp;
      nc.gap_m = best_h;
      nc.steps = step;
      return nc;
    }
    // The largest dt with (a + g_n dt) dt <= room: the gap cannot fall by more than room within it.
    // room = max(h, tol): the gap cannot close. Within the rest band (every gap so far within
    // rest_height_m of the floor, where steps of h / a would crawl: a bounce on a corner, a body
    // rocking or spinning near the floor), room grows by rest_height_m: a step may pass the floor by
    // at most that much, and the bisection above brings the search back to the crossing. A dip
    // below the floor shallower than rest_height_m may be stepped over there: a bounce the rest
    // rule does not resolve.
    const bool in_band = rest_time > 0.0 && nc.max_gap_m <= rest_height_m;
    const double room = std::max(h, tol) + (in_band ? rest_height_m : 0.0);
    const double disc = std::sqrt(a * a + 4.0 * g_n * room);
    const double dt = 2.0 * room / (a + disc);
    if (!(dt > 0.0) || !std::isfinite(dt)) {
      throw ctx.error("", "the body neither moves nor falls towards the floor: no next contact");
    }
    prev = s;
    s = flight.advance(s, dt);
  }
  throw ctx.error("", "no contact with the floor found within " + std::to_string(kMaxSearchSteps) +
                          " steps of conservative advancement");
}

}  // namespace impactdeck::sequence
