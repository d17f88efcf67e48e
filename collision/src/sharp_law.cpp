// The laws of a sharp edge and a sharp corner pressed into the other body (docs/sharp-contacts.md):
// "wedge" and "cone"; and "line", the line contact of a rounded edge (below). The sharp part indents the other body at the indentation hardness p (fully
// plastic at once: the pressure under a sharp indenter does not depend on its depth), so the force
// is p times the projected contact area A(x) at the depth x:
//   wedge  (edge of interior dihedral angle 2 beta and length L):  A = 2 L x tan(beta),
//          F = k x, k = 2 p L tan(beta)               (linear: harmonic loading)
//          x* = V sqrt(m/k), F* = V sqrt(m k), t_m = (pi/2) sqrt(m/k)
//   cone   (corner of apex half-angle alpha):  A = pi x^2 tan(alpha)^2,
//          F = c x^2, c = pi p tan(alpha)^2
//          1/2 m V^2 = c x*^3 / 3, F* = c x*^2, t_m = (x*/V) B(1/3, 1/2) / 3 (from
//          t(x) = int_0^x du / sqrt(V^2 - 2 c u^3 / (3 m)); B the Beta function)
// Unloading is elastic and linear, with the stiffness of a rigid flat elliptical punch whose
// semi-axes a >= b are the indent's at F* (Galin; Johnson 1985, Sect. 3.6):
//   S = pi E* a / K(e), e^2 = 1 - b^2/a^2, K the complete elliptic integral of the first kind
//   (a circle: Sneddon's 2 E* a; the wedge's long strip, a = L/2, b = x* tan(beta): about
//   pi E* a / ln(4 a / b))
//   recovery d_e = F*/S, dent d_p = x* - d_e, released energy F*^2/(2 S) = 1/2 m V_r^2,
//   e = V_r / V = F* / (V sqrt(m S)); F = F* cos(w_u (t - t_m)), w_u = sqrt(S/m), t_u = pi/(2 w_u)
// The other body is taken flat at the point (its curvature is not read) and the edge's or cone's
// axis along the contact normal. Poisson's R is e.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_sf_ellint.h>
#include <gsl/gsl_sf_gamma.h>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/common/number_text.hpp"
#include "plastic_law.hpp"

namespace impactdeck::collision {

namespace {

// The loading of F = k x from x = 0 at speed V (harmonic): x* = V/w, F* = k x*, t_m = pi/(2 w),
// w = sqrt(k/m) into r.state[0].
void harmonic_loading(double k, double m, double V, LawResult& r) {
  const double w = std::sqrt(k / m);
  r.stiffness = k;
  r.max_indentation_m = V / w;
  r.max_force_N = k * r.max_indentation_m;
  r.compression_time_s = 0.5 * M_PI / w;
  r.state[0] = w;
}

// What both laws share: the hardness, the elastic unloading and F(t) after t_m.
// state: [0] w (wedge: the loading's angular frequency; cone: unused), [1] w_u.
class SharpLaw : public ContactLaw {
 public:
  SharpLaw(double hardness_Pa, SharpKind kind) : hardness_Pa_(hardness_Pa), kind_(kind) {}
  bool takes_sharp_points() const noexcept override { return true; }

  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    for (std::size_t k = 0; k < count; ++k) solve_one(in[k], out[k]);
  }

  double force_N(const LawResult& r, double t) const noexcept override {
    if (!(t > 0.0) || t >= r.contact_time_s) return 0.0;
    if (t <= r.compression_time_s) return loading_force(r, t);
    return r.max_force_N * std::cos(r.state[1] * (t - r.compression_time_s));
  }

 protected:
  /// F(t) for 0 < t <= t_m.
  virtual double loading_force(const LawResult& r, double t) const noexcept = 0;
  /// x*, F*, t_m, the stiffness and the patch's semi-axes (a >= b) from m, V and the feature;
  /// false when the feature is not the law's or out of range.
  virtual bool load(const LawInput& in, double p, LawResult& r) const noexcept = 0;

 private:
  void solve_one(const LawInput& in, LawResult& r) const noexcept {
    r = LawResult{};
    r.status = LawStatus::degenerate;
    const double m = in.reduced_mass_kg, V = in.approach_velocity_m_s, E = in.effective_modulus_Pa;
    const double p = hardness_Pa_ > 0.0 ? hardness_Pa_ : kTaborHardnessFactor * in.yield_strength_Pa;
    if (!detail::finite_positive(p) || in.sharp_kind != kind_) return;  // the scene refuses such an input first
    r.impulse_compression_Ns = m * V;
    if (!load(in, p, r)) return;
    // K(e) = R_F(0, b^2/a^2, 1) (Carlson's form: accurate for a long strip, where e -> 1).
    const double a = r.contact_semi_axis_a_m, ratio = r.contact_semi_axis_b_m / a;
    gsl_sf_result K;
    if (gsl_sf_ellint_RF_e(0.0, ratio * ratio, 1.0, GSL_PREC_DOUBLE, &K) != GSL_SUCCESS) return;
    const double S = M_PI * E * a / K.val;
    const double recovery = r.max_force_N / S;
    const double wu = std::sqrt(S / m);
    r.restitution.coefficient = r.max_force_N / (V * std::sqrt(m * S));
    r.residual_indentation_m = r.max_indentation_m - recovery;
    r.unloading_time_s = 0.5 * M_PI / wu;
    r.contact_time_s = r.compression_time_s + r.unloading_time_s;
    r.state[1] = wu;
    r.contact_pressure_Pa = p;
    detail::finish_plastic_result(r);
    if (std::isfinite(r.restitution.coefficient) && r.restitution.coefficient >= 1.0) {
      // The punch's elastic recovery reaches the indent (E* too low against p): the hardness does
      // not fit this feature; describe_restitution names the key that sets it.
      r.status = LawStatus::restitution_invalid;
      r.restitution.invalid = true;
    } else if (!(r.residual_indentation_m > 0.0)) {
      r.status = LawStatus::degenerate;
    }
  }

 public:
  std::string describe_restitution(const LawResult& r, double) const override {
    if (!r.restitution.invalid) return "";
    const std::string feature = kind_ == SharpKind::edge ? "edge" : "corner";
    return std::string(name()) + " law at a sharp " + feature + ": the indentation hardness p = " +
           format_number(r.contact_pressure_Pa, 6) + " Pa is too high against the effective modulus here: the " +
           "flat punch's elastic recovery reaches the whole indent (e = " + format_number(r.restitution.coefficient, 6) +
           " >= 1, no dent); lower limiting_pressure_Pa (the hardness; default " +
           "3 x the weaker body's yield strength), or give the body edge_radius";
  }

 private:

  double hardness_Pa_;
  SharpKind kind_;
};

class WedgeLaw final : public SharpLaw {
 public:
  explicit WedgeLaw(double hardness_Pa) : SharpLaw(hardness_Pa, SharpKind::edge) {}
  const char* name() const noexcept override { return "wedge"; }
  bool uses_yield_strength() const noexcept override { return true; }

 protected:
  double loading_force(const LawResult& r, double t) const noexcept override {
    return r.max_force_N * std::sin(r.state[0] * t);
  }
  bool load(const LawInput& in, double p, LawResult& r) const noexcept override {
    const double beta = 0.5 * in.sharp_angle_rad, L = in.sharp_length_m, m = in.reduced_mass_kg;
    if (!(beta > 0.0 && beta < 0.5 * M_PI) || !detail::finite_positive(L)) return false;
    harmonic_loading(2.0 * p * L * std::tan(beta), m, in.approach_velocity_m_s, r);
    const double half_width = r.max_indentation_m * std::tan(beta);
    r.contact_semi_axis_a_m = std::max(0.5 * L, half_width);
    r.contact_semi_axis_b_m = std::min(0.5 * L, half_width);
    r.dent_radius_m = r.contact_semi_axis_b_m;  // the indent's half-width x* tan(beta) (at most L/2)
    return true;
  }
};

/// B(1/3, 1/2) / 3: t_m = this x*/V for F = c x^2.
double cone_time_factor() {
  static const double f = gsl_sf_beta(1.0 / 3.0, 0.5) / 3.0;
  return f;
}

class ConeLaw final : public SharpLaw {
 public:
  explicit ConeLaw(double hardness_Pa) : SharpLaw(hardness_Pa, SharpKind::corner) {}
  const char* name() const noexcept override { return "cone"; }
  bool uses_yield_strength() const noexcept override { return true; }

 protected:
  // x(t)/x* = u solves t/t_m = I_{u^3}(1/3, 1/2) (the regularised incomplete Beta function, the
  // normalised t(x) above): bisection to the last bit (at most 64 halvings: bounded).
  double loading_force(const LawResult& r, double t) const noexcept override {
    const double target = std::min(1.0, t / r.compression_time_s);
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 64 && hi - lo > 1e-16; ++i) {
      const double mid = 0.5 * (lo + hi);
      gsl_sf_result b;
      if (gsl_sf_beta_inc_e(1.0 / 3.0, 0.5, mid * mid * mid, &b) != GSL_SUCCESS) return 0.0;
      (b.val < target ? lo : hi) = mid;
    }
    const double u = 0.5 * (lo + hi);
    return r.max_force_N * u * u;
  }
  bool load(const LawInput& in, double p, LawResult& r) const noexcept override {
    const double alpha = in.sharp_angle_rad, m = in.reduced_mass_kg, V = in.approach_velocity_m_s;
    if (!(alpha > 0.0 && alpha < 0.5 * M_PI)) return false;
    const double ta = std::tan(alpha);
    const double c = M_PI * p * ta * ta;
    r.stiffness = c;
    r.max_indentation_m = std::cbrt(1.5 * m * V * V / c);
    r.max_force_N = c * r.max_indentation_m * r.max_indentation_m;
    r.compression_time_s = cone_time_factor() * r.max_indentation_m / V;
    const double a = r.max_indentation_m * ta;
    r.contact_semi_axis_a_m = r.contact_semi_axis_b_m = r.dent_radius_m = a;  // the indent's radius x* tan(alpha)
    return true;
  }
};

// The line contact of an edge rounded to the radius R* over its straight length L (an edge break
// on a flat; or where the elliptical contact's length 2a along the edge reaches L):
// F = (pi/4) E* L d (Johnson 1985, Sect. 5.6, without the logarithmic term: the approach of two
// cylinders' axes is not defined in plane strain), elastic: a harmonic half-cycle each way,
// x* = V sqrt(m/k), F* = V sqrt(m k), t_m = t_u = (pi/2) sqrt(m/k), e = 1, no dent. The patch at F*:
// the strip of half-width b = sqrt(4 F* R* / (pi L E*)) under p0 = 2 F* / (pi b L).
class LineLaw final : public ContactLaw {
 public:
  const char* name() const noexcept override { return "line"; }
  bool takes_line_contacts() const noexcept override { return true; }
  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    for (std::size_t k = 0; k < count; ++k) solve_one(in[k], out[k]);
  }
  double force_N(const LawResult& r, double t) const noexcept override {
    if (!(t > 0.0) || t >= r.contact_time_s) return 0.0;
    return r.max_force_N * std::sin(r.state[0] * t);
  }

 private:
  static void solve_one(const LawInput& in, LawResult& r) noexcept {
    r = LawResult{};
    r.status = LawStatus::degenerate;
    const double m = in.reduced_mass_kg, V = in.approach_velocity_m_s, E = in.effective_modulus_Pa,
                 L = in.sharp_length_m, R = in.effective_radius_m;
    if (in.sharp_kind != SharpKind::edge || !detail::finite_positive(L)) return;
    harmonic_loading(0.25 * M_PI * E * L, m, V, r);
    r.impulse_compression_Ns = m * V;
    r.unloading_time_s = r.compression_time_s;
    r.contact_time_s = 2.0 * r.compression_time_s;
    r.restitution.coefficient = 1.0;
    const double b = std::sqrt(4.0 * r.max_force_N * R / (M_PI * L * E));
    r.contact_semi_axis_a_m = std::max(0.5 * L, b);
    r.contact_semi_axis_b_m = std::min(0.5 * L, b);
    r.contact_pressure_Pa = 2.0 * r.max_force_N / (M_PI * b * L);
    detail::finish_plastic_result(r);
  }
};

}  // namespace

std::shared_ptr<const ContactLaw> make_line_law(const LawOptions&) { return std::make_shared<const LineLaw>(); }

std::shared_ptr<const ContactLaw> make_wedge_law(const LawOptions& options) {
  return std::make_shared<const WedgeLaw>(options.hardness_Pa);
}

std::shared_ptr<const ContactLaw> make_cone_law(const LawOptions& options) {
  return std::make_shared<const ConeLaw>(options.hardness_Pa);
}

}  // namespace impactdeck::collision
