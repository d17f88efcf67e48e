#include "impactdeck/study/sweep_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"
#include "number_text.hpp"

namespace impactdeck::study {
namespace {

std::string g17(double v) { return detail::g17(v, "sweep output"); }

void header(std::ostream& o, const char* comment, const SweepMeta& m, const SweepResult& r) {
  o << comment << " impactdeck " << kVersion << " sweep: maximal Hertz contact force over the surface\n";
  if (!m.source.empty()) o << comment << " scene: " << m.source << "\n";
  if (!m.impact.empty())
    o << comment << " impact: " << m.impact << " (" << m.impactor << " hits " << m.target << " along the inward normal)\n";
  if (!m.cloud.empty()) o << comment << " cloud: " << m.cloud << ", " << r.points.size() << " points\n";
  o << comment << " units: SI (m, kg, N, s); coordinates in the target's frame\n";
  o << comment << " force ratio min/max = " << g17(r.force_ratio) << " (min at point " << r.min_index
    << ", max at point " << r.max_index << ")\n";
  o << comment << " flagged points: " << r.flagged_count << " (the contact model does not apply there: left out of "
    << "min/max; column flag names why";
  for (int f = 1; f < collision::kContactFlagCount; ++f) {
    if (r.flag_counts[f] > 0) o << "; " << collision::flag_word(static_cast<collision::ContactFlag>(f)) << " " << r.flag_counts[f];
  }
  o << ")\n";
}

double max_force(const SweepResult& r) { return r.points[r.max_index].max_force_N; }

// A body's local radius as written: a flat place (zero curvature, e.g. a face of a box) has an
// infinite radius, written as 0 (no real radius is 0), since the files hold no Inf.
double radius_out(double r) { return std::isinf(r) ? 0.0 : r; }

}  // namespace

void write_sweep_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta) {
  write_file_atomically(path, [&](std::ostream& o) {
    header(o, "#", meta, r);
    o << "index,x_m,y_m,z_m,nx,ny,nz,target_radius_m,impactor_radius_m,effective_radius_m,"
         "reduced_mass_kg,hertz_constant_N_per_m1_5,max_indentation_m,max_force_N,force_ratio,"
         "compression_time_s,restitution,contact_time_s,impulse_total_Ns,"
         "target_dvx_m_s,target_dvy_m_s,target_dvz_m_s,target_dwx_rad_s,target_dwy_rad_s,target_dwz_rad_s,"
         "contact_ellipse_axis_ratio,sharp_feature,flag\n";
    const double fmax = max_force(r);
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      const PointResult& p = r.points[i];
      o << i;
      for (double v : {p.point_m.x(), p.point_m.y(), p.point_m.z(), p.normal.x(), p.normal.y(), p.normal.z(),
                       radius_out(p.target_radius_m), radius_out(p.impactor_radius_m), p.effective_radius_m,
                       p.reduced_mass_kg,
                       p.hertz_constant, p.max_indentation_m, p.max_force_N, p.max_force_N / fmax,
                       p.compression_time_s, p.restitution, p.contact_time_s, p.impulse_total_Ns,
                       p.target_delta_velocity_m_s.x(), p.target_delta_velocity_m_s.y(),
                       p.target_delta_velocity_m_s.z(), p.target_delta_angular_velocity_rad_s.x(),
                       p.target_delta_angular_velocity_rad_s.y(), p.target_delta_angular_velocity_rad_s.z(),
                       p.contact_ellipse_axis_ratio}) {
        o << ',' << g17(v);
      }
      o << ',' << (p.sharp_feature ? 1 : 0) << ',' << collision::flag_word(p.flag) << '\n';
    }
  });
}

void write_sweep_curves_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta) {
  if (r.curves_N.empty() || r.curve_samples < 2) {
    throw InputError(path.string(), "curves", "the sweep was run without force curves");
  }
  write_file_atomically(path, [&](std::ostream& o) {
    header(o, "#", meta, r);
    o << "# F(t) at each point: " << r.curve_samples << " samples uniform over [0, contact time]\n";
    o << "point,time_s,force_N\n";
    const double last = static_cast<double>(r.curve_samples - 1);
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      if (r.points[i].flagged()) continue;  // no curve where the model does not apply
      const double tc = r.points[i].contact_time_s;
      for (std::size_t k = 0; k < r.curve_samples; ++k) {
        o << i << ',' << g17(tc * static_cast<double>(k) / last) << ','
          << g17(r.curves_N[i * r.curve_samples + k]) << '\n';
      }
    }
  });
}

void write_sweep_pos(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta) {
  write_file_atomically(path, [&](std::ostream& o) {
    header(o, "//", meta, r);
    o << "// open with: gmsh " << path.filename().string() << "\n";
    const double fmax = max_force(r);
    auto sp = [&](const PointResult& p, double v) {
      o << "SP(" << g17(p.point_m.x()) << "," << g17(p.point_m.y()) << "," << g17(p.point_m.z()) << "){" << g17(v)
        << "};\n";
    };
    // The computed views hold the points not flagged; sharp points and the other flagged points get
    // views of their own (value: the flag's number, collision::ContactFlag).
    const char* names[] = {"max_force_N", "force_ratio", "contact_ellipse_axis_ratio"};
    for (int view = 0; view < 3; ++view) {
      o << "View \"" << names[view] << "\" {\n";
      for (const PointResult& p : r.points) {
        if (p.flagged()) continue;
        sp(p, view == 0 ? p.max_force_N : view == 1 ? p.max_force_N / fmax : p.contact_ellipse_axis_ratio);
      }
      o << "};\n";
    }
    if (r.sharp_count > 0) {
      o << "View \"sharp_feature\" {\n";
      for (const PointResult& p : r.points)
        if (p.sharp_feature) sp(p, 1.0);
      o << "};\n";
    }
    if (r.flagged_count > r.sharp_count) {
      o << "View \"flag\" {\n";
      for (const PointResult& p : r.points)
        if (p.flagged() && !p.sharp_feature) sp(p, static_cast<double>(p.flag));
      o << "};\n";
    }
  });
}

void write_sweep_vtp(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta) {
  const std::size_t n = r.points.size();
  const double fmax = max_force(r);
  write_file_atomically(path, [&](std::ostream& o) {
    o << "<?xml version=\"1.0\"?>\n";
    std::ostringstream h;
    header(h, "", meta, r);
    std::string comment = h.str();
    // "--" is not allowed inside an XML comment.
    for (std::size_t k; (k = comment.find("--")) != std::string::npos;) comment.replace(k, 2, "- -");
    o << "<!--\n" << comment << "-->\n";
    o << "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
      << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
      << "<PointData Scalars=\"max_force_N\" Normals=\"normal\">\n";
    auto scalar = [&](const char* name, auto get) {
      o << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (std::size_t i = 0; i < n; ++i) o << g17(get(r.points[i])) << ((i + 1) % 6 == 0 || i + 1 == n ? "\n" : " ");
      o << "</DataArray>\n";
    };
    scalar("max_force_N", [](const PointResult& p) { return p.max_force_N; });
    scalar("force_ratio", [&](const PointResult& p) { return p.max_force_N / fmax; });
    scalar("reduced_mass_kg", [](const PointResult& p) { return p.reduced_mass_kg; });
    scalar("effective_radius_m", [](const PointResult& p) { return p.effective_radius_m; });
    scalar("target_radius_m", [](const PointResult& p) { return radius_out(p.target_radius_m); });
    scalar("contact_ellipse_axis_ratio", [](const PointResult& p) { return p.contact_ellipse_axis_ratio; });
    scalar("sharp_feature", [](const PointResult& p) { return p.sharp_feature ? 1.0 : 0.0; });
    scalar("flag", [](const PointResult& p) { return static_cast<double>(p.flag); });  // collision::ContactFlag
    o << "<DataArray type=\"Float64\" Name=\"normal\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const PointResult& p : r.points)
      o << g17(p.normal.x()) << ' ' << g17(p.normal.y()) << ' ' << g17(p.normal.z()) << '\n';
    o << "</DataArray>\n</PointData>\n<Points>\n"
      << "<DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const PointResult& p : r.points)
      o << g17(p.point_m.x()) << ' ' << g17(p.point_m.y()) << ' ' << g17(p.point_m.z()) << '\n';
    o << "</DataArray>\n</Points>\n<Verts>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) o << i << ((i + 1) % 16 == 0 || i + 1 == n ? "\n" : " ");
    o << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) o << i + 1 << ((i + 1) % 16 == 0 || i + 1 == n ? "\n" : " ");
    o << "</DataArray>\n</Verts>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  });
}

// ---------------------------------------------------------------------------------------------
// The picture

namespace {

struct Scaled {
  double factor;
  const char* unit;
};

Scaled force_unit(double f_N) {
  if (f_N >= 1e6) return {1e-6, "MN"};
  if (f_N >= 1e3) return {1e-3, "kN"};
  return {1.0, "N"};
}

std::string coords(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s << "(" << plot::format_number(p.x(), 4) << ", " << plot::format_number(p.y(), 4) << ", "
    << plot::format_number(p.z(), 4) << ") m";
  return s.str();
}

}  // namespace

plot::Drawing force_map_drawing(const geometry::Shape& target, const Eigen::Vector3d& c,
                                const SweepResult& r, const ForceMapOptions& o) {
  if (r.points.empty()) throw InputError("", "force map", "no points to draw");
  const double az = o.azimuth_deg * M_PI / 180.0, el = o.elevation_deg * M_PI / 180.0;
  // d: unit vector from the body towards the viewer; u: screen right; w: screen up.
  const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (std::abs(d.dot(up)) > 0.99) up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = up.cross(d).normalized();
  const Eigen::Vector3d w = d.cross(u);

  // Half-extents of the cloud about the centroid: directions for the wireframe.
  Eigen::Vector3d ext = Eigen::Vector3d::Zero();
  for (const auto& p : r.points) ext = ext.cwiseMax((p.point_m - c).cwiseAbs());
  const double big = std::max(ext.maxCoeff(), 1e-300);
  ext = ext.cwiseMax(Eigen::Vector3d::Constant(1e-9 * big));

  struct WirePoint {
    Eigen::Vector3d p;
    bool front;
  };
  std::vector<std::vector<WirePoint>> wires;
  auto trace = [&](auto param, int samples) {
    std::vector<WirePoint> line;
    for (int k = 0; k <= samples; ++k) {
      const Eigen::Vector3d dir = param(static_cast<double>(k) / samples).cwiseProduct(ext);
      if (!(dir.norm() > 0.0)) continue;
      if (auto e = target.ray_exit(c, dir)) line.push_back({e->point_m, e->normal.dot(d) >= 0.0});
    }
    if (line.size() >= 2) wires.push_back(std::move(line));
  };
  for (int i = 0; i < o.meridians; ++i) {
    const double phi = 2.0 * M_PI * i / o.meridians;
    trace([&](double t) {
      const double th = M_PI * t;
      return Eigen::Vector3d(std::cos(th), std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi));
    }, 72);
  }
  for (int j = 1; j <= o.parallels; ++j) {
    const double th = M_PI * j / (o.parallels + 1);
    trace([&](double t) {
      const double phi = 2.0 * M_PI * t;
      return Eigen::Vector3d(std::cos(th), std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi));
    }, 120);
  }

  // Fit the projection into the plot area.
  const double left = 30, top = 78, right = o.width_px - 150, bottom = o.height_px - 30;
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  auto grow = [&](const Eigen::Vector3d& p) {
    const double x = (p - c).dot(u), y = (p - c).dot(w);
    xmin = std::min(xmin, x); xmax = std::max(xmax, x);
    ymin = std::min(ymin, y); ymax = std::max(ymax, y);
  };
  for (const auto& line : wires)
    for (const auto& wp : line) grow(wp.p);
  for (const auto& p : r.points) grow(p.point_m);
  const double pad = 24;
  const double bw = std::max(xmax - xmin, 1e-12 * big), bh = std::max(ymax - ymin, 1e-12 * big);
  const double scale = std::min((right - left - 2 * pad) / bw, (bottom - top - 2 * pad) / bh);
  const double cx = 0.5 * (left + right) - scale * 0.5 * (xmin + xmax);
  const double cy = 0.5 * (top + bottom) + scale * 0.5 * (ymin + ymax);
  auto screen = [&](const Eigen::Vector3d& p) {
    return plot::Point2{cx + scale * (p - c).dot(u), cy - scale * (p - c).dot(w)};
  };

  // Circle size: radius proportional to F_max, the largest about half the spacing of the points
  // seen from the front.
  const double fmin = r.points[r.min_index].max_force_N, fmax = r.points[r.max_index].max_force_N;
  const double shown = o.max_points > 0 ? std::min<double>(r.points.size(), o.max_points) : r.points.size();
  const double front_count = std::max(1.0, 0.5 * shown);
  const double area = M_PI / 4.0 * std::max(scale * bw, 1.0) * std::max(scale * bh, 8.0);
  const double rmax = std::clamp(0.4 * std::sqrt(area / front_count), 2.0, 20.0);
  auto shade = [&](double f) { return fmax > fmin ? (f - fmin) / (fmax - fmin) : 1.0; };

  plot::Drawing dr(o.width_px, o.height_px);
  plot::Style back_wire;
  back_wire.stroke = {0.80, 0.80, 0.80};
  back_wire.stroke_width = 0.7;
  plot::Style front_wire = back_wire;
  front_wire.stroke = {0.45, 0.45, 0.45};
  front_wire.stroke_width = 0.9;
  auto draw_wires = [&](bool front) {
    for (const auto& line : wires) {
      std::vector<plot::Point2> run;
      for (std::size_t k = 0; k < line.size(); ++k) {
        if (line[k].front == front) {
          run.push_back(screen(line[k].p));
        } else {
          if (run.size() >= 2) dr.polyline(run, front ? front_wire : back_wire);
          run.clear();
        }
      }
      if (run.size() >= 2) dr.polyline(run, front ? front_wire : back_wire);
    }
  };

  // Points back to front; a large cloud thinned by a fixed stride (deterministic), extremes kept.
  const std::size_t stride =
      o.max_points > 0 && r.points.size() > o.max_points ? (r.points.size() + o.max_points - 1) / o.max_points : 1;
  std::vector<std::size_t> order;
  order.reserve(r.points.size() / stride + 2);
  for (std::size_t i = 0; i < r.points.size(); i += stride) order.push_back(i);
  for (std::size_t e : {r.min_index, r.max_index})
    if (e % stride != 0) order.push_back(e);
  // Ties (equal depth) drawn in point order: std::sort with the index as tie-break, not
  // stable_sort, whose temporary buffer (operator new nothrow, freed with free) trips ASan's
  // alloc-dealloc check under clang with libstdc++ 12.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double da = r.points[a].point_m.dot(d), db = r.points[b].point_m.dot(d);
    return da < db || (da == db && a < b);
  });
  auto draw_points = [&](bool front) {
    for (std::size_t i : order) {
      const PointResult& p = r.points[i];
      if ((p.normal.dot(d) >= 0.0) != front) continue;
      if (p.flagged()) {
        // No force there (sharp, no-fit, ...): a small grey cross instead of a circle.
        plot::Style x;
        x.stroke = {0.45, 0.45, 0.45};
        x.stroke_width = 1.0;
        x.stroke_opacity = front ? 1.0 : 0.4;
        const plot::Point2 c0 = screen(p.point_m);
        const double h = 0.35 * rmax;
        dr.line({c0.x - h, c0.y - h}, {c0.x + h, c0.y + h}, x);
        dr.line({c0.x - h, c0.y + h}, {c0.x + h, c0.y - h}, x);
        continue;
      }
      plot::Style s;
      s.fill = plot::viridis(shade(p.max_force_N));
      s.fill_opacity = front ? 0.92 : 0.30;
      s.stroke = plot::mix(s.fill, plot::kBlack, 0.45);
      s.stroke_width = front ? 0.6 : 0.4;
      s.stroke_opacity = front ? 1.0 : 0.4;
      dr.circle(screen(p.point_m), rmax * p.max_force_N / fmax, s);
    }
  };
  draw_wires(false);
  draw_points(false);
  draw_wires(true);
  draw_points(true);

  // Extremes.
  auto mark = [&](std::size_t i, const char* label, double dy) {
    const PointResult& p = r.points[i];
    const plot::Point2 s = screen(p.point_m);
    plot::Style ring;
    ring.stroke = {0.85, 0.1, 0.1};
    ring.stroke_width = 1.6;
    dr.circle(s, rmax * p.max_force_N / fmax + 3.0, ring);
    dr.text({s.x + rmax * p.max_force_N / fmax + 6.0, s.y + dy}, label, 12, plot::Anchor::start,
            {0.75, 0.05, 0.05}, true);
  };
  mark(r.min_index, "min", 14.0);  // below right: the two labels stay apart when the points are close
  mark(r.max_index, "max", -4.0);

  // Titles.
  const Scaled fu = force_unit(fmax);
  dr.text({left, 26}, o.title.empty() ? "Maximal collision force over the surface" : o.title, 16,
          plot::Anchor::start, plot::kBlack, true);
  std::ostringstream sub;
  sub << r.points.size() << " points";
  if (stride > 1) sub << " (" << order.size() << " drawn)";
  sub << ", min/max = " << plot::format_number(r.force_ratio, 4) << "; min "
      << plot::format_number(fmin * fu.factor, 4) << " " << fu.unit << " at " << coords(r.points[r.min_index].point_m)
      << ", max " << plot::format_number(fmax * fu.factor, 4) << " " << fu.unit << " at "
      << coords(r.points[r.max_index].point_m);
  dr.text({left, 48}, sub.str(), 12);
  // The sharp-point count goes on the legend line: on the subtitle it ran past the picture's edge.
  std::string legend = "circle radius \xE2\x88\x9D F_max, darker = lower force; faded: far side";
  if (r.flagged_count > 0) {
    legend += "; " + std::to_string(r.flagged_count) + " flagged points (grey x, left out: ";
    bool any = false;
    for (int f = 1; f < collision::kContactFlagCount; ++f) {
      if (r.flag_counts[f] == 0) continue;
      legend += std::string(any ? ", " : "") + std::to_string(r.flag_counts[f]) + " " +
                collision::flag_word(static_cast<collision::ContactFlag>(f));
      any = true;
    }
    legend += ")";
  }
  dr.text({left, 66}, legend, 11, plot::Anchor::start, {0.35, 0.35, 0.35});

  // Colour bar.
  const double bx = o.width_px - 112, by0 = top + 20, by1 = bottom - 20, bwid = 20;
  const int slices = 96;
  for (int k = 0; k < slices; ++k) {
    plot::Style s;
    s.fill = plot::viridis((k + 0.5) / slices);
    s.fill_opacity = 1.0;
    s.stroke_width = -1;
    const double y = by1 - (by1 - by0) * (k + 1) / slices;
    dr.rect(bx, y, bwid, (by1 - by0) / slices + 0.6, s);
  }
  plot::Style frame;
  frame.stroke_width = 0.8;
  dr.rect(bx, by0, bwid, by1 - by0, frame);
  const double lo = fmin * fu.factor, hi = fmax * fu.factor;
  for (double v : plot::nice_ticks(lo, hi, 6)) {
    const double t = hi > lo ? (v - lo) / (hi - lo) : 1.0;
    const double y = by1 - (by1 - by0) * t;
    dr.line({bx + bwid, y}, {bx + bwid + 5, y}, frame);
    dr.text({bx + bwid + 8, y + 4}, plot::format_number(v, 4), 11);
  }
  dr.text({bx + bwid / 2, by0 - 10}, std::string("F_max [") + fu.unit + "]", 12, plot::Anchor::middle);
  return dr;
}

}  // namespace impactdeck::study
