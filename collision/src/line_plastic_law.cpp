// The line contact of a rounded edge that yields: the contact law "line-plastic"
// (docs/sharp-contacts.md), the line-contact analogue of Thornton's law (thornton_law.cpp). An edge
// rounded to R* across it, over its straight length L, with the limiting pressure p_y
// (detail::limiting_pressure_Pa, the sphere laws' rule). The elastic relation is the "line" law's
// (sharp_law.cpp): F = k d, k = (pi/4) E* L.
//   yield      per unit length F' = F/L, plane-strain Hertz (Johnson 1985, Sect. 4.3):
//              b = sqrt(4 F' R* / (pi E*)), p0 = 2 F' / (pi b), so p0 = sqrt(F' E* / (pi R*)) and,
//              with F = k d, b^2 = R* d (the line law's own width).
//              p0 = p_y at F_y = pi R* L p_y^2 / E*, b_y = 2 R* p_y / E*, d_y = F_y / k = b_y^2 / R*;
//              V_y = F_y / sqrt(m k) (1/2 m V_y^2 = 1/2 k d_y^2 = W_y)
//   loading    beyond d_y each increment of the width carries p_y (Thornton's idea in 2-D):
//              dF/dd = p_y L d(2b)/dd with b = sqrt(R* d), so F = F_y + 2 p_y L (sqrt(R* d) - b_y)
//              = C0 + c1 s with s = sqrt(d), c1 = 2 p_y L sqrt(R*), C0 = F_y - c1 s_y (the slope
//              drops from k to E* L / 2 at d_y)
//   maximum    W(s*) = 1/2 m V^2 with W(s) = W_y + C0 (s^2 - s_y^2) + 2/3 c1 (s^3 - s_y^3) (a cubic in
//              s*); d* = s*^2, F* = C0 + c1 s*
//   unloading  along the line law's elastic relation: F = k (d - d_p), d* - d_p = F* / k; the dent
//              is d_p; released energy F*^2 / (2 k) = 1/2 m V_r^2, e = F* / (V sqrt(m k)) < 1
// F(t) phase by phase:
//   1. elastic: F = F_e sin(w t), F_e = V sqrt(m k), w = sqrt(k/m), up to t_1 = asin(F_y / F_e) / w
//   2. plastic: t_m - t = tau = int_s^s* 2 u du / sqrt(2 (W(s*) - W(u)) / m), where
//      W(s*) - W(u) = (s* - u) Q(u), Q(u) = C0 (s* + u) + a (s*^2 + s* u + u^2), a = 2/3 c1 (Q > 0 on
//      [s_y, s*]); with u = s* - x^2 the integrand is smooth:
//      tau(x) = int_0^x 4 (s* - v^2) / sqrt(2 Q(s* - v^2) / m) dv (Gauss-Legendre of order kOrder),
//      t_m = t_1 + tau(sqrt(s* - s_y)); F(t) = F* - c1 x^2 with tau(x) = t_m - t (safeguarded Newton)
//   3. elastic unloading: F = F* cos(w (t - t_m)), t_u = pi / (2 w), t_c = t_m + t_u
// V <= V_y: the "line" law's result itself (e = 1, no dent). The patch at F*: the strip of
// semi-axes L/2 and b* = sqrt(R* d*) under its mean pressure F* / (2 b* L). Poisson's R is e.
#include <algorithm>
#include <cmath>
#include <memory>

#include <gsl/gsl_integration.h>
#include <gsl/gsl_poly.h>

#include "impactdeck/collision/contact_law.hpp"
#include "plastic_law.hpp"

namespace impactdeck::collision {

std::shared_ptr<const ContactLaw> make_line_law(const LawOptions& options);  // sharp_law.cpp

namespace {

/// The Gauss-Legendre order of the plastic phase's time integral: its integrand is smooth on the
/// whole phase (the turning point's 1/sqrt removed); with 48 nodes t_m meets an rk8pd integration
/// to about 1e-11 from V/V_y = 1.001 to 1e4 (tests/test_sharp.cpp, LinePlastic.*, asserted to 1e-8).
constexpr std::size_t kOrder = 48;

const gsl_integration_glfixed_table* gauss_legendre() {
  struct Table {
    gsl_integration_glfixed_table* t = gsl_integration_glfixed_table_alloc(kOrder);
    ~Table() { gsl_integration_glfixed_table_free(t); }
  };
  static const Table table;
  return table.t;
}

/// The plastic phase of one impact: the numbers of tau(x) above.
struct PlasticPhase {
  double m, s_star, C0, a;
  double integrand(double x) const {
    const double u = s_star - x * x;
    const double Q = C0 * (s_star + u) + a * (s_star * s_star + s_star * u + u * u);
    return 4.0 * u / std::sqrt(2.0 * Q / m);
  }
  /// tau(x): the time from s = s* - x^2 to the turning point s*.
  double tau(double x) const {
    const gsl_integration_glfixed_table* t = gauss_legendre();
    if (t == nullptr || !(x > 0.0)) return 0.0;
    gsl_function f{[](double v, void* p) { return static_cast<const PlasticPhase*>(p)->integrand(v); },
                   const_cast<PlasticPhase*>(this)};
    return gsl_integration_glfixed(&f, 0.0, x, t);
  }
};

// state: [0] w, [1] t_1 (the end of the elastic loading; t_m when elastic), [2] s_y, [3] c1.
class LinePlasticLaw final : public ContactLaw {
 public:
  explicit LinePlasticLaw(double limiting_pressure_Pa)
      : limiting_pressure_Pa_(limiting_pressure_Pa), elastic_(make_line_law(LawOptions{})) {
    gauss_legendre();  // its one allocation here, not in solve() (the kernel's hot path)
  }
  const char* name() const noexcept override { return "line-plastic"; }
  bool uses_yield_strength() const noexcept override { return true; }
  bool takes_line_contacts() const noexcept override { return true; }

  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    for (std::size_t k = 0; k < count; ++k) solve_one(in[k], out[k]);
  }

  double force_N(const LawResult& r, double t) const noexcept override {
    if (!(t > 0.0) || t >= r.contact_time_s) return 0.0;
    const double w = r.state[0], t1 = r.state[1], tm = r.compression_time_s;
    if (t <= t1) return r.impulse_compression_Ns * w * std::sin(w * t);  // F_e = m V w
    if (t >= tm) return r.max_force_N * std::cos(w * (t - tm));
    const double c1 = r.state[3], s_star = std::sqrt(r.max_indentation_m), s_y = r.state[2];
    const PlasticPhase p = phase(r);
    // x in [0, x_y] with tau(x) = t_m - t: tau increases with x (tau' = the integrand > 0).
    const double target = tm - t, x_y = std::sqrt(s_star - s_y);
    double lo = 0.0, hi = x_y, x = std::min(x_y, target / p.integrand(0.0));
    for (int i = 0; i < 64; ++i) {
      const double err = p.tau(x) - target;
      (err < 0.0 ? lo : hi) = x;
      double next = x - err / p.integrand(x);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      const bool converged = std::abs(next - x) <= 1e-15 * x_y;
      x = next;
      if (converged || hi - lo <= 1e-15 * x_y) break;
    }
    return r.max_force_N - c1 * x * x;
  }

 private:
  /// The plastic phase of a solved impact (from r and its state).
  static PlasticPhase phase(const LawResult& r) noexcept {
    const double w = r.state[0], c1 = r.state[3], s_star = std::sqrt(r.max_indentation_m);
    return PlasticPhase{r.stiffness / (w * w), s_star, r.max_force_N - c1 * s_star, 2.0 / 3.0 * c1};
  }

  void solve_one(const LawInput& in, LawResult& r) const noexcept {
    elastic_->solve(&in, &r, 1);  // the "line" law: k, F_e, w, t_m and its patch
    if (r.status != LawStatus::ok) return;
    const double w = r.state[0];
    r.state[1] = r.compression_time_s;
    const double py = detail::limiting_pressure_Pa(limiting_pressure_Pa_, in.yield_strength_Pa);
    const double E = in.effective_modulus_Pa, L = in.sharp_length_m, R = in.effective_radius_m;
    r.status = LawStatus::degenerate;
    if (!detail::finite_positive(py) || !detail::finite_positive(R) || gauss_legendre() == nullptr) return;
    const double k = r.stiffness, Fe = r.max_force_N;
    const double Fy = line_yield_force_N(E, R, k, py);
    if (!(Fe > Fy)) {  // V <= V_y: the line law's result, e = 1, no dent
      r.status = LawStatus::ok;
      return;
    }
    const double m = k / (w * w), V = in.approach_velocity_m_s;
    const double dy = Fy / k, sy = std::sqrt(dy);  // = b_y / sqrt(R*), b_y = 2 R* p_y / E*
    const double c1 = 2.0 * py * L * std::sqrt(R), C0 = Fy - c1 * sy, a = 2.0 / 3.0 * c1;
    // The turning point: a s^3 + C0 s^2 = K, K = 1/2 m V^2 - W_y + C0 s_y^2 + a s_y^3 (> 0: the
    // energy beyond yield plus s_y^2 (F_y - c1 s_y / 3) > 0); one root above s_y (W increases there).
    const double K = 0.5 * m * V * V - 0.5 * Fy * dy + sy * sy * (C0 + a * sy);
    double roots[3] = {0.0, 0.0, 0.0};
    const int n = gsl_poly_solve_cubic(C0 / a, 0.0, -K / a, &roots[0], &roots[1], &roots[2]);
    double s = std::max(roots[n == 3 ? 2 : 0], sy);
    for (int i = 0; i < 4; ++i) {  // Newton's polish of the cubic formula's rounding
      const double h = s * s * (a * s + C0) - K, dh = 2.0 * s * (C0 + c1 * s);
      if (!(dh > 0.0)) break;
      s -= h / dh;
    }
    const double F_star = C0 + c1 * s;
    r.max_indentation_m = s * s;
    r.max_force_N = F_star;
    r.state = {w, std::asin(Fy / Fe) / w, sy, c1};
    r.compression_time_s = r.state[1] + phase(r).tau(std::sqrt(s - sy));
    r.unloading_time_s = 0.5 * M_PI / w;
    r.contact_time_s = r.compression_time_s + r.unloading_time_s;
    r.restitution.coefficient = F_star / Fe;
    r.residual_indentation_m = r.max_indentation_m - F_star / k;
    const double b = std::sqrt(R * r.max_indentation_m);
    r.contact_semi_axis_a_m = std::max(0.5 * L, b);
    r.contact_semi_axis_b_m = std::min(0.5 * L, b);
    r.contact_pressure_Pa = F_star / (2.0 * b * L);
    r.dent_radius_m = r.contact_semi_axis_b_m;  // the dent's half-width b* (at most L/2), as the wedge's
    detail::finish_plastic_result(r);
    if (!(r.residual_indentation_m > 0.0)) r.status = LawStatus::degenerate;
  }

  double limiting_pressure_Pa_;
  std::shared_ptr<const ContactLaw> elastic_;
};

}  // namespace

std::shared_ptr<const ContactLaw> make_line_plastic_law(const LawOptions& options) {
  return std::make_shared<const LinePlasticLaw>(options.limiting_pressure_Pa);
}

double line_yield_force_N(double E, double R, double k, double py) { return 4.0 * R * py * py * k / (E * E); }

}  // namespace impactdeck::collision
