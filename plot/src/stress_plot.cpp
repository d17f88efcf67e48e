#include "impactdeck/plot/stress_plot.hpp"

#include <algorithm>
#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::plot {
namespace {

const Colour kPalette[kStressPaletteSize] = {{0.0, 0.45, 0.70},  {0.0, 0.62, 0.45},  {0.90, 0.62, 0.0},
                                             {0.80, 0.47, 0.65}, {0.34, 0.71, 0.91}, {0.84, 0.37, 0.0}};

}  // namespace

Drawing stress_time_drawing(const std::vector<StressSeries>& series, const StressPlotOptions& opt) {
  if (series.empty()) throw InputError("", "stress plot", "no series to draw");
  double t_max = 0, s_max = 0, s_min_peak = 1e300;
  for (const auto& s : series) {
    if (s.time_s.size() < 2 || s.time_s.size() != s.von_mises_Pa.size()) {
      throw InputError("", "stress plot", "series '" + s.label + "' needs two or more (time, stress) samples");
    }
    t_max = std::max(t_max, s.time_s.back());
    double peak = 0;
    for (double v : s.von_mises_Pa) {
      if (!std::isfinite(v)) throw InputError("", "stress plot", "series '" + s.label + "' has a non-finite value");
      peak = std::max(peak, v);
    }
    s_max = std::max(s_max, peak);
    s_min_peak = std::min(s_min_peak, peak);
  }
  if (opt.yield_strength_Pa) s_max = std::max(s_max, *opt.yield_strength_Pa);
  if (!(t_max > 0) || !(s_max > 0)) throw InputError("", "stress plot", "nothing to draw (no time span or no stress)");

  const double tf = t_max < 1e-3 ? 1e6 : 1e3;
  const char* tu = t_max < 1e-3 ? "\xC2\xB5s" : "ms";
  const double sf = opt.force_N ? (s_max >= 1e4 ? 1e-3 : 1.0) : s_max >= 1e6 ? 1e-6 : 1e-3;
  const char* su = opt.force_N ? (s_max >= 1e4 ? "kN" : "N") : s_max >= 1e6 ? "MPa" : "kPa";

  // The legend goes under the chart, one line per entry (labels shortened to the width, never
  // clipped by the canvas): the chart keeps the full width.
  const std::size_t entries = series.size() + (opt.yield_strength_Pa ? 1 : 0);
  const double legend_h = 20.0 * static_cast<double>(entries) + 8;
  Drawing d(opt.width_px, opt.height_px + legend_h);
  const double left = 84, top = 56, right = opt.width_px - 30, bottom = opt.height_px - 62;
  const double t_hi = t_max * tf;
  // Stress axis: linear from 0, or logarithmic over the decades the series span.
  const bool log = opt.log_scale;
  double y_lo = 0, y_hi = s_max * 1.08 * sf;
  std::vector<double> yticks;
  if (log) {
    const double hi = std::ceil(std::log10(s_max * sf));
    const double lo = std::min(hi - 1, std::floor(std::log10(std::max(s_min_peak * sf, s_max * sf * 1e-4))));
    y_lo = lo, y_hi = hi;
    for (double e = lo; e <= hi + 1e-9; e += 1) yticks.push_back(e);
  } else {
    yticks = nice_ticks(0.0, y_hi, 5);
    if (!yticks.empty()) y_hi = std::max(y_hi, yticks.back());
  }
  auto X = [&](double t_s) { return left + (right - left) * (t_s * tf) / t_hi; };
  auto Y = [&](double v_Pa) {
    double y = v_Pa * sf;
    if (log) y = std::log10(std::max(y, std::pow(10.0, y_lo)));
    return bottom - (bottom - top) * (y - y_lo) / (y_hi - y_lo);
  };

  std::vector<Tick> xt, yt;
  for (double v : nice_ticks(0.0, t_hi, 6)) xt.push_back({left + (right - left) * v / t_hi, format_number(v)});
  for (double v : yticks) {
    yt.push_back({bottom - (bottom - top) * (v - y_lo) / (y_hi - y_lo),
                  log ? format_number(std::pow(10.0, v)) : format_number(v)});
  }
  chart_frame(d, left, top, right, bottom, xt, yt, std::string("time t [") + tu + "]",
              opt.quantity + " [" + su + "]" + (log ? " (log scale)" : ""));
  d.text({left, 30}, opt.title.empty() ? "Von Mises stress against time" : opt.title, 15, Anchor::start, kBlack, true);

  Style mark;
  mark.stroke = {0.3, 0.3, 0.3};
  mark.stroke_width = 1.0;
  mark.dash = 3;
  if (opt.contact_end_s && *opt.contact_end_s > 0 && *opt.contact_end_s < t_max) {
    d.line({X(*opt.contact_end_s), top}, {X(*opt.contact_end_s), bottom}, mark);
    d.text({X(*opt.contact_end_s) + 4, top + 12}, "end of contact", 11);
  }
  const double lx = left;
  double ly = opt.height_px + 6;
  const auto max_chars = static_cast<std::size_t>(std::max(10.0, (opt.width_px - lx - 40) / 7.0));
  auto fit = [&](const std::string& label) {
    if (label.size() <= max_chars) return label;
    std::size_t cut = max_chars - 3;
    while (cut > 0 && (static_cast<unsigned char>(label[cut]) & 0xC0) == 0x80) --cut;  // not inside a UTF-8 character
    return label.substr(0, cut) + "...";
  };
  if (opt.yield_strength_Pa) {
    Style ys;
    ys.stroke = {0.75, 0.1, 0.1};
    ys.stroke_width = 1.4;
    ys.dash = 8;
    d.line({left, Y(*opt.yield_strength_Pa)}, {right, Y(*opt.yield_strength_Pa)}, ys);
    d.line({lx, ly - 4}, {lx + 26, ly - 4}, ys);
    d.text({lx + 34, ly}, "yield " + format_number(*opt.yield_strength_Pa * sf) + " " + su, 12);
    ly += 20;
  }
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto& s = series[i];
    Style st;
    st.stroke = kPalette[(s.colour >= 0 ? s.colour : static_cast<int>(i)) % kStressPaletteSize];
    st.stroke_width = 1.8;
    if (s.dashed) st.dash = 6;
    std::vector<Point2> pts;
    pts.reserve(s.time_s.size());
    for (std::size_t k = 0; k < s.time_s.size(); ++k) pts.push_back({X(s.time_s[k]), Y(s.von_mises_Pa[k])});
    d.polyline(std::move(pts), st);
    d.line({lx, ly - 4}, {lx + 26, ly - 4}, st);
    d.text({lx + 34, ly}, fit(s.label), 12);
    ly += 20;
  }
  return d;
}

}  // namespace impactdeck::plot
