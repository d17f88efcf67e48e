#include "impactdeck/study/sweep_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <mutex>
#include <thread>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/version.hpp"
#include "number_text.hpp"
#include "parallel.hpp"
#include "table_text.hpp"
#include "vtk_xml.hpp"

namespace impactdeck::study {
namespace {

constexpr const char* kWhat = "sweep output";
std::string num(double v) { return detail::shortest(v, kWhat); }

void header(std::ostream& o, const char* comment, const SweepMeta& m, const SweepResult& r,
            LengthUnit unit = LengthUnit::m) {
  o << comment << " impactdeck " << kVersion << " sweep: maximal Hertz contact force over the surface\n";
  if (!m.source.empty()) o << comment << " scene: " << m.source << "\n";
  if (!m.impact.empty())
    o << comment << " impact: " << m.impact << " (" << m.impactor << " hits " << m.target << " along the inward normal)\n";
  if (!m.cloud.empty()) o << comment << " cloud: " << m.cloud << ", " << r.points.size() << " points\n";
  if (!m.contact_law.empty()) o << comment << " contact law: " << m.contact_law << "\n";
  o << comment << " units: SI (m, kg, N, s) but coordinates in " << to_string(unit) << " (metres per unit "
    << num(metres_per(unit)) << "), in the target's frame\n";
  o << comment << " force ratio min/max = " << num(r.force_ratio) << " (min at point " << r.min_index
    << ", max at point " << r.max_index << ")\n";
  o << comment << " flagged points: " << r.flagged_count << " (the contact model does not apply there: left out of "
    << "min/max; column flag names why";
  for (int f = 1; f < collision::kContactFlagCount; ++f) {
    if (r.flag_counts[f] > 0) o << "; " << collision::flag_word(static_cast<collision::ContactFlag>(f)) << " " << r.flag_counts[f];
  }
  o << ")\n";
}

// What header() says, for the CSVs' JSON sidecar (common/csv_sidecar.hpp).
std::vector<std::pair<std::string, std::string>> sidecar_metadata(const SweepMeta& m, const SweepResult& r,
                                                                   LengthUnit unit) {
  std::vector<std::pair<std::string, std::string>> d = {
      {"title", "impactdeck sweep: maximal Hertz contact force over the surface"}};
  if (!m.source.empty()) d.push_back({"scene", m.source});
  if (!m.impact.empty()) d.push_back({"impact", m.impact + " (" + m.impactor + " hits " + m.target + " along the inward normal)"});
  if (!m.cloud.empty()) d.push_back({"cloud", m.cloud + ", " + std::to_string(r.points.size()) + " points"});
  if (!m.contact_law.empty()) d.push_back({"contact_law", m.contact_law});
  d.push_back({"frame", "coordinates in the target's frame, in " + std::string(to_string(unit)) + " (metres per unit " +
                            num(metres_per(unit)) + "); every other column SI"});
  d.push_back({"force_ratio", num(r.force_ratio) + " (min at point " + std::to_string(r.min_index) + ", max at point " +
                                  std::to_string(r.max_index) + ")"});
  std::string flags = std::to_string(r.flagged_count) + " (the contact model does not apply there: left out of "
                      "min/max; column flag names why";
  for (int f = 1; f < collision::kContactFlagCount; ++f) {
    if (r.flag_counts[f] > 0)
      flags += std::string("; ") + collision::flag_word(static_cast<collision::ContactFlag>(f)) + " " + std::to_string(r.flag_counts[f]);
  }
  d.push_back({"flagged_points", flags + ")"});
  return d;
}

double max_force(const SweepResult& r) { return r.points[r.max_index].max_force_N; }

// A body's local radius as written: a flat place (zero curvature, e.g. a face of a box) has an
// infinite radius, written as 0 (no real radius is 0), since the files hold no Inf.
double radius_out(double r) { return std::isinf(r) ? 0.0 : r; }

detail::RowWriteOptions row_options(const SweepWriteOptions& o) {
  detail::RowWriteOptions w;
  w.threads = o.threads;
  w.progress = o.progress;
  return w;
}

}  // namespace

void write_sweep_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options) {
  const auto& P = r.points;
  const double fmax = max_force(r);
  // Column by column (one more is one more line here).
  detail::CsvTable t;
  t.integer("index", [](std::size_t i) { return i; });
  const double per_m = 1.0 / metres_per(options.length_unit);
  const std::string u = to_string(options.length_unit);
  t.number("x_" + u, [&](std::size_t i) { return P[i].point_m.x() * per_m; });
  t.number("y_" + u, [&](std::size_t i) { return P[i].point_m.y() * per_m; });
  t.number("z_" + u, [&](std::size_t i) { return P[i].point_m.z() * per_m; });
  t.number("nx", [&](std::size_t i) { return P[i].normal.x(); });
  t.number("ny", [&](std::size_t i) { return P[i].normal.y(); });
  t.number("nz", [&](std::size_t i) { return P[i].normal.z(); });
  t.number("target_radius_m", [&](std::size_t i) { return radius_out(P[i].target_radius_m); });
  t.number("impactor_radius_m", [&](std::size_t i) { return radius_out(P[i].impactor_radius_m); });
  t.number("effective_radius_m", [&](std::size_t i) { return P[i].effective_radius_m; });
  t.number("reduced_mass_kg", [&](std::size_t i) { return P[i].reduced_mass_kg; });
  t.number("hertz_constant_N_per_m1_5", [&](std::size_t i) { return P[i].hertz_constant; });
  t.number("max_indentation_m", [&](std::size_t i) { return P[i].max_indentation_m; });
  t.number("max_force_N", [&](std::size_t i) { return P[i].max_force_N; });
  t.number("force_ratio", [&](std::size_t i) { return P[i].max_force_N / fmax; });
  t.number("compression_time_s", [&](std::size_t i) { return P[i].compression_time_s; });
  t.number("restitution", [&](std::size_t i) { return P[i].restitution; });
  t.number("contact_time_s", [&](std::size_t i) { return P[i].contact_time_s; });
  t.number("impulse_total_Ns", [&](std::size_t i) { return P[i].impulse_total_Ns; });
  t.number("residual_indentation_m", [&](std::size_t i) { return P[i].residual_indentation_m; });
  t.number("target_dvx_m_s", [&](std::size_t i) { return P[i].target_delta_velocity_m_s.x(); });
  t.number("target_dvy_m_s", [&](std::size_t i) { return P[i].target_delta_velocity_m_s.y(); });
  t.number("target_dvz_m_s", [&](std::size_t i) { return P[i].target_delta_velocity_m_s.z(); });
  t.number("target_dwx_rad_s", [&](std::size_t i) { return P[i].target_delta_angular_velocity_rad_s.x(); });
  t.number("target_dwy_rad_s", [&](std::size_t i) { return P[i].target_delta_angular_velocity_rad_s.y(); });
  t.number("target_dwz_rad_s", [&](std::size_t i) { return P[i].target_delta_angular_velocity_rad_s.z(); });
  t.number("contact_ellipse_axis_ratio", [&](std::size_t i) { return P[i].contact_ellipse_axis_ratio; });
  t.integer("sharp_feature", [&](std::size_t i) { return P[i].sharp_feature ? 1 : 0; });
  t.text("flag", [&](std::size_t i) { return std::string_view(collision::flag_word(P[i].flag)); });
  write_file_atomically(path, [&](std::ostream& o) {
    o << t.header();
    detail::write_rows(o, P.size(), t.rows(kWhat), row_options(options));
  });
  write_csv_sidecar(path, csv_columns(t.header()), sidecar_metadata(meta, r, options.length_unit));
}

void write_sweep_curves_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                            const SweepWriteOptions& options) {
  if (r.curves_N.empty() || r.curve_samples < 2) {
    throw InputError(path.string(), "curves", "the sweep was run without force curves");
  }
  write_file_atomically(path, [&](std::ostream& o) {
    o << "point,time_s,force_N\n";
    const double last = static_cast<double>(r.curve_samples - 1);
    // One unit of work per point: its curve_samples rows (none for a flagged point: the model does not apply there).
    detail::write_rows(o, r.points.size(), [&](std::size_t begin, std::size_t end, std::string& out) {
      for (std::size_t i = begin; i < end; ++i) {
        if (r.points[i].flagged()) continue;  // no curve where the model does not apply
        const double tc = r.points[i].contact_time_s;
        char index[24];
        const std::size_t index_size = static_cast<std::size_t>(std::to_chars(index, index + sizeof index, i).ptr - index);
        for (std::size_t k = 0; k < r.curve_samples; ++k) {
          out.append(index, index_size);
          out.push_back(',');
          detail::append_shortest(out, tc * static_cast<double>(k) / last, kWhat);
          out.push_back(',');
          detail::append_shortest(out, r.curves_N[i * r.curve_samples + k], kWhat);
          out.push_back('\n');
        }
      }
    }, row_options(options));
  });
  auto d = sidecar_metadata(meta, r, options.length_unit);
  d.push_back({"curves", "F(t) at each point: " + std::to_string(r.curve_samples) +
                             " samples uniform over [0, contact time]; none at a flagged point"});
  write_csv_sidecar(path, {"point", "time_s", "force_N"}, d);
}

void write_sweep_pos(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options) {
  const double fmax = max_force(r);
  const std::size_t n = r.points.size();
  // "SP(x,y,z){" of every point, formatted once (in parallel, by chunks of points) for the three or
  // four views; the text of point i is prefix[i / kChunk] from text_begin[i] to text_end[i].
  constexpr std::size_t kChunk = 8192;
  std::vector<std::string> prefix((n + kChunk - 1) / kChunk);
  std::vector<std::uint32_t> text_begin(n), text_end(n);
  const double per_m = 1.0 / metres_per(options.length_unit);
  detail::parallel_for(prefix.size(), options.threads, 1, [&](std::size_t c) {
    std::string& out = prefix[c];
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      text_begin[i] = static_cast<std::uint32_t>(out.size());
      const Eigen::Vector3d x = r.points[i].point_m * per_m;  // as the CSV, the .vtp and the decks
      out.append("SP(", 3);
      for (int k = 0; k < 3; ++k) {
        if (k > 0) out.push_back(',');
        detail::append_shortest(out, x[k], kWhat);
      }
      out.append("){", 2);
      text_end[i] = static_cast<std::uint32_t>(out.size());
    }
  }, nullptr);
  write_file_atomically(path, [&](std::ostream& o) {
    header(o, "//", meta, r, options.length_unit);
    o << "// open with: gmsh " << path.filename().string() << "\n";
    // SP(x,y,z){v}; for the points of one view (chunks of points formatted in parallel). Progress
    // runs over all views: view k of m reports k n + done of m n.
    const std::size_t views = 5 + (r.sharp_count > 0 ? 1 : 0) + (r.flagged_count > r.sharp_count ? 1 : 0);
    std::size_t views_done = 0;
    auto view = [&](const char* name, auto in_view, auto value) {
      detail::RowWriteOptions w = row_options(options);
      if (options.progress)
        w.progress = [&](std::size_t d, std::size_t) { options.progress(views_done * n + d, views * n); };
      o << "View \"" << name << "\" {\n";
      detail::write_rows(o, n, [&](std::size_t begin, std::size_t end, std::string& out) {
        for (std::size_t i = begin; i < end; ++i) {
          const PointResult& p = r.points[i];
          if (!in_view(p)) continue;
          out.append(prefix[i / kChunk], text_begin[i], text_end[i] - text_begin[i]);
          detail::append_shortest(out, value(p), kWhat);
          out.append("};\n", 3);
        }
      }, w);
      o << "};\n";
      ++views_done;
    };
    // The computed views hold the points not flagged; sharp points and the other flagged points get
    // views of their own (value: the flag's number, collision::ContactFlag).
    view("max_force_N", [](const PointResult& p) { return !p.flagged(); }, [](const PointResult& p) { return p.max_force_N; });
    view("force_ratio", [](const PointResult& p) { return !p.flagged(); }, [&](const PointResult& p) { return p.max_force_N / fmax; });
    view("restitution", [](const PointResult& p) { return !p.flagged(); }, [](const PointResult& p) { return p.restitution; });
    view("residual_indentation_m", [](const PointResult& p) { return !p.flagged(); },
         [](const PointResult& p) { return p.residual_indentation_m; });
    view("contact_ellipse_axis_ratio", [](const PointResult& p) { return !p.flagged(); },
         [](const PointResult& p) { return p.contact_ellipse_axis_ratio; });
    if (r.sharp_count > 0) {
      view("sharp_feature", [](const PointResult& p) { return p.sharp_feature; }, [](const PointResult&) { return 1.0; });
    }
    if (r.flagged_count > r.sharp_count) {
      view("flag", [](const PointResult& p) { return p.flagged() && !p.sharp_feature; },
           [](const PointResult& p) { return static_cast<double>(p.flag); });
    }
  });
}

namespace {

double finite(double v) {
  if (!std::isfinite(v)) throw Error(ExitCode::internal_error, std::string(kWhat) + ": non-finite value");
  return v + 0.0;
}

template <class Get>
detail::VtkArray scalar_array(const char* name, const std::vector<PointResult>& P, Get get) {
  return {"Float64", name, 1, [&P, get](std::size_t begin, std::size_t end, char* out) {
            for (std::size_t i = begin; i < end; ++i) {
              const double v = finite(get(P[i]));
              std::memcpy(out + 8 * (i - begin), &v, 8);
            }
          }};
}

// A small count (0/1, a flag's number) as one byte.
template <class Get>
detail::VtkArray byte_array(const char* name, const std::vector<PointResult>& P, Get get) {
  return {"UInt8", name, 1, [&P, get](std::size_t begin, std::size_t end, char* out) {
            for (std::size_t i = begin; i < end; ++i) out[i - begin] = static_cast<char>(get(P[i]));
          }};
}

template <class Get>
detail::VtkArray vector_array(const char* name, const std::vector<PointResult>& P, Get get) {
  return {"Float64", name, 3, [&P, get](std::size_t begin, std::size_t end, char* out) {
            for (std::size_t i = begin; i < end; ++i) {
              const Eigen::Vector3d x = get(P[i]);
              for (int k = 0; k < 3; ++k) {
                const double v = finite(x[k]);
                std::memcpy(out + 24 * (i - begin) + 8 * k, &v, 8);
              }
            }
          }};
}

// The .vtp and the .vtu: the same points, point data and header, as PolyData or UnstructuredGrid.
void write_sweep_vtk(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options, detail::VtkDataset dataset) {
  static_assert(collision::kContactFlagCount <= 256, "the flag array is one byte");
  const double fmax = max_force(r);
  const auto& P = r.points;
  const std::vector<detail::VtkArray> point_data = {
      scalar_array("max_force_N", P, [](const PointResult& p) { return p.max_force_N; }),
      scalar_array("force_ratio", P, [fmax](const PointResult& p) { return p.max_force_N / fmax; }),
      scalar_array("restitution", P, [](const PointResult& p) { return p.restitution; }),
      scalar_array("residual_indentation_m", P, [](const PointResult& p) { return p.residual_indentation_m; }),
      scalar_array("reduced_mass_kg", P, [](const PointResult& p) { return p.reduced_mass_kg; }),
      scalar_array("effective_radius_m", P, [](const PointResult& p) { return p.effective_radius_m; }),
      scalar_array("target_radius_m", P, [](const PointResult& p) { return radius_out(p.target_radius_m); }),
      scalar_array("contact_ellipse_axis_ratio", P, [](const PointResult& p) { return p.contact_ellipse_axis_ratio; }),
      byte_array("sharp_feature", P, [](const PointResult& p) { return p.sharp_feature ? 1 : 0; }),
      // collision::ContactFlag's number (0: valid)
      byte_array("flag", P, [](const PointResult& p) { return static_cast<int>(p.flag); }),
      vector_array("normal", P, [](const PointResult& p) -> const Eigen::Vector3d& { return p.normal; })};
  const double per_m = 1.0 / metres_per(options.length_unit);
  const detail::VtkArray points =
      vector_array("Points", P, [per_m](const PointResult& p) -> Eigen::Vector3d { return p.point_m * per_m; });
  std::ostringstream h;
  header(h, "", meta, r, options.length_unit);
  detail::VtkWriteOptions w;
  w.dataset = dataset;
  w.compress = options.vtk_compress;
  w.uint64_headers = options.vtp_uint64_headers;
  w.threads = options.threads;
  w.progress = options.progress;
  detail::write_vtk_points(path, P.size(), point_data, points, "max_force_N", "normal", h.str(),
                           num(metres_per(options.length_unit)), w);
}

}  // namespace

void write_sweep_vtp(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options) {
  write_sweep_vtk(path, r, meta, options, detail::VtkDataset::poly_data);
}

void write_sweep_vtu(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options) {
  write_sweep_vtk(path, r, meta, options, detail::VtkDataset::unstructured_grid);
}

SweepFormats parse_sweep_formats(const std::string& list) {
  static const char* const known = "csv, vtp, pos, svg, png, vtu or all";
  if (list.empty()) throw std::invalid_argument(std::string("the list is empty; name one or more of ") + known);
  SweepFormats f;
  f.csv = f.vtp = f.pos = f.svg = f.png = f.vtu = false;
  bool all = false;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = list.find(',', start);
    const std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    bool* flag = name == "csv" ? &f.csv : name == "vtp" ? &f.vtp : name == "pos" ? &f.pos
               : name == "svg" ? &f.svg : name == "png" ? &f.png : name == "vtu" ? &f.vtu
               : name == "all" ? &all : nullptr;
    if (name.empty()) throw std::invalid_argument(std::string("an empty name in the list; known: ") + known);
    if (!flag)
      throw std::invalid_argument("'" + name + "' is not one of " + known +
                                  did_you_mean(name, {"csv", "vtp", "pos", "svg", "png", "vtu", "all"}));
    if (*flag) throw std::invalid_argument("'" + name + "' is listed twice");
    *flag = true;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (all) f.csv = f.vtp = f.pos = f.svg = f.png = f.vtu = true;
  return f;
}

std::vector<std::filesystem::path> write_sweep_files(const std::filesystem::path& base, const SweepFormats& formats,
                                                     const SweepResult& r, const SweepMeta& meta,
                                                     const SweepPicture& picture, const SweepWriteOptions& options) {
  auto with = [&](const char* suffix) {
    std::filesystem::path p = base;
    p += suffix;
    return p;
  };
  if ((formats.svg || formats.png) && !picture.target) {
    throw Error(ExitCode::internal_error, "sweep picture without a target shape");
  }
  // One job per file, all at once on their own threads: each data file formats on the worker
  // threads of its write_rows, and while one waits for the disk (its final flush before the
  // rename) the others keep the cores busy; the picture (single-threaded: wireframe, circles,
  // cairo) is one more job. The files and their order in the returned list do not change.
  const std::size_t n = r.points.size();
  struct Job {
    std::filesystem::path file;  // the first file of the job (the picture's second is added below)
    std::size_t units = 0;       // progress units: rows (CSV n, .pos n per view, .vtp n per array)
    std::function<void(const SweepWriteOptions&)> write;
  };
  std::vector<Job> jobs;
  if (formats.csv) jobs.push_back({with(".csv"), n, [&](const SweepWriteOptions& o) { write_sweep_csv(with(".csv"), r, meta, o); }});
  if (formats.curves)
    jobs.push_back({with("_curves.csv"), n, [&](const SweepWriteOptions& o) { write_sweep_curves_csv(with("_curves.csv"), r, meta, o); }});
  if (formats.pos)
    jobs.push_back({with(".pos"), n * (3 + (r.sharp_count > 0 ? 1 : 0) + (r.flagged_count > r.sharp_count ? 1 : 0)), [&](const SweepWriteOptions& o) { write_sweep_pos(with(".pos"), r, meta, o); }});
  // .vtp: 11 point-data arrays, the points, 2 cell arrays; .vtu one more (the cell types).
  if (formats.vtp) jobs.push_back({with(".vtp"), 14 * n, [&](const SweepWriteOptions& o) { write_sweep_vtp(with(".vtp"), r, meta, o); }});
  if (formats.vtu) jobs.push_back({with(".vtu"), 15 * n, [&](const SweepWriteOptions& o) { write_sweep_vtu(with(".vtu"), r, meta, o); }});
  if (formats.svg || formats.png) {
    jobs.push_back({formats.svg ? with(".svg") : with(".png"), 0, [&](const SweepWriteOptions&) {
                      const plot::Drawing drawing = force_map_drawing(*picture.target, picture.centroid_m, r, picture.options);
                      if (formats.svg) plot::write_svg(with(".svg"), drawing);
                      if (formats.png) plot::write_png(with(".png"), drawing, picture.png_scale);
                    }});
  }

  // Progress: the sum over the jobs, reported under a lock (the jobs run on several threads).
  std::size_t total = 0;
  for (const Job& j : jobs) total += j.units;
  std::mutex progress_lock;
  std::vector<std::size_t> done(jobs.size(), 0);
  std::vector<std::exception_ptr> errors(jobs.size());
  auto run = [&](std::size_t k) {
    SweepWriteOptions o = options;
    if (options.progress) {
      o.progress = [&, k](std::size_t d, std::size_t t) {
        std::lock_guard<std::mutex> lock(progress_lock);
        done[k] = t > 0 ? d * jobs[k].units / t : 0;
        std::size_t sum = 0;
        for (std::size_t x : done) sum += x;
        options.progress(sum, total);
      };
    }
    try {
      jobs[k].write(o);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  };
  {
    std::vector<std::thread> pool;
    struct Joiner {
      std::vector<std::thread>& pool;
      ~Joiner() {
        for (auto& t : pool)
          if (t.joinable()) t.join();
      }
    } joiner{pool};
    for (std::size_t k = 1; k < jobs.size(); ++k) pool.emplace_back(run, k);
    if (!jobs.empty()) run(0);
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);  // the first file's error
  std::vector<std::filesystem::path> files;
  for (const Job& j : jobs) files.push_back(j.file);
  if (formats.svg && formats.png) files.push_back(with(".png"));
  if (options.progress) options.progress(total, total);
  return files;
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

namespace {

// The view: d from the body towards the viewer, u screen right, w screen up; a point's screen
// position once fitted into the plot area.
struct MapView {
  Eigen::Vector3d c, d, u, w;
  double scale = 1, cx = 0, cy = 0;
  plot::Point2 screen(const Eigen::Vector3d& p) const {
    return plot::Point2{cx + scale * (p - c).dot(u), cy - scale * (p - c).dot(w)};
  }
};

struct WirePoint {
  Eigen::Vector3d p;
  bool front;
};
using Wire = std::vector<WirePoint>;

// The body's wireframe: meridians and parallels of the cloud's box of half-extents `ext` about c,
// each direction cast to the surface (ray_exit), marked as facing the viewer or not.
std::vector<Wire> body_wires(const geometry::Shape& target, const Eigen::Vector3d& c, const Eigen::Vector3d& ext,
                             const Eigen::Vector3d& d, const ForceMapOptions& o) {
  std::vector<Wire> wires;
  auto trace = [&](auto param, int samples) {
    Wire line;
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
  return wires;
}

// The wires' runs on one side (front or back) as polylines.
void draw_wires(plot::Drawing& dr, const std::vector<Wire>& wires, const MapView& v, bool front) {
  plot::Style style;
  style.stroke = front ? plot::Colour{0.45, 0.45, 0.45} : plot::Colour{0.80, 0.80, 0.80};
  style.stroke_width = front ? 0.9 : 0.7;
  for (const auto& line : wires) {
    std::vector<plot::Point2> run;
    for (std::size_t k = 0; k < line.size(); ++k) {
      if (line[k].front == front) {
        run.push_back(v.screen(line[k].p));
      } else {
        if (run.size() >= 2) dr.polyline(run, style);
        run.clear();
      }
    }
    if (run.size() >= 2) dr.polyline(run, style);
  }
}

// The points of one side in `order`: a circle of radius rmax F / fmax coloured by F, or a grey
// cross where the point has no force.
void draw_points(plot::Drawing& dr, const SweepResult& r, const std::vector<std::size_t>& order, const MapView& v,
                 double rmax, bool front) {
  const double fmin = r.points[r.min_index].max_force_N, fmax = r.points[r.max_index].max_force_N;
  auto shade = [&](double f) { return fmax > fmin ? (f - fmin) / (fmax - fmin) : 1.0; };
  for (std::size_t i : order) {
    const PointResult& p = r.points[i];
    if ((p.normal.dot(v.d) >= 0.0) != front) continue;
    if (p.flagged()) {
      // No force there (sharp, no-fit, ...): a small grey cross instead of a circle.
      plot::Style x;
      x.stroke = {0.45, 0.45, 0.45};
      x.stroke_width = 1.0;
      x.stroke_opacity = front ? 1.0 : 0.4;
      const plot::Point2 c0 = v.screen(p.point_m);
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
    dr.circle(v.screen(p.point_m), rmax * p.max_force_N / fmax, s);
  }
}

// The legend line: what the circles mean, and the flagged points by kind.
std::string force_map_legend(const SweepResult& r) {
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
  return legend;
}

// The viridis colour bar of F_max at x = bx between by0 (top) and by1, ticked in the unit fu.
void draw_colour_bar(plot::Drawing& dr, double bx, double by0, double by1, double fmin, double fmax, const Scaled& fu) {
  const double bwid = 20;
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
}

}  // namespace

plot::Drawing force_map_drawing(const geometry::Shape& target, const Eigen::Vector3d& c,
                                const SweepResult& r, const ForceMapOptions& o) {
  if (r.points.empty()) throw InputError("", "force map", "no points to draw");
  const double az = o.azimuth_deg * M_PI / 180.0, el = o.elevation_deg * M_PI / 180.0;
  MapView v;
  v.c = c;
  v.d = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (std::abs(v.d.dot(up)) > 0.99) up = Eigen::Vector3d::UnitY();
  v.u = up.cross(v.d).normalized();
  v.w = v.d.cross(v.u);

  // Half-extents of the cloud about the centroid: directions for the wireframe.
  Eigen::Vector3d ext = Eigen::Vector3d::Zero();
  for (const auto& p : r.points) ext = ext.cwiseMax((p.point_m - c).cwiseAbs());
  const double big = std::max(ext.maxCoeff(), 1e-300);
  ext = ext.cwiseMax(Eigen::Vector3d::Constant(1e-9 * big));
  const std::vector<Wire> wires = body_wires(target, c, ext, v.d, o);

  // Fit the projection into the plot area.
  const double left = 30, top = 78, right = o.width_px - 150, bottom = o.height_px - 30;
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  auto grow = [&](const Eigen::Vector3d& p) {
    const double x = (p - c).dot(v.u), y = (p - c).dot(v.w);
    xmin = std::min(xmin, x); xmax = std::max(xmax, x);
    ymin = std::min(ymin, y); ymax = std::max(ymax, y);
  };
  for (const auto& line : wires)
    for (const auto& wp : line) grow(wp.p);
  for (const auto& p : r.points) grow(p.point_m);
  const double pad = 24;
  const double bw = std::max(xmax - xmin, 1e-12 * big), bh = std::max(ymax - ymin, 1e-12 * big);
  v.scale = std::min((right - left - 2 * pad) / bw, (bottom - top - 2 * pad) / bh);
  v.cx = 0.5 * (left + right) - v.scale * 0.5 * (xmin + xmax);
  v.cy = 0.5 * (top + bottom) + v.scale * 0.5 * (ymin + ymax);

  // Circle size: radius proportional to F_max, the largest about half the spacing of the points
  // seen from the front.
  const double fmin = r.points[r.min_index].max_force_N, fmax = r.points[r.max_index].max_force_N;
  const double shown = o.max_points > 0 ? std::min<double>(r.points.size(), o.max_points) : r.points.size();
  const double front_count = std::max(1.0, 0.5 * shown);
  const double area = M_PI / 4.0 * std::max(v.scale * bw, 1.0) * std::max(v.scale * bh, 8.0);
  const double rmax = std::clamp(0.4 * std::sqrt(area / front_count), 2.0, 20.0);

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
    const double da = r.points[a].point_m.dot(v.d), db = r.points[b].point_m.dot(v.d);
    return da < db || (da == db && a < b);
  });
  plot::Drawing dr(o.width_px, o.height_px);
  draw_wires(dr, wires, v, false);
  draw_points(dr, r, order, v, rmax, false);
  draw_wires(dr, wires, v, true);
  draw_points(dr, r, order, v, rmax, true);

  // Extremes.
  auto mark = [&](std::size_t i, const char* label, double dy) {
    const PointResult& p = r.points[i];
    const plot::Point2 s = v.screen(p.point_m);
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
  dr.text({left, 66}, force_map_legend(r), 11, plot::Anchor::start, {0.35, 0.35, 0.35});
  draw_colour_bar(dr, o.width_px - 112, top + 20, bottom - 20, fmin, fmax, fu);
  return dr;
}

}  // namespace impactdeck::study
