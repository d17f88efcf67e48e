// `campaign collect`: the table of every case, the worst case's files, the map.
#include "impactdeck/campaign/collect.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/plot/html.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report_html.hpp"
#include "impactdeck/scene/scene.hpp"
#include "detail.hpp"

namespace impactdeck::campaign {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Value at a JSON pointer, or null.
json at(const json& j, const char* pointer) {
  const json::json_pointer p(pointer);
  return j.contains(p) ? j.at(p) : json(nullptr);
}

std::string cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
  if (v.is_number()) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g", v.get<double>());
    return b;
  }
  std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' || c == '\r' ? ' ' : c);
  return q + "\"";
}

// The result columns after id, state and the inputs: name and JSON pointer into the impact.
const std::vector<std::pair<std::string, std::string>>& result_columns() {
  static const std::vector<std::pair<std::string, std::string>> c = {
      {"max_force_N", "/max_force_N"},
      {"contact_time_s", "/contact_time_s"},
      {"impulse_total_Ns", "/impulse_total_Ns"},
      {"target_delta_velocity_x_m_s", "/target/delta_velocity_m_s/0"},
      {"target_delta_velocity_y_m_s", "/target/delta_velocity_m_s/1"},
      {"target_delta_velocity_z_m_s", "/target/delta_velocity_m_s/2"},
      {"target_delta_angular_velocity_x_rad_s", "/target/delta_angular_velocity_rad_s/0"},
      {"target_delta_angular_velocity_y_rad_s", "/target/delta_angular_velocity_rad_s/1"},
      {"target_delta_angular_velocity_z_rad_s", "/target/delta_angular_velocity_rad_s/2"},
      {"impactor_delta_velocity_x_m_s", "/impactor/delta_velocity_m_s/0"},
      {"impactor_delta_velocity_y_m_s", "/impactor/delta_velocity_m_s/1"},
      {"impactor_delta_velocity_z_m_s", "/impactor/delta_velocity_m_s/2"},
      {"impactor_delta_angular_velocity_x_rad_s", "/impactor/delta_angular_velocity_rad_s/0"},
      {"impactor_delta_angular_velocity_y_rad_s", "/impactor/delta_angular_velocity_rad_s/1"},
      {"impactor_delta_angular_velocity_z_rad_s", "/impactor/delta_angular_velocity_rad_s/2"},
      {"impulse_relative_error", "/checks/impulse_relative_error"},
      {"energy_relative_error", "/checks/energy_relative_error"},
      {"impact_checks_passed", "/checks/passed"},
      {"fem_linear_momentum_relative_error", "/fem/check/linear_momentum_relative_error"},
      {"fem_angular_momentum_relative_error", "/fem/check/angular_momentum_relative_error"},
      {"fem_check_passed", "/fem/check/passed"},
      {"peak_von_mises_Pa", "/fem/check/stress/verdict/governing/max_von_mises_Pa"},
      {"verdict", "/fem/check/stress/verdict/result"},
      {"safety_factor", "/fem/check/stress/verdict/safety_factor"},
  };
  return c;
}

struct Row {
  std::size_t id = 0;
  CaseState state = CaseState::planned;
  std::string drop;  ///< [drop_test]: the drop's name
  json inputs, impact, result, failure;
};

// Where a drop campaign's case sits on the orientation sphere: the direction the part moves
// towards the impactor, in the part's own frame (world -z for a drop on a floor below).
Eigen::Vector3d drop_direction(const fs::path& scene_file, const std::string& impact) {
  const scene::Scene sc = scene::load_scene(scene_file);
  for (const auto& i : sc.impacts) {
    if (i.name != impact) continue;
    const scene::BodySpec& t = sc.body(i.target);
    const scene::BodySpec& m = sc.body(i.impactor);
    Eigen::Vector3d d = t.velocity_m_s - m.velocity_m_s;
    if (!(d.norm() > 0)) d = -Eigen::Vector3d::UnitZ();
    return t.rotation.transpose() * d.normalized();
  }
  return -Eigen::Vector3d::UnitZ();
}

// A drop test's case on the orientation sphere: the floor's inward normal (the drop direction) in
// the body's own frame; the floor is the sequence's, or the collected impact's other body.
Eigen::Vector3d drop_test_direction(const fs::path& scene_file, const std::string& body, const std::string& sequence,
                                    const std::string& impact) {
  const scene::Scene sc = scene::load_scene(scene_file);
  std::string floor;
  for (const auto& q : sc.sequences)
    if (q.name == sequence) floor = q.floor;
  for (const auto& i : sc.impacts)
    if (sequence.empty() && i.name == impact) floor = i.target == body ? i.impactor : i.target;
  const scene::BodySpec& b = sc.body(body);
  const scene::BodySpec& f = sc.body(floor);
  const auto shape = scene::make_shape(f, sc);
  const geometry::Plane* plane = shape->half_space();
  const Eigen::Vector3d down = plane ? Eigen::Vector3d(-(f.rotation * plane->normal())) : Eigen::Vector3d(-Eigen::Vector3d::UnitZ());
  return b.rotation.transpose() * down.normalized();
}

// `unit`: the points' length unit (a point campaign: the scene's, so that the map overlays the
// cases' decks); none for a drop campaign, whose points are unit directions.
std::string vtp(const std::vector<Eigen::Vector3d>& pts, const std::vector<double>& force,
                const std::vector<std::size_t>& ids, std::optional<LengthUnit> unit) {
  std::ostringstream s;
  s.precision(17);
  const std::size_t n = pts.size();
  const double per = unit ? 1.0 / metres_per(*unit) : 1.0;
  s << "<?xml version=\"1.0\"?>\n<!--\nimpactdeck campaign collect: one point per case, max_force_N in N; ";
  if (unit) {
    s << "points (the impact points, target frame) in " << to_string(*unit) << " (metres per unit "
      << metres_per(*unit) << ", FieldData metres_per_length_unit), the scene's length unit\n";
  } else {
    s << "points: unit drop directions in the part's frame (dimensionless)\n";
  }
  s << "-->\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n";
  if (unit) {
    s << "<FieldData>\n<DataArray type=\"Float64\" Name=\"metres_per_length_unit\" NumberOfTuples=\"1\" "
         "format=\"ascii\">"
      << metres_per(*unit) << "</DataArray>\n</FieldData>\n";
  }
  s << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
    << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
    << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : pts) s << p.x() * per + 0.0 << " " << p.y() * per + 0.0 << " " << p.z() * per + 0.0 << "\n";
  s << "</DataArray></Points>\n<Verts>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) s << i << "\n";
  s << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) s << i + 1 << "\n";
  s << "</DataArray>\n</Verts>\n<PointData Scalars=\"max_force_N\">\n"
    << "<DataArray type=\"Float64\" Name=\"max_force_N\" format=\"ascii\">\n";
  for (double f : force) s << f << "\n";
  s << "</DataArray>\n<DataArray type=\"Int64\" Name=\"case_id\" format=\"ascii\">\n";
  for (std::size_t id : ids) s << id << "\n";
  s << "</DataArray>\n</PointData>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  return s.str();
}

// The map picture: each case a disc coloured by its max force (viridis, low dark), labelled with
// its id, the worst case ringed, a colour bar in N. Point campaigns: an oblique orthographic view
// of the points (target frame); drop campaigns: the orientation sphere as longitude / latitude of
// the drop direction in the part's frame, with its axes.
std::string map_svg(const std::vector<Eigen::Vector3d>& pts, const std::vector<double>& force,
                    const std::vector<std::size_t>& ids, std::optional<std::size_t> worst, bool sphere,
                    const std::string& title) {
  const double W = 820, H = 500, left = 70, right = W - 130, top = 50, bottom = H - 70;
  plot::Drawing d(W, H);
  const double fmin = *std::min_element(force.begin(), force.end());
  const double fmax = *std::max_element(force.begin(), force.end());
  std::vector<plot::Point2> xy;
  if (sphere) {
    for (const auto& p : pts) {
      const Eigen::Vector3d u = p.normalized();
      xy.push_back({std::atan2(u.y(), u.x()) * 180 / M_PI, std::asin(std::clamp(u.z(), -1.0, 1.0)) * 180 / M_PI});
    }
  } else {
    const double az = -62 * M_PI / 180, el = 22 * M_PI / 180;
    const Eigen::Vector3d r(-std::sin(az), std::cos(az), 0);
    const Eigen::Vector3d up(-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el));
    for (const auto& p : pts) xy.push_back({p.dot(r), p.dot(up)});
  }
  double x0 = sphere ? -180 : xy[0].x, x1 = sphere ? 180 : xy[0].x, y0 = sphere ? -90 : xy[0].y, y1 = sphere ? 90 : xy[0].y;
  for (const auto& p : xy) x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  const double span = std::max({x1 - x0, y1 - y0, 1e-30});
  const double scale = std::min((right - left - 20) / (sphere ? x1 - x0 : span), (bottom - top - 20) / (sphere ? y1 - y0 : span));
  const double cx = 0.5 * (left + right), cy = 0.5 * (top + bottom);
  auto to_px = [&](const plot::Point2& p) {
    return plot::Point2{cx + (p.x - 0.5 * (x0 + x1)) * scale, cy - (p.y - 0.5 * (y0 + y1)) * scale};
  };
  if (sphere) {  // axes: longitude and latitude in degrees
    std::vector<plot::Tick> xt, yt;
    for (int lon = -180; lon <= 180; lon += 45) xt.push_back({to_px({double(lon), 0}).x, std::to_string(lon)});
    for (int lat = -90; lat <= 90; lat += 30) yt.push_back({to_px({0, double(lat)}).y, std::to_string(lat)});
    plot::chart_frame(d, to_px({-180, 0}).x, to_px({0, 90}).y, to_px({180, 0}).x, to_px({0, -90}).y, xt, yt,
                      "longitude of the drop direction in the part's frame [deg]", "latitude [deg]");
  } else {
    d.text({left, bottom + 30}, "oblique view of the impact points (the target's frame)", 11);
  }
  for (std::size_t i = 0; i < xy.size(); ++i) {
    const double t = fmax > fmin ? (force[i] - fmin) / (fmax - fmin) : 0.5;
    const plot::Point2 p = to_px(xy[i]);
    d.circle(p, 6, plot::Style{plot::kBlack, 0.4, 1, plot::viridis(t), 1});
    d.text({p.x + 8, p.y - 6}, std::to_string(ids[i]), 10);
    if (worst && ids[i] == *worst) {
      d.circle(p, 11, plot::Style{plot::Colour{0.84, 0.1, 0.1}, 2.5});
      d.text({p.x + 14, p.y + 14}, "worst", 11, plot::Anchor::start, plot::Colour{0.84, 0.1, 0.1}, true);
    }
  }
  d.text({left, 28}, title + " (" + std::to_string(force.size()) + " cases)", 15, plot::Anchor::start, plot::kBlack, true);
  // Colour bar: max force, N.
  const double bx = W - 90, by = top + 20, bh = bottom - top - 40, bw = 16;
  for (int i = 0; i < 40; ++i) {
    plot::Style st{plot::kBlack, -1, 1, plot::viridis((i + 0.5) / 40), 1};
    d.rect(bx, by + bh - bh * (i + 1) / 40, bw, bh / 40 + 0.5, st);
  }
  d.rect(bx, by, bw, bh, plot::Style{plot::kBlack, 1});
  const double lo = fmax > fmin ? fmin : fmin - 0.5, hi = fmax > fmin ? fmax : fmax + 0.5;
  for (double v : plot::nice_ticks(lo, hi, 5)) {
    const double y = by + bh - bh * (v - lo) / (hi - lo);
    d.line({bx + bw, y}, {bx + bw + 4, y}, plot::Style{plot::kBlack, 1});
    d.text({bx + bw + 6, y + 4}, plot::format_number(v), 10);
  }
  d.text({bx - 10, by - 10}, "max force [N]", 11, plot::Anchor::start, plot::kBlack, true);
  return plot::to_svg(d);
}

// The histogram of the judged cases' safety factors (bins of a nice width), the line at 1.
std::string histogram_svg(const std::vector<double>& factors) {
  const double W = 820, H = 300, left = 70, right = W - 30, top = 46, bottom = H - 60;
  plot::Drawing d(W, H);
  const double fmax = *std::max_element(factors.begin(), factors.end());
  const double hi = std::max(1.0, fmax) * 1.0001;
  const std::vector<double> edges_hint = plot::nice_ticks(0.0, hi, 12);
  const double bin = edges_hint.size() >= 2 ? edges_hint[1] - edges_hint[0] : hi;
  const auto bins = static_cast<std::size_t>(std::ceil(hi / bin));
  std::vector<std::size_t> count(bins, 0);
  for (double f : factors) count[std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, f) / bin))]++;
  const std::size_t cmax = *std::max_element(count.begin(), count.end());
  const double x_hi = bin * static_cast<double>(bins);
  auto X = [&](double v) { return left + (right - left) * v / x_hi; };
  auto Y = [&](double c) { return bottom - (bottom - top) * c / static_cast<double>(std::max<std::size_t>(cmax, 1)); };
  std::vector<plot::Tick> xt, yt;
  for (double v : plot::nice_ticks(0.0, x_hi, 8)) xt.push_back({X(v), plot::format_number(v)});
  for (double v : plot::nice_ticks(0.0, static_cast<double>(std::max<std::size_t>(cmax, 1)), 4))
    if (v == std::floor(v)) yt.push_back({Y(v), plot::format_number(v)});
  plot::chart_frame(d, left, top, right, bottom, xt, yt, "safety factor (yield strength / governing stress)", "cases");
  for (std::size_t k = 0; k < bins; ++k) {
    if (!count[k]) continue;
    const double x = X(bin * static_cast<double>(k)), w = X(bin * static_cast<double>(k + 1)) - x;
    const bool below = bin * static_cast<double>(k + 1) <= 1.0;
    d.rect(x + 1, Y(static_cast<double>(count[k])), w - 2, bottom - Y(static_cast<double>(count[k])),
           plot::Style{plot::kBlack, 0.6, 1, below ? plot::Colour{0.84, 0.37, 0.0} : plot::Colour{0.0, 0.45, 0.70}, 1});
  }
  plot::Style one{plot::Colour{0.75, 0.1, 0.1}, 1.5};
  one.dash = 6;
  d.line({X(1.0), top}, {X(1.0), bottom}, one);
  d.text({X(1.0) + 4, top + 12}, "1: yield", 11, plot::Anchor::start, plot::Colour{0.75, 0.1, 0.1});
  d.text({left, 28}, "Safety factors of the " + std::to_string(factors.size()) + " judged cases", 15, plot::Anchor::start,
         plot::kBlack, true);
  return plot::to_svg(d);
}

std::string number_text(const json& v, int digits = 4) {
  if (!v.is_number()) return "";
  char b[40];
  std::snprintf(b, sizeof b, "%.*g", digits, v.get<double>());
  return b;
}

// A case's input for the page, short: numbers (also inside the JSON text an override holds) to
// 3 significant digits, a vector as (x, y, z).
std::string compact_input(const json& v) {
  json x = v.is_string() ? json::parse(v.get<std::string>(), nullptr, false) : v;
  if (x.is_discarded()) return v.get<std::string>();
  if (x.is_number()) return plot::format_number(x.get<double>(), 3);
  if (x.is_array() && !x.empty() && std::all_of(x.begin(), x.end(), [](const json& e) { return e.is_number(); })) {
    std::string o = "(";
    for (const auto& e : x) o += (o.size() > 1 ? ", " : "") + plot::format_number(e.get<double>(), 3);
    return o + ")";
  }
  return v.is_string() ? v.get<std::string>() : v.dump();
}

// The campaign's report page: the verdict over the cases, the counts, the table, the map.
std::string report_page(const fs::path& dir, const std::string& impact, const std::vector<std::string>& keys,
                        const std::vector<Row>& rows, const CollectResult& out, bool all_stress,
                        const std::string& map_svg, const std::string& worst_svg, const std::string& worst_caption) {
  plot::HtmlPage page("impactdeck campaign: " + dir.filename().string());
  // Verdict per case: the FEM stress verdict where ccx ran, else the Hertz peak pressure against
  // the yield onset 1.60 sigma_y (safety factor 1 / ratio).
  std::size_t yields = 0, judged = 0;
  double smallest = 0;
  std::optional<std::size_t> smallest_id;
  std::vector<std::string> verdicts(rows.size()), factors(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Row& r = rows[k];
    if (r.state != CaseState::done) continue;
    json sf = at(r.impact, "/fem/check/stress/verdict/safety_factor");
    std::string word = at(r.impact, "/fem/check/stress/verdict/result").is_string()
                           ? at(r.impact, "/fem/check/stress/verdict/result").get<std::string>()
                           : "";
    if (!sf.is_number()) {
      const json ratio = at(r.impact, "/validity/peak_pressure_over_yield_onset");
      if (ratio.is_number() && ratio.get<double>() > 0) {
        sf = 1.0 / ratio.get<double>();
        word = ratio.get<double>() > 1.0 ? "yields" : "survives";
        word += " (Hertz)";
      }
    }
    if (!sf.is_number()) continue;
    ++judged;
    if (word.rfind("yields", 0) == 0) ++yields;
    if (!smallest_id || sf.get<double>() < smallest) smallest = sf.get<double>(), smallest_id = r.id;
    verdicts[k] = std::string(word.rfind("yields", 0) == 0 ? plot::HtmlPage::kFail : plot::HtmlPage::kPass) + word;
    factors[k] = number_text(sf);
  }
  std::string verdict;
  if (judged == 0) {
    verdict = "Verdict: none (no case has a yield strength to judge by)";
  } else {
    verdict = std::string(yields > 0 ? "Verdict: yields in " + std::to_string(yields) + " of " : "Verdict: survives in all ") +
              std::to_string(judged) + " judged cases (smallest safety factor " + number_text(json(smallest)) +
              ", case " + std::to_string(*smallest_id) + ")";
  }
  page.html("<p id=\"verdict\" class=\"verdict " + std::string(judged == 0 ? "" : yields > 0 ? "fail" : "pass") + "\">" +
            plot::html_escape(verdict) + "</p>");
  const bool named_drops = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.drop.empty(); });
  auto drop_of = [&](std::size_t id) { return id < rows.size() && !rows[id].drop.empty() ? rows[id].drop + ", " : ""; };
  page.table({"campaign", "impact", "done", "failed", "pending", "worst case"},
             {{dir.string(), impact, std::to_string(out.done), std::to_string(out.failed), std::to_string(out.pending),
               out.worst_id ? std::to_string(*out.worst_id) + " (" + drop_of(*out.worst_id) +
                                  (all_stress ? "largest peak von Mises)" : "largest max force)")
                            : "-"}});

  // The five cases closest to yielding (smallest safety factor; by max force when none is judged).
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k].state == CaseState::done) order.push_back(k);
  auto factor = [&](std::size_t k) { return factors[k].empty() ? 1e300 : std::strtod(factors[k].c_str(), nullptr); };
  auto force = [&](std::size_t k) {
    const json f = at(rows[k].impact, "/max_force_N");
    return f.is_number() ? f.get<double>() : 0.0;
  };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return judged ? factor(x) < factor(y) : force(x) > force(y);
  });
  if (!order.empty()) {
    page.heading(judged ? "Top 5: the smallest safety factors" : "Top 5: the largest max forces");
    std::vector<std::vector<std::string>> top;
    for (std::size_t n = 0; n < std::min<std::size_t>(5, order.size()); ++n) {
      const Row& r = rows[order[n]];
      std::string inputs = r.drop;
      for (const auto& key : keys)
        if (r.inputs.contains(key)) inputs += (inputs.empty() ? "" : "; ") + key + " = " + compact_input(r.inputs[key]);
      top.push_back({std::to_string(r.id), verdicts[order[n]], factors[order[n]], number_text(at(r.impact, "/max_force_N")),
                     number_text(at(r.impact, "/fem/check/stress/verdict/governing/max_von_mises_Pa")), inputs});
    }
    page.table({"case", "verdict", "safety factor", "max force (N)", "peak von Mises (Pa)", "inputs"}, top);
  }
  if (!map_svg.empty())
    page.html("<figure class=\"campaign-map\">" + plot::inline_svg(map_svg) +
              "<figcaption>Max force of each case (map.svg): case ids beside the discs, the worst case ringed"
              "</figcaption></figure>");
  if (!worst_svg.empty())
    page.html("<figure class=\"part-drawing\" id=\"worst-case\">" + plot::inline_svg(worst_svg) + "<figcaption>Worst case " +
              std::to_string(*out.worst_id) + ": " + plot::html_escape(worst_caption) + "</figcaption></figure>");
  std::vector<double> judged_factors;
  for (const auto& f : factors)
    if (!f.empty()) judged_factors.push_back(std::strtod(f.c_str(), nullptr));
  if (!judged_factors.empty())
    page.html("<figure class=\"safety-histogram\">" + plot::inline_svg(histogram_svg(judged_factors)) +
              "<figcaption>Histogram of the safety factors (below 1: yields)</figcaption></figure>");

  // One compact row per case; its warnings folded (they repeat from case to case).
  std::vector<std::string> header = {"case", "state"};
  if (named_drops) header.push_back("drop");
  header.insert(header.end(), keys.begin(), keys.end());
  for (const char* h : {"max force (N)", "impulse error (Eq. 31)", "energy error (Eq. 32)", "FEM momentum error",
                        "checks", "verdict", "safety factor", "warnings / reason"})
    header.push_back(h);
  std::string t = "<table class=\"cases\">\n<tr>";
  for (const auto& h : header) t += "<th>" + plot::html_escape(h) + "</th>";
  t += "</tr>\n";
  auto td = [](const std::string& c) {
    const std::size_t marker = std::string(plot::HtmlPage::kPass).size();
    if (c.rfind(plot::HtmlPage::kPass, 0) == 0) return "<td class=\"pass\">" + plot::html_escape(c.substr(marker)) + "</td>";
    if (c.rfind(plot::HtmlPage::kFail, 0) == 0) return "<td class=\"fail\">" + plot::html_escape(c.substr(marker)) + "</td>";
    return "<td>" + plot::html_escape(c) + "</td>";
  };
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Row& r = rows[k];
    t += "<tr>" + td(std::to_string(r.id)) + td(to_string(r.state));
    if (named_drops) t += td(r.drop);
    for (const auto& key : keys) t += td(r.inputs.contains(key) ? compact_input(r.inputs[key]) : "");
    t += td(number_text(at(r.impact, "/max_force_N"), 4));
    t += td(number_text(at(r.impact, "/checks/impulse_relative_error"), 3));
    t += td(number_text(at(r.impact, "/checks/energy_relative_error"), 3));
    t += td(number_text(at(r.impact, "/fem/check/linear_momentum_relative_error"), 3));
    const json passed = r.result.is_null() ? json(nullptr) : r.result.value("all_checks_passed", json(nullptr));
    t += td(passed.is_boolean() ? std::string(passed.get<bool>() ? plot::HtmlPage::kPass : plot::HtmlPage::kFail) +
                                      (passed.get<bool>() ? "passed" : "failed")
                                : "");
    t += td(verdicts[k]) + td(factors[k]);
    // The run's warnings hold the validity warnings already: each once.
    std::vector<std::string> notes;
    if (!r.failure.is_null()) notes.push_back(r.failure.value("reason", ""));
    for (const auto& w : r.result.is_null() ? json::array() : r.result.value("warnings", json::array()))
      if (w.is_string() && std::find(notes.begin(), notes.end(), w.get<std::string>()) == notes.end())
        notes.push_back(w.get<std::string>());
    if (notes.empty()) {
      t += "<td></td>";
    } else {
      t += "<td><details><summary>" + std::to_string(notes.size()) + (notes.size() == 1 ? " note" : " notes") +
           "</summary><ul>";
      for (const auto& n : notes) t += "<li>" + plot::html_escape(n) + "</li>";
      t += "</ul></details></td>";
    }
    t += "</tr>\n";
  }
  page.heading("Cases");
  page.html("<div class=\"wide\">" + t + "</table></div>");
  return page.str();
}

// A drop test's sequence in a done case's result.json: its worst impact (null when the sequence has
// no impact). Refused when the case has no sequence of that name.
json sequence_worst_impact(const json& result, const std::string& sequence, const fs::path& file) {
  std::vector<std::string> names;
  const json seqs = result.value("sequences", json::array());
  for (const json& q : seqs.is_array() ? seqs : json::array()) {
    if (!q.is_object() || !q.value("name", json()).is_string()) continue;
    if (q["name"] != sequence) {
      names.push_back(q["name"].get<std::string>());
      continue;
    }
    const json w = q.value("worst_impact_index", json());
    const json impacts = q.value("impacts", json::array());
    if (w.is_null()) return json(nullptr);
    if (!w.is_number_unsigned() || !impacts.is_array() || w.get<std::size_t>() >= impacts.size() ||
        !impacts[w.get<std::size_t>()].is_object()) {
      throw InputError(file.string(), "key 'sequences." + sequence + ".worst_impact_index'",
                       "must index the sequence's impacts");
    }
    json i = impacts[w.get<std::size_t>()];
    i["sequence_impact_count"] = impacts.size();
    return i;
  }
  throw InputError(file.string(), "key 'sequences'",
                   "has no sequence named '" + sequence + "', the sequence the drop test collects" +
                       did_you_mean(sequence, names));
}

// The collected impact of a done case's result.json: refused when the case has none of that name
// (its overrides renamed it; the table would be empty).
json collected_impact(const json& result, const std::string& impact, const fs::path& file) {
  std::vector<std::string> names;
  for (const json& i : result["impacts"]) {
    if (i["name"] == impact) return i;
    names.push_back(i["name"].get<std::string>());
  }
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "'" : ", '") + n + "'";
  throw InputError(file.string(), "key 'impacts'",
                   "has no impact named '" + impact + "', the impact the campaign collects (the case's impacts: " +
                       (list.empty() ? "none" : list) + "; did its overrides rename it?)" + did_you_mean(impact, names));
}

// The worst case's folder is copied as it is: only real folders and regular files, no link.
void check_tree(const fs::path& root) {
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::file_status st = it->symlink_status(ec);
    if (fs::is_symlink(st)) detail::refuse_link(it->path());
    if (!fs::is_directory(st) && !fs::is_regular_file(st)) {
      throw InputError(it->path().string(), "file", "is not a regular file or folder: the worst case is not copied");
    }
  }
  if (ec) throw InputError(root.string(), "folder", "cannot be read: " + ec.message());
}

}  // namespace

CollectResult collect(const fs::path& dir_in, const std::function<void(const CollectResult&)>& before_commit) {
  const detail::Plan plan = detail::read_plan(dir_in);
  const fs::path& dir = plan.dir;
  const std::string& impact = plan.impact;
  const std::vector<std::string>& keys = plan.keys;
  const auto& generators = plan.generators;
  const bool points = std::find(generators.begin(), generators.end(), "points") != generators.end();
  const bool drop_test = std::find(generators.begin(), generators.end(), "drop_test") != generators.end();
  const bool drops = drop_test || std::find(generators.begin(), generators.end(), "orientations") != generators.end();
  std::string drop_body;
  if (drop_test) {
    const json d = plan.doc.value("drop_test", json::object());
    if (!d.is_object() || !d.value("body", json()).is_string()) {
      throw InputError(plan.file.string(), "key 'drop_test.body'", "must be a body name (string)");
    }
    drop_body = d["body"].get<std::string>();
  }

  CollectResult out;
  std::vector<Row> rows;
  for (const detail::PlanCase& c : plan.cases) {
    Row r;
    r.id = c.id;
    r.inputs = c.overrides;
    r.drop = c.drop;
    r.state = case_state(dir, r.id);
    const fs::path folder = case_folder(dir, r.id);
    if (r.state == CaseState::done) {
      r.result = detail::read_result(dir, r.id);
      r.impact = plan.sequence.empty() ? collected_impact(r.result, impact, folder / "result.json")
                                       : sequence_worst_impact(r.result, plan.sequence, folder / "result.json");
      detail::check_inside(dir, fs::path("cases") / std::to_string(r.id) / "scene.toml", detail::Kind::file);
      ++out.done;
    } else if (r.state == CaseState::failed) {
      r.failure = detail::read_failure(dir, r.id);
      ++out.failed;
    } else {
      ++out.pending;
    }
    rows.push_back(std::move(r));
  }

  // The table.
  std::ostringstream csv;
  csv << "id,state";
  if (drop_test) csv << ",drop";
  for (const auto& k : keys) csv << "," << cell(k);
  if (!plan.sequence.empty()) csv << ",sequence_impact_index,sequence_impact_count";
  for (const auto& [name, ptr] : result_columns()) csv << "," << name;
  csv << ",all_checks_passed,reason\n";
  json cases = json::array();
  for (const Row& r : rows) {
    csv << r.id << "," << to_string(r.state);
    if (drop_test) csv << "," << cell(r.drop);
    for (const auto& k : keys) csv << "," << cell(r.inputs.contains(k) ? r.inputs[k] : json(nullptr));
    if (!plan.sequence.empty()) csv << "," << cell(at(r.impact, "/index")) << "," << cell(at(r.impact, "/sequence_impact_count"));
    for (const auto& [name, ptr] : result_columns()) csv << "," << cell(at(r.impact, ptr.c_str()));
    csv << "," << cell(r.result.is_null() ? json(nullptr) : r.result.value("all_checks_passed", json(nullptr)));
    csv << "," << cell(r.failure.is_null() ? json(nullptr) : r.failure.value("reason", json("")));
    csv << "\n";
    // JSON: the case's results under the keys of `run --json` (the collected impact's object).
    json j = r.impact.is_object() ? r.impact : json::object();
    j["id"] = r.id;
    j["state"] = to_string(r.state);
    j["inputs"] = r.inputs;
    if (drop_test) j["drop"] = r.drop;
    if (!r.result.is_null()) {
      j["all_checks_passed"] = r.result.value("all_checks_passed", json(nullptr));
      j["warnings"] = r.result.value("warnings", json::array());
    }
    if (!r.failure.is_null()) j["reason"] = r.failure.value("reason", "");
    cases.push_back(std::move(j));
  }

  // The worst case: the largest peak von Mises where every done case has one, else max force.
  bool all_stress = out.done > 0;
  for (const Row& r : rows)
    if (r.state == CaseState::done && !at(r.impact, "/fem/check/stress/verdict/governing/max_von_mises_Pa").is_number())
      all_stress = false;
  const char* worst_key = all_stress ? "/fem/check/stress/verdict/governing/max_von_mises_Pa" : "/max_force_N";
  double worst = -1;
  for (const Row& r : rows) {
    const json v = at(r.impact, worst_key);
    if (r.state == CaseState::done && v.is_number() && v.get<double>() > worst) {
      worst = v.get<double>();
      out.worst_id = r.id;
    }
  }
  out.worst_case_by = all_stress ? "peak_von_mises_Pa" : "max_force_N";
  if (out.worst_id && std::isfinite(worst)) out.worst_value = worst;

  // Everything is checked before anything is written: `collect` a real folder (created by the
  // transaction when missing), the worst case's folder free of links.
  const fs::path cdir = dir / "collect";
  detail::check_inside(dir, "collect", detail::Kind::folder);
  if (out.worst_id) check_tree(case_folder(dir, *out.worst_id));
  json doc = {{"campaign", dir.string()},
                    {"impact", impact},
                    {"keys", keys},
                    {"done", out.done},
                    {"failed", out.failed},
                    {"pending", out.pending},
                    {"worst_case_id", out.worst_id ? json(*out.worst_id) : json(nullptr)},
                    {"worst_case_by", out.worst_case_by},
                    {"cases", cases}};
  if (!plan.sequence.empty()) doc["sequence"] = plan.sequence;
  if (drop_test) {
    doc["drop_test"] = plan.doc["drop_test"];
    doc["worst_drop"] = out.worst_id ? json(rows[*out.worst_id].drop) : json(nullptr);
  }
  // One transaction (common/run_transaction.hpp): every file and the worst case's copy appear
  // together, or nothing changes.
  RunTransaction txn(cdir, "collect");
  txn.run([&] {
    const std::string where = plan.file.string();
    auto add = [&](const std::string& name, const std::string& text) {
      detail::write_new_file(txn.file(name, where, "collect"), text);
      return cdir / name;
    };
    const std::string text = csv.str();
    out.csv = add("cases.csv", text);
    // the table's JSON sidecar: the unit of every column (common/csv_sidecar.hpp)
    add(csv_sidecar_path(out.csv).filename().string(),
        csv_sidecar_text(out.csv, csv_columns(std::string_view(text).substr(0, text.find('\n'))),
                         {{"title", "impactdeck campaign collect: one row per case (cases.json: the same, "
                                    "with every case's inputs and results)"}}));
    out.json = add("cases.json", doc.dump(2) + "\n");

    // The map over the part's surface (points) or the orientation sphere (drops).
    std::string map_text;
    if (points || drops) {
      std::vector<Eigen::Vector3d> pts;
      std::vector<double> force;
      std::vector<std::size_t> ids;
      std::optional<LengthUnit> unit;  // a point campaign's: its scene's length unit
      for (const Row& r : rows) {
        const json f = at(r.impact, "/max_force_N");
        if (r.state != CaseState::done || !f.is_number()) continue;
        if (!drops && !unit) unit = scene::load_scene(case_folder(dir, r.id) / "scene.toml").length_unit;
        if (drop_test) {
          pts.push_back(drop_test_direction(case_folder(dir, r.id) / "scene.toml", drop_body, plan.sequence, impact));
        } else if (drops) {
          pts.push_back(drop_direction(case_folder(dir, r.id) / "scene.toml", impact));
        } else {
          pts.push_back(plan.cases[r.id].point_m.value_or(Eigen::Vector3d::Zero()));
        }
        force.push_back(f.get<double>());
        ids.push_back(r.id);
      }
      if (!pts.empty()) {
        const std::string title = drops ? "Max force over the drop orientations" : "Max force over the impact points";
        map_text = map_svg(pts, force, ids, out.worst_id, drops, title);
        out.map_svg = add("map.svg", map_text);
        out.map_vtp = add("map.vtp", vtp(pts, force, ids, unit));
      }
    }
    // The worst case of a drop campaign as it touches the floor (its orientation).
    std::string worst_svg, worst_caption;
    if (drops && out.worst_id && plan.sequence.empty()) {
      for (const Row& r : rows) {
        const json p = at(r.impact, "/contact_point_m"), n = at(r.impact, "/contact_normal");
        auto vec3 = [](const json& v) {
          return v.is_array() && v.size() == 3 && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_number(); });
        };
        if (r.id != *out.worst_id || !vec3(p) || !vec3(n)) continue;
        const Eigen::Vector3d point(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
        const Eigen::Vector3d normal(n[0].get<double>(), n[1].get<double>(), n[2].get<double>());
        worst_svg = scene::impact_part_svg(scene::load_scene(case_folder(dir, r.id) / "scene.toml"), impact, point,
                                           normal, worst_caption);
      }
    }
    out.report_html = add("report.html", report_page(dir, impact.empty() ? "sequence '" + plan.sequence + "' (its worst impact)" : impact, keys, rows, out, all_stress, map_text, worst_svg,
                                                     worst_caption));
    if (out.worst_id) {  // a copy of the worst case's folder (scene, decks, result), checked above
      const fs::path stage = txn.folder("worst_case", where, "collect");
      std::error_code ec;
      fs::copy(case_folder(dir, *out.worst_id), stage, fs::copy_options::recursive | fs::copy_options::copy_symlinks, ec);
      if (ec) throw InputError((cdir / "worst_case").string(), "copy", "cannot copy the worst case: " + ec.message());
      fs::remove(stage / ".lock", ec);
      out.worst_case = cdir / "worst_case";
    }
    if (before_commit) before_commit(out);  // its failure rolls the collect back
    txn.commit();
  });
  refresh_states(dir);
  return out;
}

std::string collect_json(const CollectResult& r) {
  auto path = [](const std::optional<fs::path>& p) { return p ? json(p->string()) : json(nullptr); };
  const json doc = {{"csv", r.csv.string()},
                    {"json", r.json.string()},
                    {"report_html", r.report_html.string()},
                    {"map_svg", path(r.map_svg)},
                    {"map_vtp", path(r.map_vtp)},
                    {"done", r.done},
                    {"failed", r.failed},
                    {"pending", r.pending},
                    {"worst_case", {{"id", r.worst_id ? json(*r.worst_id) : json(nullptr)},
                                    {"by", r.worst_case_by},
                                    {"value", r.worst_value ? json(*r.worst_value) : json(nullptr)},
                                    {"folder", path(r.worst_case)}}}};
  return doc.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace impactdeck::campaign
