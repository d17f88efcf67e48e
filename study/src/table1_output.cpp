#include "impactdeck/study/table1_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"
#include "number_text.hpp"

namespace impactdeck::study {
namespace {

std::string g17(double v) { return detail::g17(v, "table1 output"); }

std::string fixed(double v, int decimals, bool sign = false) {
  char buf[40];
  std::snprintf(buf, sizeof buf, sign ? "%+.*f" : "%.*f", decimals, v + 0.0);
  std::string s(buf);
  if (std::strtod(buf, nullptr) == 0.0) {  // rounds to zero: no sign, no "-0"
    if (s[0] == '-' || s[0] == '+') s.erase(0, 1);
    if (sign) s = "0";
  }
  return s;
}

std::string decade(double v) {
  const double l = std::log10(v);
  if (std::abs(l - std::round(l)) < 1e-9) {
    const int e = static_cast<int>(std::lround(l));
    if (e == 0) return "1";
    return "1e" + std::to_string(e);
  }
  return plot::format_number(v, 4);
}

bool excluded(const Table1Result& r, std::size_t gi, std::size_t mi) {
  return r.options.geometric_ratios[gi] == kExcludedGeometricRatio &&
         r.options.mass_ratios[mi] == kExcludedMassRatio;
}

const char* kAxis[] = {"x", "y", "z"};

std::size_t total_flagged(const Table1Result& r) {
  std::size_t n = 0;
  for (std::size_t k : r.flagged_points) n += k;
  return n;
}

std::string settings_line(const Table1Result& r) {
  const Table1Options& op = r.options;
  std::ostringstream s;
  s << "cloud " << to_string(op.cloud);
  if (op.cloud == CloudKind::paper_grid || op.cloud == CloudKind::both) s << " (step 1/" << op.grid_steps << ")";
  if (op.cloud == CloudKind::area_uniform || op.cloud == CloudKind::both)
    s << " (" << op.uniform_count << " uniform points, seed " << op.seed << ")";
  s << ", " << r.points_per_cell << " points per cell; ";
  if (op.scene) {
    const Table1Scene& sc = *op.scene;
    const int ax = sc.stretch_axis, ref = (ax + 1) % 3;
    s << "scene " << sc.source << ", impact '" << sc.impact << "': " << sc.impactor << " hits " << sc.target
      << "; g = half-extent along " << kAxis[ax] << " / along " << kAxis[ref] << " (target stretched along "
      << kAxis[ax] << "), mu = target mass / impactor mass; contact rule " << to_string(sc.setup.rule);
    if (const std::size_t k = total_flagged(r)) s << "; " << k << " flagged points left out (all rows)";
    return s.str();
  }
  s << "size ratio (smaller semi-axis / sphere radius) " << plot::format_number(op.size_ratio, 6)
    << "; contact rule " << to_string(op.rule) << " (a sphere's radius is exact under every rule)";
  return s.str();
}

}  // namespace

void write_table1_csv(const std::filesystem::path& path, const Table1Result& r) {
  std::vector<std::string> columns = {"geometric_ratio", "mass_ratio", "collision_force_ratio", "mass_only_ratio"};
  if (r.compared) columns.insert(columns.end(), {"paper_ratio", "delta"});
  write_file_atomically(path, [&](std::ostream& o) {
    o << columns.front();
    for (std::size_t c = 1; c < columns.size(); ++c) o << ',' << columns[c];
    o << "\n";
    for (std::size_t gi = 0; gi < r.ratio.size(); ++gi) {
      for (std::size_t mi = 0; mi < r.ratio[gi].size(); ++mi) {
        o << g17(r.options.geometric_ratios[gi]) << ',' << g17(r.options.mass_ratios[mi]) << ','
          << g17(r.ratio[gi][mi]) << ',' << g17(r.mass_only[gi][mi]);
        if (r.compared) o << ',' << g17(r.paper[gi][mi]) << ',' << g17(r.delta[gi][mi]);
        o << '\n';
      }
    }
  });
  write_csv_sidecar(path, columns,
                    {{"title", "impactdeck study table1: collision force ratio min/max F_max over a cloud"},
                     {"settings", settings_line(r)}});
}

std::string table1_markdown(const Table1Result& r) {
  std::ostringstream o;
  const auto& G = r.options.geometric_ratios;
  const auto& M = r.options.mass_ratios;
  auto table = [&](const std::vector<std::vector<double>>& v, int decimals, bool sign) {
    o << "| g = a/b \\ mu = m1/m2 |";
    for (double mu : M) o << " " << decade(mu) << " |";
    o << "\n|---|";
    for (std::size_t i = 0; i < M.size(); ++i) o << "---:|";
    o << "\n";
    for (std::size_t gi = 0; gi < G.size(); ++gi) {
      o << "| **" << decade(G[gi]) << "** |";
      for (std::size_t mi = 0; mi < M.size(); ++mi) {
        o << " " << fixed(v[gi][mi], decimals, sign) << (r.compared && excluded(r, gi, mi) ? "*" : "") << " |";
      }
      o << "\n";
    }
    o << "\n";
  };
  o << "## Collision force ratio (model)\n\n" << settings_line(r) << ".\n\n";
  table(r.ratio, 4, false);
  if (r.options.scene) {
    o << "**No comparison with the paper's Table 1:** this table is driven by a scene (the user's target, "
      << "impactor and materials), not by the paper's setting; run without --scene for the comparison.\n\n";
    if (total_flagged(r) > 0) {
      o << "Flagged points per row (sharp edges/corners, no-fit, saddles, ...; left out of min/max):";
      for (std::size_t gi = 0; gi < r.flagged_points.size(); ++gi)
        o << (gi ? "," : "") << " g = " << decade(G[gi]) << ": " << r.flagged_points[gi] << " (" << r.sharp_points[gi]
          << " sharp)";
      o << ".\n\n";
    }
  }
  if (r.compared) {
    o << "## The paper's Table 1 (as printed)\n\n";
    table(r.paper, 3, false);
    o << "## Difference model - paper\n\n";
    table(r.delta, 4, true);
    o << "**Agreement** over the " << r.cells_compared << " cells with g != 1 (cell g = 10, mu = 0.1 left out, "
      << "marked *): mean |delta| = " << fixed(r.mean_abs_delta, 5) << ", max |delta| = "
      << fixed(r.max_abs_delta, 5) << ". Left-out cell: model " << fixed(r.excluded_cell_model, 4)
      << ", paper " << fixed(r.excluded_cell_paper, 3) << ".\n\n";
  }
  o << "## Analytic limit (Eq. 39-40)\n\n"
    << "Eq. 40: [(1 + mu)/(6 + mu)]^(3/5), Eq. 39 as mu -> 0 (= " << fixed(std::pow(1.0 / 6.0, 0.6), 4)
    << "). Case 2 through the core: slender spheroid (g = 1e4) hit at its end point perpendicular to its"
    << " axis vs centrally, same k_H. Cloud: the study's row g = " << decade(r.limit_row_geometric_ratio)
    << ", reduced mass alone and with the curvature.\n\n"
    << "| mu | Eq. 40 | Case 2 (core) | cloud, reduced mass only | cloud, full ratio |\n"
    << "|---:|---:|---:|---:|---:|\n";
  for (const auto& l : r.limit_check) {
    o << "| " << decade(l.mass_ratio) << " | " << fixed(l.eq40, 4) << " | " << fixed(l.case2_core, 4) << " | "
      << fixed(l.cloud_mass_only, 4) << " | " << fixed(l.cloud_ratio, 4) << " |\n";
  }
  o << "\n";
  return o.str();
}

plot::Drawing table1_heatmap(const Table1Result& r) {
  const auto& G = r.options.geometric_ratios;
  const auto& M = r.options.mass_ratios;
  const std::string title = r.options.scene
                                ? "Collision force ratio min/max F_max (scene-driven; no paper comparison)"
                                : "Collision force ratio min/max F_max (paper Table 1)";
  // The settings line is wrapped at its "; " separators (a scene path makes it long), and the
  // picture is at least as wide as its text: one panel is narrower than its title. DejaVu Sans
  // averages about 0.62 em per character in bold, 0.56 em in regular.
  std::vector<std::string> settings{""};
  {
    const std::string all = settings_line(r);
    std::size_t at = 0;
    while (at < all.size()) {
      std::size_t next = all.find("; ", at);
      const std::string part = all.substr(at, next == std::string::npos ? std::string::npos : next + 2 - at);
      if (!settings.back().empty() && settings.back().size() + part.size() > 95) settings.emplace_back();
      settings.back() += part;
      at = next == std::string::npos ? all.size() : next + 2;
    }
  }
  double text_width = 0.62 * 16 * title.size();
  for (const auto& line : settings) text_width = std::max(text_width, 0.56 * 11 * line.size());
  const double cw = 52, ch = 28, left = 86, top = 74 + 15.0 * (settings.size() - 1), gap = 78;
  const int panels = r.compared ? 3 : 1;
  const double pw = cw * M.size(), ph = ch * G.size();
  plot::Drawing d(std::max(left + panels * pw + (panels - 1) * gap + 30, left + text_width + 20), top + ph + 118);
  d.text({left, 26}, title, 16, plot::Anchor::start, plot::kBlack, true);
  for (std::size_t i = 0; i < settings.size(); ++i)
    d.text({left, 46 + 15.0 * i}, settings[i], 11, plot::Anchor::start, {0.3, 0.3, 0.3});
  const double dmax = 0.005;  // the acceptance bound on |delta|: the colour scale of the difference
  for (int panel = 0; panel < panels; ++panel) {
    const double x0 = left + panel * (pw + gap);
    const char* title = panel == 0 ? "model" : panel == 1 ? "paper (as printed)" : "model - paper";
    d.text({x0 + pw / 2, top - 10}, title, 13, plot::Anchor::middle, plot::kBlack, true);
    for (std::size_t gi = 0; gi < G.size(); ++gi) {
      const double y = top + ch * (G.size() - 1 - gi);  // g grows upwards
      d.text({x0 - 6, y + ch / 2 + 4}, decade(G[gi]), 11, plot::Anchor::end);
      for (std::size_t mi = 0; mi < M.size(); ++mi) {
        const double x = x0 + cw * mi;
        double v;
        plot::Style s;
        s.fill_opacity = 1.0;
        s.stroke = plot::kWhite;
        s.stroke_width = 1.0;
        std::string label;
        bool dark;
        if (panel < 2) {
          v = panel == 0 ? r.ratio[gi][mi] : r.paper[gi][mi];
          s.fill = plot::viridis(v);
          dark = v < 0.55;
          label = fixed(v, 3);
        } else {
          v = r.delta[gi][mi];
          s.fill = plot::diverging(v / dmax);
          dark = std::abs(v) > 0.7 * dmax;
          label = fixed(v * 1e3, 1, true);
        }
        d.rect(x, y, cw, ch, s);
        d.text({x + cw / 2, y + ch / 2 + 4}, label, 10, plot::Anchor::middle, dark ? plot::kWhite : plot::kBlack);
        if (r.compared && excluded(r, gi, mi)) {
          plot::Style frame;
          frame.stroke = {0.9, 0.1, 0.1};
          frame.stroke_width = 2.0;
          d.rect(x + 1, y + 1, cw - 2, ch - 2, frame);
        }
      }
    }
    for (std::size_t mi = 0; mi < M.size(); ++mi) {
      d.text({x0 + cw * (mi + 0.5), top + ph + 16}, decade(M[mi]), 11, plot::Anchor::middle);
    }
    d.text({x0 + pw / 2, top + ph + 36}, r.options.scene ? "mass ratio \xCE\xBC = m_target/m_impactor" : "mass ratio \xCE\xBC = m1/m2", 12, plot::Anchor::middle);
    if (panel == 0) d.text({22, top + ph / 2}, "geometric ratio g = a/b", 12, plot::Anchor::middle, plot::kBlack, false, 90);
    // Colour scale under the panel.
    const double sy = top + ph + 52, sh = 12;
    const int slices = 60;
    for (int k = 0; k < slices; ++k) {
      plot::Style s;
      s.fill_opacity = 1.0;
      s.stroke_width = -1;
      const double t = (k + 0.5) / slices;
      s.fill = panel < 2 ? plot::viridis(t) : plot::diverging(2 * t - 1);
      d.rect(x0 + pw * k / slices, sy, pw / slices + 0.5, sh, s);
    }
    const std::string lo = panel < 2 ? "0" : "-0.005", mid = panel < 2 ? "0.5" : "0", hi = panel < 2 ? "1" : "+0.005";
    d.text({x0, sy + sh + 14}, lo, 10, plot::Anchor::start);
    d.text({x0 + pw / 2, sy + sh + 14}, mid, 10, plot::Anchor::middle);
    d.text({x0 + pw, sy + sh + 14}, hi, 10, plot::Anchor::end);
    if (panel == 2) {
      d.text({x0 + pw / 2, sy + sh + 30}, "cells show delta x 1000; red frame: cell left out", 10, plot::Anchor::middle);
    }
  }
  if (r.compared) {
    std::ostringstream s;
    s << "mean |delta| = " << fixed(r.mean_abs_delta, 5) << ", max |delta| = " << fixed(r.max_abs_delta, 5)
      << " over " << r.cells_compared << " cells (g != 1, g = 10 / mu = 0.1 left out)";
    d.text({left, top + ph + 104}, s.str(), 12, plot::Anchor::start, plot::kBlack, true);
  }
  return d;
}

nlohmann::json table1_json(const Table1Result& r) {
  using nlohmann::json;
  json j;
  j["impactdeck_version"] = kVersion;
  j["geometric_ratios"] = r.options.geometric_ratios;
  j["mass_ratios"] = r.options.mass_ratios;
  j["collision_force_ratio"] = r.ratio;
  j["mass_only_ratio"] = r.mass_only;
  j["settings"] = {{"cloud", to_string(r.options.cloud)},
                   {"grid_steps", r.options.grid_steps},
                   {"uniform_count", r.options.uniform_count},
                   {"seed", r.options.seed},
                   {"points_per_cell", r.points_per_cell},
                   {"size_ratio", r.options.size_ratio},
                   {"radius_rule", to_string(r.options.rule)}};
  j["sharp_points"] = r.sharp_points;      // per row g
  j["flagged_points"] = r.flagged_points;  // per row g, any flag
  if (r.options.scene) {
    const Table1Scene& sc = *r.options.scene;
    j["settings"]["size_ratio"] = nullptr;  // sizes come from the scene
    j["settings"]["radius_rule"] = to_string(sc.setup.rule);
    j["scene"] = {{"file", sc.source},
                  {"impact", sc.impact},
                  {"target", sc.target},
                  {"impactor", sc.impactor},
                  {"stretch_axis", kAxis[sc.stretch_axis]},
                  {"reference_axis", kAxis[(sc.stretch_axis + 1) % 3]},
                  {"impactor_mass_kg", sc.setup.impactor.mass_kg},
                  {"approach_speed_m_s", sc.setup.approach_speed_m_s}};
    j["paper_comparison"] = "none: the table is driven by a scene, not the paper's setting";
  }
  if (r.compared) {
    j["paper_collision_force_ratio"] = r.paper;
    j["delta"] = r.delta;
    j["agreement"] = {{"cells_compared", r.cells_compared},
                      {"mean_abs_delta", r.mean_abs_delta},
                      {"max_abs_delta", r.max_abs_delta},
                      {"excluded_cell", {{"geometric_ratio", kExcludedGeometricRatio},
                                         {"mass_ratio", kExcludedMassRatio},
                                         {"model", r.excluded_cell_model},
                                         {"paper", r.excluded_cell_paper}}}};
  }
  json lim = json::array();
  for (const auto& l : r.limit_check) {
    lim.push_back({{"mass_ratio", l.mass_ratio},
                   {"eq40", l.eq40},
                   {"case2_core", l.case2_core},
                   {"cloud_mass_only", l.cloud_mass_only},
                   {"cloud_ratio", l.cloud_ratio}});
  }
  j["limit_check"] = {{"geometric_ratio", r.limit_row_geometric_ratio}, {"rows", lim}};
  j["seconds"] = r.seconds;
  return j;
}

}  // namespace impactdeck::study
