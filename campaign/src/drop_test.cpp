// Standard drop programmes: the drops of a standard on the part's principal box, as placements of
// the body (docs/campaign-format.md, "[drop_test]").
#include "impactdeck/campaign/drop_test.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>

#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/toml_text.hpp"
#include "detail.hpp"

namespace impactdeck::campaign {

namespace {

// Two directions are taken as parallel (gravity along the floor's normal) within this angle, rad:
// a scene written with exact components meets it to rounding; a tilt a user meant is far above it.
constexpr double kParallelTolerance = 1e-9;
// A height_m equals a preferred IEC height within this, m (a TOML decimal of the listed value).
constexpr double kHeightMatchTolerance_m = 1e-9;

std::string axis_name(int axis) { return std::string(1, static_cast<char>('x' + axis)); }

DropPoint named(const Eigen::Vector3i& s) {
  int nonzero = 0;
  std::string axes;
  for (int i = 0; i < 3; ++i) {
    if (s[i] == 0) continue;
    ++nonzero;
    axes += (s[i] > 0 ? "+" : "-") + axis_name(i);
  }
  const char* kind = nonzero == 1 ? "face " : nonzero == 2 ? "edge " : "corner ";
  return DropPoint{s, kind + axes};
}

// A number for a message: up to 6 significant digits.
std::string short_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

}  // namespace

const std::vector<std::string>& drop_standard_names() {
  static const std::vector<std::string> n = {kMilStd810h, kIsta1a, kIec60068_2_31};
  return n;
}

std::optional<double> mil_std_810h_height_m(double mass_kg, double largest_dimension_m) {
  if (mass_kg >= 0 && mass_kg < 45.4 && largest_dimension_m < 0.91) return 1.22;
  return std::nullopt;
}

std::optional<double> ista_1a_height_m(double mass_kg) {
  if (mass_kg < 0) return std::nullopt;
  if (mass_kg < 10) return 0.76;
  if (mass_kg < 19) return 0.61;
  if (mass_kg < 28) return 0.46;
  if (mass_kg < 45) return 0.31;
  if (mass_kg <= 68) return 0.20;
  return std::nullopt;
}

const std::vector<double>& iec_60068_2_31_heights_m() {
  static const std::vector<double> h = {0.025, 0.05, 0.1, 0.25, 0.5, 1.0};
  return h;
}

std::vector<DropPoint> all_drop_points() {
  std::vector<DropPoint> out;
  for (int i = 0; i < 3; ++i)
    for (int s : {1, -1}) {
      Eigen::Vector3i v = Eigen::Vector3i::Zero();
      v[i] = s;
      out.push_back(named(v));
    }
  for (auto [i, j] : {std::pair{0, 1}, std::pair{0, 2}, std::pair{1, 2}})
    for (int a : {1, -1})
      for (int b : {1, -1}) {
        Eigen::Vector3i v = Eigen::Vector3i::Zero();
        v[i] = a;
        v[j] = b;
        out.push_back(named(v));
      }
  for (int a : {1, -1})
    for (int b : {1, -1})
      for (int c : {1, -1}) out.push_back(named(Eigen::Vector3i(a, b, c)));
  return out;
}

std::vector<DropPoint> ista_1a_drop_points(const Eigen::Vector3d& L) {
  std::vector<DropPoint> out = {named(Eigen::Vector3i(1, 1, 1))};
  std::array<int, 3> by_length = {0, 1, 2};
  std::stable_sort(by_length.begin(), by_length.end(), [&](int a, int b) { return L[a] < L[b]; });
  for (int axis : by_length) {  // the edge along `axis` from the corner: the other two at +
    Eigen::Vector3i v(1, 1, 1);
    v[axis] = 0;
    out.push_back(named(v));
  }
  // A face normal to `axis` has the area of the other two sides.
  std::array<int, 3> by_area = {0, 1, 2};
  std::stable_sort(by_area.begin(), by_area.end(), [&](int a, int b) {
    return L[(a + 1) % 3] * L[(a + 2) % 3] < L[(b + 1) % 3] * L[(b + 2) % 3];
  });
  for (int axis : by_area)
    for (int s : {1, -1}) {
      Eigen::Vector3i v = Eigen::Vector3i::Zero();
      v[axis] = s;
      out.push_back(named(v));
    }
  return out;
}

std::vector<DropPoint> iec_drop_points() {
  std::vector<DropPoint> all = all_drop_points(), out;
  for (const auto& d : all)
    if (d.name.rfind("face", 0) == 0 || d.name.rfind("corner", 0) == 0) out.push_back(d);
  return out;
}

Eigen::Vector3d PrincipalBox::point(const Eigen::Vector3i& s) const {
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p[i] = s[i] > 0 ? high_m[i] : s[i] < 0 ? low_m[i] : 0.5 * (low_m[i] + high_m[i]);
  return p;
}

std::vector<scene::Override> orientation_overrides(const std::string& prefix, const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q);
  Eigen::Vector3d axis = aa.axis();
  double angle_deg = aa.angle() * 180.0 / M_PI;
  if (!(angle_deg > 1e-12) || !axis.allFinite()) {
    axis = Eigen::Vector3d::UnitZ();
    angle_deg = 0.0;
  }
  return {{prefix + "orientation_axis", detail::toml_vec_text(axis)},
          {prefix + "orientation_angle_deg", scene::detail::toml_float_text(angle_deg)}};
}

std::vector<scene::Override> drop_overrides(const scene::Scene& base, std::size_t j, const Drop& d) {
  const std::string prefix = "bodies[" + std::to_string(j) + "].";
  std::vector<scene::Override> o = {{prefix + "position", detail::toml_vec_text(d.position_m / metres_per(base.length_unit))}};
  for (auto& r : orientation_overrides(prefix, d.orientation)) o.push_back(std::move(r));
  o.push_back({prefix + "velocity_m_s", detail::toml_vec_text(d.velocity_m_s)});
  o.push_back({prefix + "angular_velocity_rad_s", "[0, 0, 0]"});
  return o;
}

DropProgramme plan_drops(const scene::Scene& sc, const DropTestSpec& spec, std::optional<std::size_t> impact,
                         const InputContext& ctx) {
  const auto& names = drop_standard_names();
  if (std::find(names.begin(), names.end(), spec.standard) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw ctx.error(spec.standard_place,
                    "unknown standard '" + spec.standard + "' (known: " + list + ")" + did_you_mean(spec.standard, names));
  }
  DropProgramme p;
  std::vector<std::string> body_names;
  for (const auto& b : sc.bodies) body_names.push_back(b.name);
  const auto bit = std::find(body_names.begin(), body_names.end(), spec.body);
  if (bit == body_names.end()) {
    throw ctx.error(spec.body_place, "the scene has no body named '" + spec.body + "'" + did_you_mean(spec.body, body_names));
  }
  p.body_index = static_cast<std::size_t>(bit - body_names.begin());
  const scene::BodySpec& body = sc.bodies[p.body_index];
  if (body.fixed) throw ctx.error(spec.body_place, "body '" + spec.body + "' is fixed: a drop test drops a free body");

  // What the case runs: the body's sequence, else the collected first-contact impact on a plane.
  std::string floor_name;
  for (const auto& s : sc.sequences)
    if (s.body == spec.body) {
      p.sequence = s.name;
      floor_name = s.floor;
      break;
    }
  if (p.sequence.empty()) {
    if (!impact || *impact >= sc.impacts.size()) {
      throw ctx.error(spec.body_place, "the scene has no [[sequences]] of body '" + spec.body +
                                           "' and no [[impacts]] entry: a drop test needs one of them");
    }
    const scene::ImpactSpec& im = sc.impacts[*impact];
    if (!im.first_contact || (im.target != spec.body && im.impactor != spec.body)) {
      throw ctx.error(spec.body_place, "the scene has no [[sequences]] of body '" + spec.body + "', and impact '" + im.name +
                                           "' is not a point = \"first-contact\" impact of it: a drop test needs one of them");
    }
    floor_name = im.target == spec.body ? im.impactor : im.target;
  }
  const scene::BodySpec& floor = sc.body(floor_name);
  const auto floor_shape = scene::make_shape(floor, sc);
  const geometry::Plane* plane = floor_shape->half_space();
  if (!plane) {
    throw ctx.error(spec.body_place, "body '" + spec.body + "' falls onto '" + floor_name +
                                         "', which is not a plane: a drop test drops onto a floor (shape = \"plane\")");
  }
  const Eigen::Vector3d n = (floor.rotation * plane->normal()).normalized();
  const Eigen::Vector3d down = -n;
  if (sc.gravity_m_s2) {
    const double g = sc.gravity_m_s2->norm();
    if (!(g > 0) || (sc.gravity_m_s2->normalized() - down).norm() > kParallelTolerance) {
      throw ctx.error(spec.table_place, "the scene's gravity_m_s2 must point straight into the floor '" + floor_name +
                                            "' (along its inward normal): the drops are vertical");
    }
    p.gravity_m_s2 = g;
  }

  // The principal box: axes by ascending moment, signs fixed (largest own component positive).
  const contact::PreparedBody pb = scene::prepare_body(body, sc);
  p.mass_kg = pb.mass_kg;
  const geometry::PrincipalAxes pa = geometry::principal_axes(pb.inertia_kg_m2);
  Eigen::Matrix3d A = pa.axes;
  for (int i = 0; i < 2; ++i) {
    Eigen::Index k = 0;
    A.col(i).cwiseAbs().maxCoeff(&k);
    if (A(k, i) < 0) A.col(i) = -A.col(i);
  }
  A.col(2) = A.col(0).cross(A.col(1)).normalized();
  p.box.axes = A;
  p.box.centroid_m = pb.volume.centroid_m;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d a = A.col(i);
    const auto hi = pb.shape->support_point(a), lo = pb.shape->support_point(-a);
    if (!hi || !lo) throw ctx.error(spec.body_place, "body '" + spec.body + "' is unbounded: it has no box");
    p.box.high_m[i] = a.dot(hi->point_m - p.box.centroid_m);
    p.box.low_m[i] = a.dot(lo->point_m - p.box.centroid_m);
  }

  // The height.
  const std::string mass_text = short_number(p.mass_kg) + " kg";
  std::vector<DropPoint> points;
  if (spec.standard == kMilStd810h) {
    points = all_drop_points();
    const double largest = p.box.lengths_m().maxCoeff();
    const auto h = mil_std_810h_height_m(p.mass_kg, largest);
    if (!spec.height_m && !h) {
      throw ctx.error(spec.table_place,
                      "body '" + spec.body + "' (" + mass_text + ", largest box side " + short_number(largest) +
                          " m) is outside the row of MIL-STD-810H Table 516.8-VI built in (under 45.4 kg and "
                          "0.91 m: 1.22 m): give drop_test.height_m from the standard's table for this item");
    }
    p.height_m = spec.height_m.value_or(h.value_or(0));
  } else if (spec.standard == kIsta1a) {
    points = ista_1a_drop_points(p.box.lengths_m());
    const auto h = ista_1a_height_m(p.mass_kg);
    if (!spec.height_m && !h) {
      throw ctx.error(spec.table_place, "body '" + spec.body + "' (" + mass_text +
                                            ") is heavier than ISTA 1A's table (up to 68 kg): give drop_test.height_m");
    }
    p.height_m = spec.height_m.value_or(h.value_or(0));
  } else {
    points = iec_drop_points();
    const auto& pref = iec_60068_2_31_heights_m();
    std::string list;
    for (double h : pref) list += (list.empty() ? "" : ", ") + short_number(h);
    if (!spec.height_m) {
      throw ctx.error(spec.table_place, "missing required key 'drop_test.height_m' for " + spec.standard +
                                            ": one of its preferred heights " + list + " (m)");
    }
    const auto match = std::find_if(pref.begin(), pref.end(),
                                    [&](double h) { return std::abs(h - *spec.height_m) <= kHeightMatchTolerance_m; });
    if (match == pref.end()) {
      throw ctx.error(spec.height_place, "must be one of IEC 60068-2-31's preferred heights " + list + " (m), got " +
                                             short_number(*spec.height_m));
    }
    p.height_m = *match;
  }

  // Each drop: the box point straight below the centroid, the lowest point at the height.
  const Eigen::Vector3d f = floor.position_m;
  const double speed = p.sequence.empty() ? std::sqrt(2.0 * p.gravity_m_s2 * p.height_m) : 0.0;
  for (const DropPoint& dp : points) {
    Drop d;
    d.point = dp;
    d.height_m = p.height_m;
    const Eigen::Vector3d u = p.box.point(dp.signs).normalized();  // principal coordinates
    const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(u, down).toRotationMatrix() * A.transpose();
    d.orientation = Eigen::Quaterniond(R).normalized();
    const auto low = pb.shape->support_point(R.transpose() * down);
    if (!low) throw ctx.error(spec.body_place, "body '" + spec.body + "' has no lowest point");
    d.position_m = f + p.height_m * n - R * low->point_m;
    d.velocity_m_s = speed * down;
    p.drops.push_back(std::move(d));
  }
  return p;
}

}  // namespace impactdeck::campaign
