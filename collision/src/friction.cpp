#include "impactdeck/collision/friction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "impactdeck/collision/kernel.hpp"

namespace impactdeck::collision {

const char* to_string(SlipEvent e) {
  switch (e) {
    case SlipEvent::slides: return "slides";
    case SlipEvent::sticks: return "sticks";
    case SlipEvent::reverses: return "reverses";
  }
  return "?";
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = std::numeric_limits<double>::epsilon();
// ODE steps (accepted and rejected) of all curved phases of one impact.
constexpr std::size_t kMaxSteps = 100000;
// Phases (closed-form or integrated) of one impact: compression and restitution, each split at
// most kMaxSlipEvents times.
constexpr int kMaxPhases = 4 * static_cast<int>(kMaxSlipEvents) + 4;
// Iterations locating an event inside one ODE step.
constexpr int kEventIterations = 200;
// The integrator's local tolerance (absolute on the scaled state and relative): a decade or two
// under kFrictionRelativeTolerance for the global error of rk8pd.
constexpr double kStepTolerance = 1e-13;
// |u_t| below this times |u| is rest in the tangent plane.
constexpr double kRestRelative = 1e-13;
// A slip direction whose rate of change is below this (relative) is constant: a closed-form phase.
constexpr double kStraightRelative = 1e-13;

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& r) {
  Eigen::Matrix3d m;
  m << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
  return m;
}

// Orthonormal t1, t2, n as columns (t1 x t2 = n).
Eigen::Matrix3d contact_frame(const Eigen::Vector3d& n) {
  const Eigen::Vector3d axis = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = (axis - n * n.dot(axis)).normalized();
  Eigen::Matrix3d q;
  q.col(0) = t1;
  q.col(1) = n.cross(t1);
  q.col(2) = n;
  return q;
}

// The state: contact velocity (u_t1, u_t2, u_n), normal work W_n, tangential impulse (P_t1, P_t2).
constexpr std::size_t kDim = 6;

struct Curved {  // the sliding ODE's parameters
  Eigen::Matrix3d W;  // contact frame
  double mu = 0;
  Eigen::Vector2d s_last = Eigen::Vector2d::UnitX();
};

int slide_rhs(double, const double y[], double f[], void* params) {
  const Curved& c = *static_cast<const Curved*>(params);
  const Eigen::Vector2d ut(y[0], y[1]);
  const double rho = ut.norm();
  const Eigen::Vector2d s = rho > 0.0 ? Eigen::Vector2d(ut / rho) : c.s_last;
  const Eigen::Vector3d q(-c.mu * s.x(), -c.mu * s.y(), 1.0);
  const Eigen::Vector3d du = c.W * q;
  f[0] = du.x(), f[1] = du.y(), f[2] = du.z();
  f[3] = y[2];
  f[4] = q.x(), f[5] = q.y();
  return GSL_SUCCESS;
}

// GSL's rk8pd with a scaled error control, freed on every path.
struct Integrator {
  gsl_odeiv2_step* step = nullptr;
  gsl_odeiv2_control* control = nullptr;
  gsl_odeiv2_evolve* evolve = nullptr;
  explicit Integrator(const double scale_abs[kDim]) {
    gsl_set_error_handler_off();  // GSL's default handler aborts; every status is checked here
    step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, kDim);
    control = gsl_odeiv2_control_scaled_new(kStepTolerance, kStepTolerance, 1.0, 0.0, scale_abs, kDim);
    evolve = gsl_odeiv2_evolve_alloc(kDim);
  }
  ~Integrator() {
    if (evolve) gsl_odeiv2_evolve_free(evolve);
    if (control) gsl_odeiv2_control_free(control);
    if (step) gsl_odeiv2_step_free(step);
  }
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;
  bool ok() const { return step && control && evolve; }
};

enum class Mode { free, stick, straight, curved };  // free: mu = 0

class Solver {
 public:
  Solver(const Eigen::Matrix3d& W, const Eigen::Vector3d& u0, double mu, double e, const InputContext& ctx)
      : W_(W), mu_(mu), e_(e), ctx_(ctx) {
    y_[0] = u0.x(), y_[1] = u0.y(), y_[2] = u0.z();
    vscale_ = u0.norm();
    // Impulses are at most of order |u| / lambda_min(W) (the impulse that stops the contact).
    const double lambda_min = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(W, Eigen::EigenvaluesOnly).eigenvalues()(0);
    pscale_ = vscale_ / lambda_min;
    // A generous bound on p_n (the frictionless p_n is at most 2 |u| / W_nn <= 2 pscale).
    p_cap_ = 1e3 * (1.0 + mu) * pscale_;
  }

  void run(std::vector<SlipEvent>& history) {
    start(history);
    for (int phase = 0; !done_; ++phase) {
      if (phase >= kMaxPhases) fail("more than " + std::to_string(kMaxPhases) + " phases");
      if (mode_ == Mode::curved) {
        run_curved(history);
      } else {
        run_straight(history);
      }
    }
  }

  double p() const { return p_; }
  const double* y() const { return y_; }
  double compression_impulse() const { return p_c_; }
  double compression_work() const { return w_c_; }
  bool cut_short() const { return cut_short_; }
  bool integrated() const { return integrated_; }
  std::size_t steps() const { return steps_; }

 private:
  Eigen::Matrix3d W_;
  double mu_, e_;
  const InputContext& ctx_;
  double y_[kDim] = {0, 0, 0, 0, 0, 0};
  double p_ = 0;
  double vscale_ = 0, pscale_ = 0, p_cap_ = 0;
  Mode mode_ = Mode::free;
  Eigen::Vector3d q_ = Eigen::Vector3d::UnitZ();  // dP/dp_n of a closed-form phase (contact frame)
  Eigen::Vector2d s_ = Eigen::Vector2d::UnitX();  // slip direction of a straight slide
  bool restitution_ = false, done_ = false, cut_short_ = false, integrated_ = false;
  double p_c_ = 0, w_c_ = 0, target_ = 0;
  std::size_t steps_ = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw ctx_.error("friction", "the frictional impact was not solved within the limits (" + what +
                                     "); please report this input");
  }

  Eigen::Vector2d ut() const { return {y_[0], y_[1]}; }
  Eigen::Matrix2d Wtt() const { return W_.topLeftCorner<2, 2>(); }
  Eigen::Vector2d Wtn() const { return W_.topRightCorner<2, 1>(); }

  // A slide in direction s: straight when s does not turn (u_t' parallel to s), else curved.
  void slide(const Eigen::Vector2d& s) {
    s_ = s;
    q_ = Eigen::Vector3d(-mu_ * s.x(), -mu_ * s.y(), 1.0);
    const Eigen::Vector2d rate = Wtn() - mu_ * Wtt() * s;
    const double turn = s.x() * rate.y() - s.y() * rate.x();
    mode_ = std::abs(turn) <= kStraightRelative * rate.norm() ? Mode::straight : Mode::curved;
  }

  // At rest in the tangent plane: stick when the sticking impulse lies in the cone, else slide in
  // the one direction s with u_t' = W_tn - mu W_tt s = lambda s, lambda > 0.
  SlipEvent from_rest() {
    y_[0] = y_[1] = 0.0;
    const Eigen::Matrix2d A = Wtt();
    const Eigen::Vector2d b = Wtn();
    const Eigen::Vector2d k = -A.ldlt().solve(b);
    if (k.norm() <= mu_) {
      mode_ = Mode::stick;
      q_ = Eigen::Vector3d(k.x(), k.y(), 1.0);
      return SlipEvent::sticks;
    }
    // |(lambda 1 + mu A)^-1 b| decreases from |k|/mu > 1 at lambda = 0 to < 1 at lambda = |b|.
    auto dir = [&](double lambda) -> Eigen::Vector2d {
      return (lambda * Eigen::Matrix2d::Identity() + mu_ * A).ldlt().solve(b);
    };
    double lo = 0.0, hi = b.norm();
    for (int it = 0; it < 400 && hi - lo > 2.0 * kEps * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (dir(mid).norm() > 1.0 ? lo : hi) = mid;
    }
    slide(dir(hi).normalized());
    mode_ = Mode::straight;  // a ray: u_t grows along s
    return SlipEvent::slides;
  }

  void start(std::vector<SlipEvent>& history) {
    if (mu_ == 0.0) {
      mode_ = Mode::free;
      q_ = Eigen::Vector3d::UnitZ();
      return;
    }
    const double rho = ut().norm();
    if (rho <= kRestRelative * vscale_) {
      history.push_back(from_rest() == SlipEvent::sticks ? SlipEvent::sticks : SlipEvent::slides);
    } else {
      slide(ut() / rho);
      history.push_back(SlipEvent::slides);
    }
  }

  void record(std::vector<SlipEvent>& history, SlipEvent e) {
    if (history.size() >= kMaxSlipEvents) fail("more than " + std::to_string(kMaxSlipEvents) + " slip events");
    history.push_back(e);
  }

  // The slide came to rest (u_t = 0): it sticks or restarts in a new direction.
  void slip_stopped(std::vector<SlipEvent>& history) {
    const SlipEvent e = from_rest();
    record(history, e == SlipEvent::sticks ? SlipEvent::sticks : SlipEvent::reverses);
  }

  // u_n reached 0: the restitution target, or the end when nothing is to be released or u_n cannot
  // grow (du_n/dp_n = a <= 0).
  void compression_ended(double a) {
    y_[2] = 0.0;
    restitution_ = true;
    p_c_ = p_;
    w_c_ = y_[3];
    target_ = (1.0 - e_ * e_) * w_c_;
    if (e_ == 0.0) {
      done_ = true;
    } else if (!(a > 0.0)) {
      done_ = cut_short_ = true;
    }
  }

  // A phase of constant dP/dp_n = q_ in closed form: u linear, W_n quadratic in p_n.
  void run_straight(std::vector<SlipEvent>& history) {
    Eigen::Vector3d du = W_ * q_;
    if (mode_ == Mode::stick) du.x() = du.y() = 0.0;  // W_tt k + W_tn = 0 up to rounding
    const double a = du.z(), un = y_[2];
    enum class Event { none, compression, restitution, returned, slip } ev = Event::none;
    double x = kInf;
    if (!restitution_) {
      if (a > 0.0) x = -un / a, ev = Event::compression;
    } else {
      const double D = std::max(0.0, target_ - y_[3]);
      const double disc = un * un + 2.0 * a * D;
      if (disc >= 0.0) {
        const double den = un + std::sqrt(disc);
        x = den > 0.0 ? 2.0 * D / den : 0.0;
        ev = Event::restitution;
      } else {  // a < 0: u_n returns to 0 first
        x = un / -a;
        ev = Event::returned;
      }
    }
    if (mode_ == Mode::straight) {
      const double rho = ut().norm();
      const double lambda = s_.dot(du.head<2>());
      if (lambda < 0.0 && rho / -lambda < x) x = rho / -lambda, ev = Event::slip;
    }
    if (ev == Event::none || !std::isfinite(x) || p_ + x > p_cap_) fail("no end of the impact in sight");
    y_[3] += un * x + 0.5 * a * x * x;
    for (int i = 0; i < 3; ++i) y_[i] += du[i] * x;
    y_[4] += q_.x() * x;
    y_[5] += q_.y() * x;
    p_ += x;
    switch (ev) {
      case Event::compression: compression_ended(a); break;
      case Event::restitution: done_ = true; break;
      case Event::returned:
        y_[2] = 0.0;
        done_ = cut_short_ = true;
        break;
      case Event::slip: slip_stopped(history); break;
      case Event::none: break;
    }
  }

  // A curved slide (3-D, the slip direction turning), integrated by GSL's rk8pd until an event:
  // compression or restitution ends (located inside the step), or the slide comes to rest.
  void run_curved(std::vector<SlipEvent>& history) {
    integrated_ = true;
    const double scale_abs[kDim] = {vscale_, vscale_, vscale_, vscale_ * pscale_, pscale_, pscale_};
    Integrator in(scale_abs);
    if (!in.ok()) fail("the integrator could not be allocated");
    Curved c{W_, mu_, ut().normalized()};
    gsl_odeiv2_system sys{slide_rhs, nullptr, kDim, &c};
    double h = 1e-3 * pscale_;
    bool positive_seen = false;  // u_n > 0 met in restitution
    double f[kDim];
    while (!done_) {
      if (++steps_ > kMaxSteps) fail(std::to_string(kMaxSteps) + " integration steps");
      slide_rhs(p_, y_, f, &c);
      const Eigen::Vector2d u_t = ut();
      const double rho = u_t.norm();
      const double rho_rate = u_t.dot(Eigen::Vector2d(f[0], f[1])) / rho;
      if (rho <= kRestRelative * vscale_ * 10.0) {
        // At rest up to the tolerance: the rest of the way to u_t = 0 on the tangent (O(rho^2)).
        const double x = rho_rate < 0.0 ? rho / -rho_rate : 0.0;
        y_[3] += y_[2] * x + 0.5 * f[2] * x * x;
        for (std::size_t i = 0; i < kDim; ++i) {
          if (i != 3) y_[i] += f[i] * x;
        }
        p_ += x;
        slip_stopped(history);
        if (!restitution_ && y_[2] >= 0.0) compression_ended((W_ * q_).z());
        return;
      }
      c.s_last = u_t / rho;
      // Never step past u_t = 0, where the slip direction jumps: half the way there at most.
      const double limit = rho_rate < 0.0 ? std::min(p_cap_, p_ + 0.5 * rho / -rho_rate) : p_cap_;
      if (!(p_ < p_cap_)) fail("no end of the impact in sight");
      const double p0 = p_;
      double y0[kDim];
      std::copy(y_, y_ + kDim, y0);
      if (gsl_odeiv2_evolve_apply(in.evolve, in.control, in.step, &sys, &p_, limit, &h, y_) != GSL_SUCCESS ||
          !std::all_of(y_, y_ + kDim, [](double v) { return std::isfinite(v); })) {
        fail("the integration failed");
      }
      if (ut().dot(u_t) <= 0.0) {  // went through rest: that step again, shorter
        std::copy(y0, y0 + kDim, y_);
        h = 0.25 * (p_ - p0);
        p_ = p0;
        gsl_odeiv2_evolve_reset(in.evolve);
        continue;
      }
      // The event function of the phase: crosses 0 from below at the event.
      auto g = [&](const double* yy) {
        if (!restitution_) return yy[2];
        const double released = yy[3] - target_;
        return positive_seen ? std::max(released, -yy[2]) : released;
      };
      if (g(y_) >= 0.0) {
        locate(in, sys, p0, y0, p_ - p0, g);
        if (!restitution_) {
          slide_rhs(p_, y_, f, &c);
          compression_ended(f[2]);
        } else {
          cut_short_ = y_[3] < target_;
          if (cut_short_) y_[2] = 0.0;
          done_ = true;
        }
        gsl_odeiv2_evolve_reset(in.evolve);
        continue;
      }
      if (restitution_ && y_[2] > 0.0) positive_seen = true;
    }
  }

  // The event inside the step [p0, p0 + span] from y0: g(y(p)) = 0, g(y0) < 0 <= g(y(p0 + span)),
  // by the Illinois method on single rk8pd steps from y0 (each as accurate as the accepted step).
  template <class G>
  void locate(Integrator& in, gsl_odeiv2_system& sys, double p0, const double* y0, double span, G g) {
    double yy[kDim], err[kDim];
    auto at = [&](double x) {
      std::copy(y0, y0 + kDim, yy);
      if (x > 0.0 && gsl_odeiv2_step_apply(in.step, p0, x, yy, err, nullptr, nullptr, &sys) != GSL_SUCCESS) {
        fail("the integration failed");
      }
      return g(yy);
    };
    double lo = 0.0, hi = span, glo = g(y0), ghi = at(span);
    int side = 0;
    for (int it = 0; it < kEventIterations && hi - lo > 4.0 * kEps * (p0 + hi); ++it) {
      double x = (it % 4 == 3) ? 0.5 * (lo + hi) : (lo * ghi - hi * glo) / (ghi - glo);
      if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
      const double gx = at(x);
      if (gx >= 0.0) {
        hi = x, ghi = gx;
        if (side == 1) glo *= 0.5;
        side = 1;
      } else {
        lo = x, glo = gx;
        if (side == -1) ghi *= 0.5;
        side = -1;
      }
    }
    at(hi);
    std::copy(yy, yy + kDim, y_);
    p_ = p0 + hi;
  }
};

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

FrictionalImpactResult solve_frictional_impact(const FrictionalImpactInput& in) {
  const InputContext& ctx = in.context;
  if (in.a.fixed() && in.b.fixed()) {
    throw ctx.error("bodies", "both bodies are fixed (infinite mass): nothing can move");
  }
  if (!(in.friction_coefficient >= 0.0) || !std::isfinite(in.friction_coefficient)) {
    std::ostringstream s;
    s << "must be finite and >= 0, got " << in.friction_coefficient;
    throw ctx.error("friction_coefficient", s.str());
  }
  if (!(in.restitution >= 0.0 && in.restitution <= 1.0)) {
    std::ostringstream s;
    s << "must lie in [0, 1], got " << in.restitution;
    throw ctx.error("restitution", s.str());
  }
  const double nn = in.normal.norm();
  if (!(nn > 0.0) || !std::isfinite(nn)) throw ctx.error("contact normal", "must be a non-zero finite vector");
  if (!finite(in.r_a_m) || !finite(in.r_b_m)) throw ctx.error("lever arm", "must be finite");
  for (const RigidBody* body : {&in.a, &in.b}) {
    if (!finite(body->velocity_m_s) || !finite(body->angular_velocity_rad_s)) {
      throw ctx.error("velocity", "must be finite");
    }
  }
  const KernelBody ka = kernel_body(in.a, ctx.at("body a"));
  const KernelBody kb = kernel_body(in.b, ctx.at("body b"));
  const Eigen::Vector3d n = in.normal / nn;
  const Eigen::Matrix3d Ra = cross_matrix(in.r_a_m), Rb = cross_matrix(in.r_b_m);
  Eigen::Matrix3d W = (ka.inverse_mass_per_kg + kb.inverse_mass_per_kg) * Eigen::Matrix3d::Identity() -
                      Ra * ka.inverse_inertia_world * Ra - Rb * kb.inverse_inertia_world * Rb;
  W = 0.5 * (W + W.transpose());
  const Eigen::Vector3d u0 = in.a.velocity_m_s + in.a.angular_velocity_rad_s.cross(in.r_a_m) - in.b.velocity_m_s -
                             in.b.angular_velocity_rad_s.cross(in.r_b_m);
  if (!W.allFinite() || !finite(u0)) throw ctx.error("bodies", "the impact cannot be computed in double precision");
  const Eigen::Matrix3d Q = contact_frame(n);
  const Eigen::Matrix3d Wc = Q.transpose() * W * Q;
  const Eigen::Vector3d u0c = Q.transpose() * u0;
  if (!(u0c.z() < 0.0)) {
    std::ostringstream s;
    s << "no impact: the bodies do not approach at the contact point (approach velocity " << -u0c.z() + 0.0
      << " m/s along the normal)";
    throw ctx.error("velocity", s.str());
  }

  FrictionalImpactResult r;
  Solver solver(0.5 * (Wc + Wc.transpose()), u0c, in.friction_coefficient, in.restitution, ctx);
  solver.run(r.slip_history);
  const double* y = solver.y();
  r.normal_impulse_Ns = solver.p();
  r.tangential_impulse_Ns = Q.col(0) * y[4] + Q.col(1) * y[5];
  r.impulse_Ns = r.tangential_impulse_Ns + r.normal_impulse_Ns * n;
  r.compression_impulse_Ns = solver.compression_impulse();
  r.compression_work_J = solver.compression_work();
  r.restitution_work_J = y[3] - solver.compression_work();
  r.restitution_cut_short = solver.cut_short();
  r.integration_steps = solver.steps();
  r.relative_error_bound = solver.integrated() ? kFrictionRelativeTolerance : 0.0;
  const Eigen::Vector3d& P = r.impulse_Ns;
  r.delta_velocity_a_m_s = ka.inverse_mass_per_kg * P;
  r.delta_angular_velocity_a_rad_s = ka.inverse_inertia_world * in.r_a_m.cross(P);
  r.delta_velocity_b_m_s = -kb.inverse_mass_per_kg * P;
  r.delta_angular_velocity_b_rad_s = kb.inverse_inertia_world * in.r_b_m.cross(-P);
  r.contact_velocity_before_m_s = u0;
  r.contact_velocity_after_m_s = u0 + W * P;
  // The kinetic energy lost: -int u.dP = -(u0 + u1)/2 . P (u is linear in P).
  const double loss = -0.5 * (u0 + r.contact_velocity_after_m_s).dot(P);
  const double scale = 0.5 * u0.norm() * P.norm();
  if (!std::isfinite(loss) || !r.impulse_Ns.allFinite() || !r.delta_velocity_a_m_s.allFinite() ||
      !r.delta_angular_velocity_a_rad_s.allFinite() || !r.delta_velocity_b_m_s.allFinite() ||
      !r.delta_angular_velocity_b_rad_s.allFinite()) {
    throw ctx.error("bodies", "the impact cannot be computed in double precision");
  }
  // Rounding of a lossless impact (e = 1, mu = 0) may give a loss of -1e-16 |u| |P|.
  if (loss < -1e-9 * scale) {
    std::ostringstream s;
    s << "energy grew by " << -loss << " J; please report this input";
    throw ctx.error("friction", s.str());
  }
  r.energy_lost_J = std::max(0.0, loss);
  return r;
}

}  // namespace impactdeck::collision
