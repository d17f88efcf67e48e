// Thornton's elastic - perfectly plastic law (C. Thornton, J. Appl. Mech. 64 (1997) 383-386): the
// contact law "thornton". With k_H = 4/3 E* sqrt(R*) and the limiting pressure p_y:
//   yield      a_y = pi R* p_y / (2 E*),  d_y = a_y^2 / R*,  F_y = k_H d_y^1.5,  W_y = 2/5 F_y d_y
//   loading    F = k_H d^1.5 (d <= d_y);  F = F_y + k_p (d - d_y), k_p = pi p_y R* (d > d_y)
//   maximum    1/2 m V^2 = W_y + F_y D + 1/2 k_p D^2,  d* = d_y + D,  F* = F_y + k_p D
//   unloading  F = 4/3 E* sqrt(R_p) (d - d_p)^1.5,  R_p = 4 E*/(3 F*) ((2 F* + F_y)/(2 pi p_y))^1.5,
//              d* - d_p = (F*/k_u)^(2/3) with k_u = 4/3 E* sqrt(R_p); the dent is d_p
//   restitution  1/2 m V_r^2 = 2/5 F* (d* - d_p) (the unloading's elastic energy), e = V_r / V
// F(t) phase by phase, in closed form:
//   1. Hertz loading at speed V up to d_y: F = F_H Phi(t / t_H) (compression.hpp's curve of the
//      Hertz impact at V: F_H, t_H), reached at t_1 = t_H I_{z^p}(1/p, 1/2), z = d_y / x_H, p = 5/2,
//      computed as (d_y / V) S(z^p) (compression.hpp's hertz_loading_time_factor)
//   2. plastic: m y'' = -k_p y with y = d - d_y + F_y/k_p, so F = F* cos(w (t_m - t)), w = sqrt(k_p/m),
//      t_m = t_1 + (pi/2 - phi)/w, phi = atan2(F_y/k_p, V_1/w), V_1^2 = V^2 - 2 W_y/m
//   3. Hertz unloading with k_u: half a Hertz cycle at speed V_r, F = F* Phi(1 - (t - t_m)/t_u),
//      t_u = C_n (d* - d_p) / V_r, t_c = t_m + t_u
// Where 1/2 m V^2 <= W_y the impact stays elastic: Hertz with e = 1, no dent. Poisson's R is e
// (the restitution impulse m V_r over m V).
#include <cmath>
#include <limits>
#include <memory>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "plastic_law.hpp"

namespace impactdeck::collision {

namespace {

// state: [0] t_1 (end of the Hertz loading), [1] t_H, [2] F_H (the Hertz impact at V), [3] w.
class ThorntonLaw final : public ContactLaw {
 public:
  explicit ThorntonLaw(double limiting_pressure_Pa) : limiting_pressure_Pa_(limiting_pressure_Pa) {}
  const char* name() const noexcept override { return "thornton"; }
  bool uses_yield_strength() const noexcept override { return true; }

  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    for (std::size_t k = 0; k < count; ++k) solve_one(in[k], out[k]);
  }

  double force_N(const LawResult& r, double t) const noexcept override {
    if (!(t > 0.0) || t >= r.contact_time_s) return 0.0;
    const double t1 = r.state[0], tH = r.state[1], FH = r.state[2], w = r.state[3];
    const double tm = r.compression_time_s;
    if (t <= t1) return FH * compression_force_fraction(t / tH);
    if (t <= tm) return r.max_force_N * std::cos(w * (tm - t));
    return r.max_force_N * compression_force_fraction(1.0 - (t - tm) / r.unloading_time_s);
  }

  void unloading_forces(const LawResult& r, const double* u, double* f, std::size_t n) const override {
    for (std::size_t i = 0; i < n; ++i) f[i] = r.max_force_N * compression_force_fraction(1.0 - u[i]);
  }

 private:
  void solve_one(const LawInput& in, LawResult& r) const noexcept {
    r = LawResult{};
    r.status = LawStatus::degenerate;
    const double m = in.reduced_mass_kg, V = in.approach_velocity_m_s, E = in.effective_modulus_Pa,
                 R = in.effective_radius_m;
    const double py = detail::limiting_pressure_Pa(limiting_pressure_Pa_, in.yield_strength_Pa);
    if (!detail::finite_positive(py)) return;  // no limiting pressure: the caller refuses such an input first
    const double kH = hertz_constant(E, R);
    r.stiffness = kH;
    const double ay = M_PI * R * py / (2.0 * E);
    const double dy = ay * ay / R;
    const double Fy = kH * dy * std::sqrt(dy);
    const double Wy = 0.4 * Fy * dy;
    const double energy = 0.5 * m * V * V;
    r.impulse_compression_Ns = m * V;
    if (!(energy > Wy)) {  // elastic: Hertz with e = 1
      const CompressionPhase hertz = compression_phase(m, V, kH);
      detail::elastic_hertz_result(hertz, R, r);
      r.state = {hertz.compression_time_s, hertz.compression_time_s, hertz.max_force_N, 0.0};
    } else {
      const double kp = M_PI * py * R;
      const double excess = energy - Wy;                                   // F_y D + k_p D^2 / 2
      const double D = 2.0 * excess / (Fy + std::sqrt(Fy * Fy + 2.0 * kp * excess));  // no cancellation
      const double d_star = dy + D, F_star = Fy + kp * D;
      // d* - d_p = (F*/k_u)^(2/3) with k_u = 4/3 E* sqrt(R_p) and R_p's closed form above: in one
      // step, 3 F* / (4 E* sqrt(q)) with q = (2 F* + F_y) / (2 pi p_y) (no cube root).
      const double q = (2.0 * F_star + Fy) / (2.0 * M_PI * py);
      const double du = 0.75 * F_star / (E * std::sqrt(q));
      const double Vr = std::sqrt(0.8 * F_star * du / m);
      // Phase 1: Hertz loading from V to d_y takes t_1 = (d_y / V) S(u), u = W_y / (m V^2 / 2) the
      // energy fraction stored at d_y (hertz_loading_time_factor). The Hertz impact at V that this
      // loading follows (for F(t)): x_H = d_y / z with z = u^(1/p), t_H = C_n x_H / V, F_H = k_H x_H^(3/2).
      const double u = Wy / energy;
      const double t1 = dy / V * hertz_loading_time_factor(u);
      const double z = std::pow(u, 0.4);
      const double tH = compression_time_factor() * dy / (z * V), FH = Fy / (z * std::sqrt(z));
      // Phase 2: harmonic about -F_y/k_p, from (y0, V_1) to its top.
      const double w = std::sqrt(kp / m);
      const double V1 = std::sqrt(V * V - 2.0 * Wy / m);
      const double phi = std::atan2(Fy / kp, V1 / w);
      r.max_indentation_m = d_star;
      r.max_force_N = F_star;
      r.compression_time_s = t1 + (0.5 * M_PI - phi) / w;
      // Phase 3: half a Hertz cycle with k_u at V_r.
      r.unloading_time_s = compression_time_factor() * du / Vr;
      r.contact_time_s = r.compression_time_s + r.unloading_time_s;
      r.restitution.coefficient = Vr / V;
      detail::hertz_unloading(R, E, du, r);  // the dent d_p = d* - du, its radius, R_p
      r.state = {t1, tH, FH, w};
    }
    detail::finish_plastic_result(r);
  }

  double limiting_pressure_Pa_;
};

}  // namespace

double yield_velocity_m_s(double m, double E, double R, double py) {
  const double c = M_PI / (2.0 * E);
  return c * c * std::sqrt(8.0 * M_PI * R * R * R / (15.0 * m)) * py * py * std::sqrt(py);
}

std::shared_ptr<const ContactLaw> make_thornton_law(const LawOptions& options) {
  return std::make_shared<const ThorntonLaw>(options.limiting_pressure_Pa);
}

}  // namespace impactdeck::collision
