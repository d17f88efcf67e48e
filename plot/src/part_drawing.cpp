// Pictures of a part from its triangles (see part_drawing.hpp).
#include "impactdeck/plot/part_drawing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>

#include "impactdeck/common/error.hpp"

namespace impactdeck::plot {
namespace {

using V3 = Eigen::Vector3d;

bool finite(const V3& v) { return v.allFinite(); }

// The triangles worth drawing: indices in range, corners finite, not degenerate.
std::vector<std::array<int, 3>> valid_triangles(const PartSurface& s) {
  std::vector<std::array<int, 3>> out;
  out.reserve(s.triangles.size());
  const long n = static_cast<long>(s.vertices.size());
  for (const auto& t : s.triangles) {
    bool ok = true;
    for (int i : t) ok = ok && i >= 0 && i < n && finite(s.vertices[static_cast<std::size_t>(i)]);
    if (ok && t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) out.push_back(t);
  }
  return out;
}

// One pass of vertex clustering: every vertex moves to the mean of its cell of a res^3 grid over the
// bounding box; triangles whose corners share a cell vanish, repeated ones are kept once.
PartSurface cluster(const PartSurface& s, int res, const std::vector<double>* values, std::vector<double>* values_out) {
  V3 lo = V3::Constant(1e300), hi = V3::Constant(-1e300);
  for (const auto& t : s.triangles)
    for (int i : t) lo = lo.cwiseMin(s.vertices[static_cast<std::size_t>(i)]), hi = hi.cwiseMax(s.vertices[static_cast<std::size_t>(i)]);
  const double cell = std::max((hi - lo).maxCoeff() / res, 1e-300);
  std::unordered_map<std::uint64_t, int> cell_index;
  std::vector<int> vertex_cell(s.vertices.size(), -1);
  PartSurface o;
  std::vector<double> counts, sums;
  for (const auto& t : s.triangles) {
    for (int i : t) {
      const auto ui = static_cast<std::size_t>(i);
      if (vertex_cell[ui] >= 0) continue;
      const V3 q = (s.vertices[ui] - lo) / cell;
      const auto c = [&](double x) { return static_cast<std::uint64_t>(std::clamp(x, 0.0, static_cast<double>(res))); };
      const std::uint64_t key = (c(q.x()) << 42) | (c(q.y()) << 21) | c(q.z());
      auto [it, fresh] = cell_index.emplace(key, static_cast<int>(o.vertices.size()));
      if (fresh) {
        o.vertices.push_back(V3::Zero());
        counts.push_back(0);
        sums.push_back(0);
      }
      const auto k = static_cast<std::size_t>(it->second);
      vertex_cell[ui] = it->second;
      o.vertices[k] += s.vertices[ui];
      counts[k] += 1;
      if (values) sums[k] += (*values)[ui];
    }
  }
  for (std::size_t k = 0; k < o.vertices.size(); ++k) o.vertices[k] /= counts[k];
  if (values_out) {
    values_out->resize(o.vertices.size());
    for (std::size_t k = 0; k < o.vertices.size(); ++k) (*values_out)[k] = sums[k] / counts[k];
  }
  std::unordered_map<std::uint64_t, char> seen;
  for (const auto& t : s.triangles) {
    std::array<int, 3> m{vertex_cell[static_cast<std::size_t>(t[0])], vertex_cell[static_cast<std::size_t>(t[1])],
                         vertex_cell[static_cast<std::size_t>(t[2])]};
    if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) continue;
    std::array<std::uint64_t, 3> k{static_cast<std::uint64_t>(m[0]), static_cast<std::uint64_t>(m[1]),
                                   static_cast<std::uint64_t>(m[2])};
    std::sort(k.begin(), k.end());
    if (seen.emplace((k[0] << 42) | (k[1] << 21) | k[2], 1).second) o.triangles.push_back(m);
  }
  return o;
}

double area(const PartSurface& s, const std::array<int, 3>& t) {
  const V3& a = s.vertices[static_cast<std::size_t>(t[0])];
  return (s.vertices[static_cast<std::size_t>(t[1])] - a).cross(s.vertices[static_cast<std::size_t>(t[2])] - a).norm();
}

// A view: screen right and up (world, orthonormal); toward the viewer is right x up.
struct View {
  std::string name;
  V3 right, up;
  V3 toward() const { return right.cross(up); }
};

View isometric(const V3& toward, const std::string& name) {
  const V3 v = toward.normalized();
  const V3 up = (V3::UnitZ() - V3::UnitZ().dot(v) * v).normalized();
  return {name, up.cross(v), up};
}

// Clips segment a-b to the box; false when nothing is left (Liang-Barsky).
bool clip(Point2& a, Point2& b, double x0, double y0, double x1, double y1) {
  double t0 = 0, t1 = 1;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double p[4] = {-dx, dx, -dy, dy}, q[4] = {a.x - x0, x1 - a.x, a.y - y0, y1 - a.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0) t0 = std::max(t0, r);
    else t1 = std::min(t1, r);
  }
  if (t0 > t1) return false;
  const Point2 a0 = a;
  a = {a0.x + t0 * dx, a0.y + t0 * dy};
  b = {a0.x + t1 * dx, a0.y + t1 * dy};
  return true;
}

void arrow(Drawing& d, Point2 from, Point2 to, const Colour& c, double width) {
  Style s;
  s.stroke = c;
  s.stroke_width = width;
  const double dx = to.x - from.x, dy = to.y - from.y, len = std::hypot(dx, dy);
  if (len < 6) {  // along the line of sight: a ring
    d.circle(to, 5, s);
    return;
  }
  const double ux = dx / len, uy = dy / len, head = std::min(12.0, 0.4 * len);
  d.line(from, {to.x - ux * head * 0.6, to.y - uy * head * 0.6}, s);
  Style f = s;
  f.fill = c;
  f.fill_opacity = 1;
  f.stroke_width = 0.5;
  d.polygon({to, {to.x - ux * head - uy * head * 0.4, to.y - uy * head + ux * head * 0.4},
             {to.x - ux * head + uy * head * 0.4, to.y - uy * head - ux * head * 0.4}},
            f);
}

const Colour kContact{0.84, 0.1, 0.1}, kNormal{0.0, 0.45, 0.70}, kForce{0.84, 0.37, 0.0}, kFloor{0.3, 0.3, 0.3};
const Colour kAxes[3] = {{0.75, 0.1, 0.1}, {0.1, 0.55, 0.1}, {0.1, 0.2, 0.8}};

// One view's panel in the drawing: its frame, and the projection of the world into it (one
// scale for every view, so that they compare; centred on the view's box).
struct Panel {
  View view;
  double x = 0, y = 0, w = 0, h = 0, label_h = 0;
  double scale = 1, mx = 0, my = 0;  // pixels per world unit; the view box's centre (world)
  Point2 project(const V3& p) const {
    const double cx = x + w / 2, cy = y + label_h + (h - label_h) / 2;
    return {cx + (p.dot(view.right) - mx) * scale, cy - (p.dot(view.up) - my) * scale};
  }
  bool clip_inside(Point2& a, Point2& b) const { return clip(a, b, x + 1, y + label_h, x + w - 1, y + h - 1); }
};

// The values shown as colours (field drawings) and their range; `values` null: plain shading.
struct FieldRange {
  const std::vector<double>* values = nullptr;
  double lo = 0, hi = 1;
};

// The part's front faces, back to front (painter's algorithm), shaded or coloured by the field.
void draw_faces(Drawing& d, const PartSurface& s, const Panel& p, const FieldRange& field) {
  const V3 toward = p.view.toward();
  const V3 light = (toward + 0.6 * p.view.up - 0.4 * p.view.right).normalized();
  struct Face {
    double depth;
    std::size_t index;
    double shade;
  };
  std::vector<Face> faces;
  for (std::size_t f = 0; f < s.triangles.size(); ++f) {
    const auto& t = s.triangles[f];
    const V3& a = s.vertices[static_cast<std::size_t>(t[0])];
    const V3& b = s.vertices[static_cast<std::size_t>(t[1])];
    const V3& c = s.vertices[static_cast<std::size_t>(t[2])];
    const V3 n = (b - a).cross(c - a);
    const double len = n.norm();
    if (!(len > 0) || n.dot(toward) <= 0) continue;
    faces.push_back({(a + b + c).dot(toward), f, std::max(0.0, n.dot(light) / len)});
  }
  std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) { return x.depth < y.depth; });
  for (const Face& f : faces) {
    const auto& t = s.triangles[f.index];
    Colour c;
    if (field.values) {
      const std::vector<double>& v = *field.values;
      const double val = (v[static_cast<std::size_t>(t[0])] + v[static_cast<std::size_t>(t[1])] +
                          v[static_cast<std::size_t>(t[2])]) / 3;
      c = mix(kBlack, viridis((val - field.lo) / (field.hi - field.lo)), 0.8 + 0.2 * f.shade);
    } else {
      const double g = 0.35 + 0.6 * f.shade;
      c = {0.55 * g + 0.1, 0.62 * g + 0.1, 0.72 * g + 0.1};
    }
    Style st;
    st.fill = c;
    st.fill_opacity = 1;
    st.stroke = c;
    st.stroke_width = 0.4;
    d.polygon({p.project(s.vertices[static_cast<std::size_t>(t[0])]), p.project(s.vertices[static_cast<std::size_t>(t[1])]),
               p.project(s.vertices[static_cast<std::size_t>(t[2])])},
              st);
  }
}

// The floor through the contact point, as a hatched line where the view sees it edge-on enough.
void draw_floor(Drawing& d, const Panel& p, const V3& point, const V3& floor_normal, double width_px) {
  const V3 n = floor_normal.normalized();
  const Point2 nn{n.dot(p.view.right), -n.dot(p.view.up)};  // screen direction of the normal
  const double nl = std::hypot(nn.x, nn.y);
  if (nl <= 0.2) return;  // seen nearly face-on: no line
  const Point2 o = p.project(point);
  const Point2 dir{-nn.y / nl, nn.x / nl};
  Point2 a{o.x - dir.x * 2 * width_px, o.y - dir.y * 2 * width_px};
  Point2 e{o.x + dir.x * 2 * width_px, o.y + dir.y * 2 * width_px};
  if (!p.clip_inside(a, e)) return;
  Style fl;
  fl.stroke = kFloor;
  fl.stroke_width = 2;
  d.line(a, e, fl);
  Style hatch = fl;
  hatch.stroke_width = 1;
  const double len = std::hypot(e.x - a.x, e.y - a.y);
  const Point2 in{-nn.x / nl * 8, -nn.y / nl * 8};  // into the floor
  for (double u = 6; u < len; u += 14) {
    const Point2 q{a.x + (e.x - a.x) * u / len, a.y + (e.y - a.y) * u / len};
    Point2 q0 = q, q1{q.x + in.x - dir.x * 6, q.y + in.y - dir.y * 6};
    if (p.clip_inside(q0, q1)) d.line(q0, q1, hatch);
  }
}

// The markers on top of the part: floor, own axes, force, normal, contact point, peak.
// `size`: the part's extent; `reach`: the arrows' length (world units).
void draw_markers(Drawing& d, const Panel& p, const PartMarkers& m, double size, double reach, double width_px) {
  const bool has_point = m.contact_point && finite(*m.contact_point);
  if (has_point && m.floor_normal && finite(*m.floor_normal)) draw_floor(d, p, *m.contact_point, *m.floor_normal, width_px);
  if (m.frame) {
    const Point2 o = p.project(m.frame_origin);
    for (int i = 0; i < 3; ++i) {
      const V3 axis = m.frame->col(i);
      if (!finite(axis)) continue;
      const Point2 tip = p.project(m.frame_origin + axis.normalized() * 0.2 * size);
      arrow(d, o, tip, kAxes[i], 1.5);
      d.text({tip.x + 3, tip.y - 3}, m.frame_names[static_cast<std::size_t>(i)], 11, Anchor::start, kAxes[i], true);
    }
  }
  if (has_point) {
    const Point2 c = p.project(*m.contact_point);
    if (m.force && finite(*m.force)) {
      // Beside the normal (a normal force is collinear with it): shifted 9 px sideways.
      const Point2 tail = p.project(*m.contact_point - m.force->normalized() * reach);
      const double dx = c.x - tail.x, dy = c.y - tail.y, len = std::hypot(dx, dy);
      const Point2 off = len > 6 ? Point2{-dy / len * 9, dx / len * 9} : Point2{0, 0};
      arrow(d, {tail.x + off.x, tail.y + off.y}, {c.x + off.x, c.y + off.y}, kForce, 3);
    }
    if (m.normal && finite(*m.normal)) arrow(d, c, p.project(*m.contact_point + m.normal->normalized() * 0.6 * reach), kNormal, 1.5);
    Style dot;
    dot.fill = kContact;
    dot.fill_opacity = 1;
    dot.stroke = kBlack;
    d.circle(c, 4.5, dot);
  }
  if (m.peak_point && finite(*m.peak_point)) {
    const Point2 c = p.project(*m.peak_point);
    Style ring;
    ring.stroke = kBlack;
    ring.stroke_width = 2;
    d.circle(c, 7, ring);
    ring.stroke = kWhite;
    ring.stroke_width = 1;
    d.circle(c, 9, ring);
    d.text({c.x + 11, c.y - 8}, m.peak_label, 11, Anchor::start, kBlack, true);
  }
}

// The scale bar (at most max_bar_px long; `scale` pixels per world unit) and the markers' legend on the
// line at `ly`.
void draw_legend(Drawing& d, const PartMarkers& m, double ly, double x0, double max_bar_px, double scale,
                 const PartDrawingOptions& opt) {
  const bool has_point = m.contact_point && finite(*m.contact_point);
  const double unit = opt.length_unit_size > 0 && std::isfinite(opt.length_unit_size) ? opt.length_unit_size : 1.0;
  const std::vector<double> nice = nice_ticks(0, max_bar_px / scale / unit, 2);
  const double bar_len = nice.size() >= 2 ? nice[1] : max_bar_px / scale / unit;
  const double bar_px = bar_len * unit * scale;
  Style sb;
  sb.stroke_width = 2;
  d.line({x0, ly}, {x0 + bar_px, ly}, sb);
  d.line({x0, ly - 4}, {x0, ly + 4}, sb);
  d.line({x0 + bar_px, ly - 4}, {x0 + bar_px, ly + 4}, sb);
  d.text({x0 + bar_px + 6, ly + 4}, format_number(bar_len) + " " + opt.length_unit, 11);
  double lx = x0 + bar_px + 80;
  const double ty = ly + 4;
  auto entry = [&](const std::string& label, const Colour& c, int kind) {
    Style st;
    st.stroke = c;
    st.stroke_width = kind == 2 ? 3 : 2;
    if (kind == 0) {
      st.fill = c;
      st.fill_opacity = 1;
      st.stroke = kBlack;
      st.stroke_width = 1;
      d.circle({lx + 6, ty - 4}, 4.5, st);
    } else if (kind == 3) {
      st.stroke = kBlack;
      d.circle({lx + 6, ty - 4}, 6, st);
    } else {
      d.line({lx, ty - 4}, {lx + 18, ty - 4}, st);
    }
    d.text({lx + 24, ty}, label, 11);
    lx += 24 + 6.5 * static_cast<double>(label.size()) + 14;
  };
  if (has_point) entry("contact point", kContact, 0);
  if (has_point && m.normal) entry("normal n", kNormal, 1);
  if (has_point && m.force) entry("force on the part", kForce, 2);
  if (has_point && m.floor_normal) entry("floor", kFloor, 1);
  if (m.frame) entry(m.frame_label, kAxes[0], 1);
  if (m.peak_point) entry(m.peak_label, kBlack, 3);
}

// The field's colour bar at (bx, by), bh tall, with its ticks (in value_scale units) and label.
void draw_colour_bar(Drawing& d, double bx, double by, double bh, const FieldRange& field,
                     const PartDrawingOptions& opt) {
  const double bw = 18;
  const int steps = 48;
  for (int i = 0; i < steps; ++i) {
    Style st;
    st.fill = viridis((i + 0.5) / steps);
    st.fill_opacity = 1;
    st.stroke_width = -1;
    d.rect(bx, by + bh - bh * (i + 1) / steps, bw, bh / steps + 0.5, st);
  }
  Style border;
  border.stroke_width = 1;
  d.rect(bx, by, bw, bh, border);
  for (double tv : nice_ticks(field.lo * opt.value_scale, field.hi * opt.value_scale, 6)) {
    const double y = by + bh - bh * (tv / opt.value_scale - field.lo) / (field.hi - field.lo);
    if (y < by - 0.5 || y > by + bh + 0.5) continue;
    d.line({bx + bw, y}, {bx + bw + 4, y}, border);
    d.text({bx + bw + 6, y + 4}, format_number(tv), 11);
  }
  d.text({bx, by - 10}, opt.value_label, 11, Anchor::start, kBlack, true);
}

}  // namespace

PartSurface decimate(const PartSurface& surface, std::size_t max_triangles, std::vector<double>* values) {
  PartSurface s{surface.vertices, valid_triangles(surface)};
  max_triangles = std::max<std::size_t>(max_triangles, 16);
  if (s.triangles.size() <= max_triangles) return s;
  std::vector<double> in_values = values ? *values : std::vector<double>{};
  for (int res : {256, 128, 96, 64, 48, 32, 24, 16, 12, 8}) {
    std::vector<double> out_values;
    PartSurface c = cluster(s, res, values ? &in_values : nullptr, values ? &out_values : nullptr);
    if (c.triangles.size() <= max_triangles || res == 8) {
      if (c.triangles.size() > max_triangles) {  // keep the largest: a hard bound whatever the mesh
        std::vector<std::size_t> order(c.triangles.size());
        std::iota(order.begin(), order.end(), 0);
        std::nth_element(order.begin(), order.begin() + static_cast<long>(max_triangles), order.end(),
                         [&](std::size_t a, std::size_t b) { return area(c, c.triangles[a]) > area(c, c.triangles[b]); });
        std::vector<std::array<int, 3>> kept;
        for (std::size_t k = 0; k < max_triangles; ++k) kept.push_back(c.triangles[order[k]]);
        c.triangles = std::move(kept);
      }
      if (values) *values = std::move(out_values);
      return c;
    }
  }
  return s;  // not reached
}

Drawing part_drawing(const PartSurface& surface, const PartMarkers& m, const PartDrawingOptions& opt) {
  const bool field = !opt.vertex_values.empty();
  if (field && opt.vertex_values.size() != surface.vertices.size()) {
    throw InputError("", "part drawing", "one value per vertex is needed");
  }
  std::vector<double> values = opt.vertex_values;
  const PartSurface s = decimate(surface, opt.max_triangles, field ? &values : nullptr);
  if (s.triangles.empty()) throw InputError("", "part drawing", "no triangle to draw");

  // Extent of the part (and the markers' reach: arrows are a third of the part's size).
  V3 lo = V3::Constant(1e300), hi = V3::Constant(-1e300);
  for (const auto& t : s.triangles)
    for (int i : t) lo = lo.cwiseMin(s.vertices[static_cast<std::size_t>(i)]), hi = hi.cwiseMax(s.vertices[static_cast<std::size_t>(i)]);
  const double size = std::max((hi - lo).norm(), 1e-300);
  const double reach = 0.35 * size;
  std::vector<V3> extent_points;
  for (const auto& t : s.triangles)
    for (int i : t) extent_points.push_back(s.vertices[static_cast<std::size_t>(i)]);
  const bool has_point = m.contact_point && finite(*m.contact_point);
  if (has_point) {
    extent_points.push_back(*m.contact_point);
    if (m.normal && finite(*m.normal)) extent_points.push_back(*m.contact_point + m.normal->normalized() * reach);
    if (m.force && finite(*m.force)) extent_points.push_back(*m.contact_point - m.force->normalized() * reach);
  }

  // Views and panels.
  std::vector<View> views;
  if (field) {
    views = {isometric({1, -1, 1}, "isometric, from the front (-y), right (+x) and above"),
             isometric({-1, 1, 1}, "isometric, from behind (+y), left (-x) and above")};
  } else {
    views = {{"front: x right, z up (seen from -y)", V3::UnitX(), V3::UnitZ()},
             {"side: y right, z up (seen from +x)", V3::UnitY(), V3::UnitZ()},
             {"top: x right, y up (seen from +z)", V3::UnitX(), V3::UnitY()},
             isometric({1, -1, 1}, "isometric (from -y, +x, +z)")};
  }
  const double bar_w = field ? 110 : 0;
  const double title_h = 30, gap = 10, label_h = 18;
  const double panel_w = (opt.width_px - bar_w - 3 * gap) / 2, panel_h = field ? 360 : 280;
  const int rows = static_cast<int>((views.size() + 1) / 2);
  const double legend_h = 46;
  const double height = title_h + rows * (panel_h + gap) + legend_h;
  Drawing d(opt.width_px, height);
  d.text({gap, 20}, opt.title, 15, Anchor::start, kBlack, true);

  // One scale for every view (they compare), the largest that fits each panel.
  double scale = 1e300;
  std::vector<std::array<double, 4>> boxes;  // per view: min x, max x, min y, max y (world units)
  for (const View& v : views) {
    std::array<double, 4> b{1e300, -1e300, 1e300, -1e300};
    for (const V3& p : extent_points) {
      const double x = p.dot(v.right), y = p.dot(v.up);
      b = {std::min(b[0], x), std::max(b[1], x), std::min(b[2], y), std::max(b[3], y)};
    }
    boxes.push_back(b);
    const double pad = 24;
    scale = std::min({scale, (panel_w - 2 * pad) / std::max(b[1] - b[0], 1e-9 * size),
                      (panel_h - label_h - 2 * pad) / std::max(b[3] - b[2], 1e-9 * size)});
  }

  FieldRange range;
  if (field) {
    range.values = &values;
    range.lo = *std::min_element(values.begin(), values.end());
    range.hi = *std::max_element(values.begin(), values.end());
    if (!(range.hi > range.lo)) range.hi = range.lo + 1;
  }

  Style frame;
  frame.stroke = {0.8, 0.8, 0.8};
  for (std::size_t k = 0; k < views.size(); ++k) {
    Panel p;
    p.view = views[k];
    p.x = gap + static_cast<double>(k % 2) * (panel_w + gap);
    p.y = title_h + static_cast<double>(k / 2) * (panel_h + gap);
    p.w = panel_w;
    p.h = panel_h;
    p.label_h = label_h;
    p.scale = scale;
    p.mx = 0.5 * (boxes[k][0] + boxes[k][1]);
    p.my = 0.5 * (boxes[k][2] + boxes[k][3]);
    d.rect(p.x, p.y, p.w, p.h, frame);
    d.text({p.x + 6, p.y + 14}, p.view.name, 11, Anchor::start, {0.25, 0.25, 0.25});
    draw_faces(d, s, p, range);
    draw_markers(d, p, m, size, reach, opt.width_px);
  }

  // Scale bar and legend under the panels.
  draw_legend(d, m, title_h + rows * (panel_h + gap) + 14, gap, panel_w * 0.3, scale, opt);
  if (field) draw_colour_bar(d, opt.width_px - bar_w + 10, title_h + 30, rows * (panel_h + gap) - 70, range, opt);
  return d;
}

}  // namespace impactdeck::plot
