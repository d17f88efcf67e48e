#include "impactdeck/plot/force_plot.hpp"

#include <algorithm>
#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::plot {
namespace {

struct Scaled {
  double factor;     // value in SI times factor = value in the shown unit
  const char* unit;
};

Scaled time_unit(double span_s) {
  if (span_s < 1e-3) return {1e6, "\xC2\xB5s"};  // µs
  if (span_s < 1.0) return {1e3, "ms"};
  return {1.0, "s"};
}

Scaled force_unit(double f_N) {
  if (f_N >= 1e6) return {1e-6, "MN"};
  if (f_N >= 1e3) return {1e-3, "kN"};
  return {1.0, "N"};
}

std::string with_unit(double v, const char* unit, int digits = 4) {
  return format_number(v, digits) + " " + unit;
}

}  // namespace

Drawing force_time_drawing(const collision::ForceHistory& h, const ForcePlotOptions& opt) {
  const auto& c = h.compression;
  if (!(c.compression_time_s > 0.0) || !(c.max_force_N > 0.0) || !std::isfinite(c.max_force_N)) {
    throw InputError("", "force plot", "the force history has no contact to draw");
  }
  const double tm = c.compression_time_s, tc = h.contact_time_s();
  const Scaled tu = time_unit(tc), fu = force_unit(c.max_force_N);

  Drawing d(opt.width_px, opt.height_px);
  const double left = 84, top = 56, right = opt.width_px - 230, bottom = opt.height_px - 62;
  const double t_hi = tc * 1.06 * tu.factor;
  std::vector<double> fticks = nice_ticks(0.0, c.max_force_N * 1.12 * fu.factor, 5);
  if (fticks.size() >= 2 && fticks.back() < c.max_force_N * 1.12 * fu.factor) {
    fticks.push_back(fticks.back() + (fticks[1] - fticks[0]));  // the axis ends on a tick above F_max
  }
  const double f_hi = std::max(fticks.back(), c.max_force_N * 1.12 * fu.factor);
  auto X = [&](double t_s) { return left + (right - left) * (t_s * tu.factor) / t_hi; };
  auto Y = [&](double f_N) { return bottom - (bottom - top) * (f_N * fu.factor) / f_hi; };

  // Grid and ticks.
  std::vector<Tick> xt, yt;
  for (double v : nice_ticks(0.0, t_hi, 6)) xt.push_back({left + (right - left) * v / t_hi, format_number(v)});
  for (double v : fticks) yt.push_back({bottom - (bottom - top) * v / f_hi, format_number(v)});
  chart_frame(d, left, top, right, bottom, xt, yt, std::string("time t [") + tu.unit + "]",
              std::string("contact force F [") + fu.unit + "]");
  d.text({left, 30}, opt.title.empty() ? "Hertz contact force" : opt.title, 15, Anchor::start, kBlack, true);

  // The curve: compression then restitution, uniform in time within each phase.
  const int n = std::max(8, opt.samples_per_phase);
  std::vector<Point2> comp, rest;
  comp.reserve(n + 1);
  for (int i = 0; i <= n; ++i) {
    const double t = tm * i / n;
    comp.push_back({X(t), Y(i == 0 ? 0.0 : h.force_N(t))});
  }
  const Colour blue{0.12, 0.35, 0.70}, red{0.80, 0.25, 0.15};
  Style sc;
  sc.stroke = blue;
  sc.stroke_width = 2.2;
  Style sr = sc;
  sr.stroke = red;
  if (h.restitution > 0.0) {
    rest.reserve(n + 1);
    for (int i = 0; i <= n; ++i) {
      const double t = tm + (tc - tm) * i / n;
      rest.push_back({X(t), Y(i == n ? 0.0 : h.force_N(t))});
    }
  } else {
    rest = {{X(tm), Y(c.max_force_N)}, {X(tm), Y(0.0)}};  // perfectly plastic: force drops at t_m
  }
  d.polyline(comp, sc);
  d.polyline(rest, sr);

  // Marks at t_m and at the end of contact.
  Style mark;
  mark.stroke = {0.3, 0.3, 0.3};
  mark.stroke_width = 1.0;
  mark.dash = 4;
  d.line({X(tm), top}, {X(tm), bottom}, mark);
  d.line({X(tc), top}, {X(tc), bottom}, mark);
  // Labels left of their lines (the legend is on the right).
  d.text({X(tm) - 4, top + 12}, "t_m = " + with_unit(tm * tu.factor, tu.unit), 11, Anchor::end);
  d.text({X(tc) - 4, top + 28}, "end = " + with_unit(tc * tu.factor, tu.unit), 11, Anchor::end);
  Style peak;
  peak.stroke = kBlack;
  peak.stroke_width = 1.0;
  peak.fill = kWhite;
  peak.fill_opacity = 1.0;
  d.circle({X(tm), Y(c.max_force_N)}, 3.5, peak);

  // Legend on the right.
  const double lx = right + 22;
  double ly = top + 8;
  auto legend_line = [&](const Style& s, const std::string& label) {
    d.line({lx, ly - 4}, {lx + 26, ly - 4}, s);
    d.text({lx + 34, ly}, label, 12);
    ly += 20;
  };
  auto legend_text = [&](const std::string& label) {
    d.text({lx, ly}, label, 12);
    ly += 18;
  };
  legend_line(sc, "compression");
  legend_line(sr, "restitution");
  ly += 6;
  legend_text("F_max = " + with_unit(c.max_force_N * fu.factor, fu.unit));
  legend_text("x_max = " + format_number(c.max_indentation_m * 1e3) + " mm");
  legend_text("R = " + format_number(h.restitution));
  ly += 6;
  legend_text("\xCE\xA0\xE2\x82\x81 = " + format_number(h.impulse_compression_Ns()) + " N s");       // Π₁
  legend_text("\xCE\xA0\xE2\x82\x82 = R \xCE\xA0\xE2\x82\x81 = " + format_number(h.impulse_restitution_Ns()) + " N s");
  // Compact: a small impulse's digits (0.0007762) must still fit the canvas.
  legend_text("\xCE\xA0 = (1+R)\xCE\xA0\xE2\x82\x81 = " + format_number(h.impulse_total_Ns()) + " N s");
  return d;
}

}  // namespace impactdeck::plot
