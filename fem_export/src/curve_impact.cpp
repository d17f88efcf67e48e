// An impact on a tabulated contact (contact_model.hpp, impact_on_curves): the quasi-static
// full-contact route's force-approach curves with the impact's mass on them.
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "impactdeck/common/number_text.hpp"
#include "impactdeck/fem_export/contact_model.hpp"

namespace impactdeck::fem_export {

namespace {

// F at x on a piecewise-linear curve with increasing abscissae, held constant beyond its ends.
double on_curve(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  if (x <= xs.front()) return ys.front();
  if (x >= xs.back()) return ys.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
  const double t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return ys[i - 1] + t * (ys[i] - ys[i - 1]);
}

void check_curve(const std::vector<double>& x, const std::vector<double>& f, bool increasing, const char* what) {
  if (x.size() != f.size() || x.size() < 2) throw std::invalid_argument(std::string(what) + ": fewer than 2 points");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(f[i])) throw std::invalid_argument(std::string(what) + ": not finite");
    if (i > 0 && !(increasing ? x[i] > x[i - 1] : x[i] < x[i - 1])) {
      throw std::invalid_argument(std::string(what) + ": approach not " + (increasing ? "increasing" : "decreasing"));
    }
  }
}

// Forces below this fraction of the loading peak are solver round-off. ccx balances forces to
// about 5e-3 of their mean (its default R_alpha), so no real contact force of a run is this small;
// its separated bodies' reaction totals are 1e-11 of the peak.
constexpr double kForceFloorRel = 1e-6;

// Four significant digits (std::to_string prints a micrometre approach as 0.000001).
std::string num(double x) { return format_number(x, 4); }

// One RK4 step of d'' = a(d) (the force depends on the approach only).
template <class Accel>
void rk4(double& d, double& v, double h, const Accel& a) {
  const double k1d = v, k1v = a(d);
  const double k2d = v + 0.5 * h * k1v, k2v = a(d + 0.5 * h * k1d);
  const double k3d = v + 0.5 * h * k2v, k3v = a(d + 0.5 * h * k2d);
  const double k4d = v + h * k3v, k4v = a(d + h * k3d);
  d += h / 6 * (k1d + 2 * k2d + 2 * k3d + k4d);
  v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
}

}  // namespace

double curve_work_J(const std::vector<double>& x, const std::vector<double>& f) {
  double w = 0;
  for (std::size_t i = 1; i < x.size(); ++i) w += 0.5 * (f[i] + f[i - 1]) * (x[i] - x[i - 1]);
  return w;
}

std::optional<double> approach_at_work(const std::vector<double>& ld, const std::vector<double>& lf, double work_J) {
  // The work reaches work_J inside segment i (exact for the piecewise-linear force:
  // W + f0 s + k s^2 / 2 = work_J).
  double work = 0;
  for (std::size_t i = 1; i < ld.size(); ++i) {
    const double h = ld[i] - ld[i - 1], f0 = lf[i - 1], k = (lf[i] - lf[i - 1]) / h;
    const double seg = 0.5 * (lf[i] + f0) * h;
    if (work + seg < work_J) {
      work += seg;
      continue;
    }
    const double rest = work_J - work;
    const double s = std::abs(k) * h < 1e-12 * std::abs(f0) ? rest / f0
                                                            : (-f0 + std::sqrt(std::max(0.0, f0 * f0 + 2 * k * rest))) / k;
    return ld[i - 1] + std::clamp(s, 0.0, h);
  }
  return std::nullopt;
}

CurveImpact impact_on_curves(const std::vector<double>& ld_in, const std::vector<double>& lf_in,
                             const std::vector<double>& ud, const std::vector<double>& uf, double mass_kg, double speed_m_s,
                             double extension) {
  check_curve(ld_in, lf_in, true, "loading curve");
  std::vector<double> ld = ld_in, lf = lf_in;
  if (extension > 0) {
    // The last segment continued: the work of `extension` times the energy more, at most.
    const std::size_t n = ld.size();
    const double slope = std::max(0.0, (lf[n - 1] - lf[n - 2]) / (ld[n - 1] - ld[n - 2]));
    const double e = 0.5 * mass_kg * speed_m_s * speed_m_s * extension;
    const double f = lf.back();
    const double s = slope > 0 ? (-f + std::sqrt(f * f + 2 * slope * e)) / slope : (f > 0 ? e / f : 0);
    if (s > 0 && std::isfinite(s)) {
      ld.push_back(ld.back() + s);
      lf.push_back(f + slope * s);
    }
  }
  check_curve(ud, uf, false, "unloading curve");
  if (!(mass_kg > 0) || !(speed_m_s > 0) || !std::isfinite(mass_kg) || !std::isfinite(speed_m_s)) {
    throw std::invalid_argument("mass and speed must be > 0");
  }
  CurveImpact c;
  const double energy = 0.5 * mass_kg * speed_m_s * speed_m_s;
  const std::optional<double> turn = approach_at_work(ld, lf, energy);
  if (!turn) {
    throw std::invalid_argument("the loading curve's work (" + num(curve_work_J(ld, lf)) + " J up to an approach of " +
                                num(ld.back()) + " m) falls short of the impact energy " + num(energy) + " J");
  }
  c.max_approach_m = *turn;
  c.max_force_N = on_curve(ld, lf, *turn);
  for (std::size_t i = 0; i < ld.size() && ld[i] <= *turn; ++i) c.max_force_N = std::max(c.max_force_N, lf[i]);
  // The unloading curve, increasing for the look-ups, cut where its force vanishes. A force within
  // kForceFloorRel of the loading peak is zero: ccx's reaction total on separated bodies is round-off
  // of either sign (seen: +2.3e-10 N and -4.2e-11 N beside a 28 N peak).
  std::vector<double> ux(ud.rbegin(), ud.rend()), uy(uf.rbegin(), uf.rend());
  const double peak_N = *std::max_element(lf.begin(), lf.end()), floor_N = kForceFloorRel * peak_N;
  for (double& f : uy) {
    if (std::abs(f) <= floor_N) f = 0;
  }
  std::size_t last_positive = ux.size();  // from the unloading start (the end of ux)
  for (std::size_t i = ux.size(); i-- > 0;) {
    if (uy[i] <= 0) break;
    last_positive = i;
  }
  if (last_positive == ux.size()) throw std::invalid_argument("the unloading curve starts with no force");
  if (last_positive == 0) {
    throw std::invalid_argument("the unloading force never vanishes (the bodies stay pressed): " + num(uy[0]) +
                                " N at an approach of " + num(ux[0]) + " m, the loading peak " +
                                num(peak_N) + " N");
  }
  {
    const std::size_t i = last_positive;  // uy[i - 1] <= 0 < uy[i]
    c.residual_approach_m = ux[i - 1] + (ux[i] - ux[i - 1]) * (0 - uy[i - 1]) / (uy[i] - uy[i - 1]);
    ux.erase(ux.begin(), ux.begin() + static_cast<std::ptrdiff_t>(i - 1));
    uy.erase(uy.begin(), uy.begin() + static_cast<std::ptrdiff_t>(i - 1));
    ux.front() = c.residual_approach_m;
    uy.front() = 0;
  }
  // The unloading work from the turning point down to the residual approach.
  double back = 0;
  for (std::size_t i = 1; i < ux.size(); ++i) {
    const double a = ux[i - 1], b = std::min(ux[i], c.max_approach_m);
    if (b <= a) break;
    back += 0.5 * (uy[i - 1] + on_curve(ux, uy, b)) * (b - a);
  }
  if (c.max_approach_m > ux.back()) back += uy.back() * (c.max_approach_m - ux.back());  // held beyond its start
  c.restitution = std::sqrt(std::max(0.0, back) / energy);

  // F(t): loading until the speed vanishes, then unloading until the residual approach.
  const double h = c.max_approach_m / speed_m_s / 4000;
  double t = 0, d = 0, v = speed_m_s;
  std::vector<double> ts{0.0}, fs{0.0};
  auto load_a = [&](double x) { return -on_curve(ld, lf, std::max(x, 0.0)) / mass_kg; };
  auto unload_a = [&](double x) { return -on_curve(ux, uy, x) / mass_kg; };
  const std::size_t cap = 2000000;  // steps: bounded work whatever the curves
  std::size_t steps = 0;
  while (v > 0 && steps++ < cap) {
    const double d0 = d, v0 = v;
    rk4(d, v, h, load_a);
    t += h;
    if (v <= 0) {  // the turning instant, interpolated
      const double f = v0 / (v0 - v);
      t -= (1 - f) * h;
      d = d0 + f * (d - d0);
      v = 0;
    }
    ts.push_back(t);
    fs.push_back(on_curve(ld, lf, d));
  }
  c.max_force_time_s = t;
  d = std::max(d, c.max_approach_m);  // the exact turning point (RK4 agrees to its order)
  while (d > c.residual_approach_m && steps++ < cap) {
    const double d0 = d;
    rk4(d, v, h, unload_a);
    t += h;
    if (d <= c.residual_approach_m) {  // the separation, interpolated
      const double f = (d0 - c.residual_approach_m) / (d0 - d);
      t -= (1 - f) * h;
      d = c.residual_approach_m;
    }
    ts.push_back(t);
    fs.push_back(on_curve(ux, uy, d));
  }
  if (steps >= cap) throw std::invalid_argument("the impact on the curves did not end within its step budget");
  c.contact_time_s = t;
  for (std::size_t i = 1; i < ts.size(); ++i) c.impulse_Ns += 0.5 * (fs[i] + fs[i - 1]) * (ts[i] - ts[i - 1]);
  const std::size_t stride = std::max<std::size_t>(1, ts.size() / 400);
  for (std::size_t i = 0; i < ts.size(); i += stride) {
    c.time_s.push_back(ts[i]);
    c.force_N.push_back(fs[i]);
  }
  if (c.time_s.back() != ts.back()) {
    c.time_s.push_back(ts.back());
    c.force_N.push_back(fs.back());
  }
  return c;
}

}  // namespace impactdeck::fem_export
