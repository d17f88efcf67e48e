#include "impactdeck/plot/sequence_plot.hpp"

#include <algorithm>
#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::plot {

Drawing sequence_drawing(const SequencePlotData& d) {
  if (d.time_s.empty() || d.time_s.size() != d.height_m.size()) {
    throw InputError("", "sequence plot", "the trajectory is empty");
  }
  const double W = 760, H = 460, left = 80, right = W - 80, top = 50, bottom = H - 60;
  Drawing g(W, H);
  const double t1 = std::max(d.time_s.back(), 1e-12);
  double hmax = 0;
  for (double h : d.height_m) hmax = std::max(hmax, h / d.metres_per_unit);
  if (!(hmax > 0)) hmax = 1;
  double fmax = 0;
  for (double f : d.impact_max_force_N)
    if (std::isfinite(f)) fmax = std::max(fmax, f);
  const double fscale = fmax >= 1e6 ? 1e6 : fmax >= 1e3 ? 1e3 : 1.0;
  const char* funit = fmax >= 1e6 ? "MN" : fmax >= 1e3 ? "kN" : "N";
  const double ftop = fmax > 0 ? fmax / fscale : 1.0;
  auto X = [&](double t) { return left + (right - left) * t / t1; };
  auto Y = [&](double h) { return bottom - (bottom - top) * std::max(0.0, h) / hmax; };
  auto YF = [&](double f) { return bottom - (bottom - top) * f / ftop; };
  std::vector<Tick> xt, yt;
  for (double v : nice_ticks(0, t1)) if (v <= t1) xt.push_back({X(v), format_number(v)});
  for (double v : nice_ticks(0, hmax)) if (v <= hmax) yt.push_back({Y(v), format_number(v)});
  chart_frame(g, left, top, right, bottom, xt, yt, "time (s)", "height of the lowest point (" + d.length_unit + ")");
  // The right axis: F_max.
  const Style axis{kBlack, 1.0};
  g.line({right, top}, {right, bottom}, axis);
  for (double v : nice_ticks(0, ftop)) {
    if (v > ftop) continue;
    g.line({right, YF(v)}, {right + 5, YF(v)}, axis);
    g.text({right + 8, YF(v) + 4}, format_number(v), 11);
  }
  g.text({W - 20, (top + bottom) / 2}, std::string("F_max (") + funit + ")", 12, Anchor::middle, kBlack, false, -90);
  std::vector<Point2> pts;
  for (std::size_t k = 0; k < d.time_s.size(); ++k) pts.push_back({X(d.time_s[k]), Y(d.height_m[k] / d.metres_per_unit)});
  Style line{Colour{0.12, 0.35, 0.70}, 1.6};
  g.polyline(std::move(pts), line);
  const Colour red{0.80, 0.15, 0.10};
  for (std::size_t i = 0; i < d.impact_time_s.size(); ++i) {
    const double x = X(d.impact_time_s[i]);
    const double f = i < d.impact_max_force_N.size() ? d.impact_max_force_N[i] : NAN;
    if (std::isfinite(f)) {
      g.line({x, bottom}, {x, YF(f / fscale)}, Style{red, 1.4});
      Style dot{red, 1.0};
      dot.fill = red;
      dot.fill_opacity = 1.0;
      g.circle({x, YF(f / fscale)}, 3.0, dot);
    } else {
      g.circle({x, bottom}, 4.0, Style{red, 1.4});  // no Hertz force (a sharp corner): hollow
    }
  }
  g.text({W / 2, 28}, d.title, 14, Anchor::middle, kBlack, true);
  g.text({left, H - 14}, "blue: height; red stems: F_max of each impact (hollow: no Hertz force, e.g. a sharp corner)",
         11);
  return g;
}

}  // namespace impactdeck::plot
