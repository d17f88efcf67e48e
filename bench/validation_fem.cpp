// The FEM route against analytic references, as Markdown for docs/validation.md, with figures
// (SVG and PNG) written to FIGURE_DIR. Usage: validation_fem SOURCE_DIR FIGURE_DIR [study ...]
// with study one of: wave, convergence, contact (default: all). Each runs whole scenes through
// the pipeline (Gmsh, decks, ccx, stresses); expect minutes.
//   wave         the 1-D wave in a long bar hit on its end: sigma(x, t) = F(t - x/c) / A
//   convergence  a probe's peak von Mises over three mesh sizes (Richardson extrapolation)
//   contact      point against Hertz-patch load near the contact, under refinement, against the
//                quasi-static Hertz field on the axis (Johnson, Contact Mechanics, Sect. 3.4 and
//                4.2: von Mises peaks at 0.62 p0 at depth 0.48 a for nu = 0.3)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/plot/stress_plot.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

constexpr double kE = 2.05e11, kNu = 0.3, kRho = 7850;

// A box [x0, x0 + Lx] x [-Ly/2, Ly/2] x [-Lz/2, Lz/2] mm as an ASCII STL of 12 outward triangles.
void write_box_stl(const fs::path& p, double x0, double Lx, double Ly, double Lz) {
  const double a = x0, b = x0 + Lx, hy = Ly / 2, hz = Lz / 2;
  const double q[6][4][3] = {{{a, -hy, -hz}, {a, -hy, hz}, {a, hy, hz}, {a, hy, -hz}},
                             {{b, -hy, -hz}, {b, hy, -hz}, {b, hy, hz}, {b, -hy, hz}},
                             {{a, -hy, -hz}, {b, -hy, -hz}, {b, -hy, hz}, {a, -hy, hz}},
                             {{a, hy, -hz}, {a, hy, hz}, {b, hy, hz}, {b, hy, -hz}},
                             {{a, -hy, -hz}, {a, hy, -hz}, {b, hy, -hz}, {b, -hy, -hz}},
                             {{a, -hy, hz}, {b, -hy, hz}, {b, hy, hz}, {a, hy, hz}}};
  const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
  std::ofstream s(p);
  s.precision(17);
  s << "solid box\n";
  for (const auto& f : q)
    for (const auto& t : tri) {
      s << "facet normal 0 0 0\nouter loop\n";
      for (int k = 0; k < 3; ++k) s << "vertex " << f[t[k]][0] << " " << f[t[k]][1] << " " << f[t[k]][2] << "\n";
      s << "endloop\nendfacet\n";
    }
  s << "endsolid box\n";
}

std::string materials() {
  std::ostringstream s;
  s << "[materials.steel]\nyoungs_modulus_Pa = " << kE << "\npoisson_ratio = " << kNu << "\ndensity_kg_m3 = " << kRho
    << "\n";
  return s.str();
}

scene::RunReport run_text(const std::string& text, const fs::path& dir, const fs::path& base) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const scene::Scene sc = scene::parse_scene(text, (dir / "scene.toml").string(), base);
  std::ofstream(dir / "scene.toml") << text;
  scene::RunOptions o;
  o.out_dir = dir;
  return scene::run_scene(sc, o);
}

void figure(const plot::Drawing& d, const fs::path& dir, const std::string& stem) {
  plot::write_svg(dir / (stem + ".svg"), d);
  plot::write_png(dir / (stem + ".png"), d, 1.5);
}

// The bar scene of the wave studies: `bar.stl` in `work`, ball r = 10 mm at 1 m/s, R = 1.
std::string bar_scene(double h_mm, double end_time_s, const std::string& probes) {
  std::ostringstream s;
  s << "length_unit = \"mm\"\n" << materials()
    << "[[bodies]]\nname = \"bar\"\nshape = \"mesh\"\nmesh = \"bar.stl\"\nmaterial = \"steel\"\n"
    << "[[bodies]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 10\nmaterial = \"steel\"\n"
    << "[[impacts]]\nname = \"wave\"\ntarget = \"bar\"\nimpactor = \"ball\"\npoint = [-1, 0, 0]\n"
    << "approach_speed_m_s = 1\nrestitution = 1\ncontact_radius = \"mean\"\nmax_projection_distance = 2\n"
    << "[outputs.fem]\nmesh_size = " << h_mm << "\nend_time_s = " << end_time_s << "\ntime_step_s = 1e-6\n"
    << "probes = " << probes << "\nrun = \"calculix\"\ncode_aster = false\n";
  return s.str();
}

// ---- 1. The 1-D wave ----------------------------------------------------------------------------
void wave(const fs::path& work, const fs::path& figs) {
  const double L = 1000, w = 20;  // mm, docs/validation.md's bar
  const fs::path dir = work / "wave";
  fs::create_directories(work);
  write_box_stl(work / "bar.stl", 0, L, w, w);
  std::printf("## 1. The 1-D wave in a long bar\n\n");
  std::printf("A free steel bar %g x %g x %g mm (E = %g Pa, rho = %g kg/m3), hit at the centre of its end face "
              "by a steel ball r = 10 mm at 1 m/s (R = 1), point load, probes on the axis at x = 250, 500 and "
              "750 mm. Away from the end, sigma(x, t) = F(t - x/c) / A with c = sqrt(E/rho) (1-D wave theory). End time "
              "200 us (the reflection from the far end reaches x = 750 mm at 245 us), step 1 us after the contact.\n\n",
              L, w, w, kE, kRho);
  std::printf("| mesh size (mm) | nodes | probe x (mm) | FE peak (MPa) | F_max/A (MPa) | error | FE time of peak (us) "
              "| t_m + x/c (us) | error | ccx (s) |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (double h : {10.0}) {
    const scene::RunReport rep = run_text(bar_scene(h, 2e-4, "[[250, 0, 0], [500, 0, 0], [750, 0, 0]]"), dir, work);
    const auto& ir = rep.impacts.at(0);
    const auto& st = *ir.fem_check->stress;
    const auto& c = ir.result.history.compression;
    const double A = w * w * 1e-6, cw = std::sqrt(kE / kRho);
    std::vector<plot::StressSeries> series;
    for (std::size_t i = 0; i < st.probes.size(); ++i) {
      const auto& p = st.probes[i];
      const double x = p.point_m.x();
      const double ref = c.max_force_N / A, tref = c.compression_time_s + x / cw;
      std::printf("| %g | %zu | %.0f | %.4f | %.4f | %+.2f %% | %.2f | %.2f | %+.2f %% | %.0f |\n", h, ir.fem_deck->node_count,
                  x * 1e3, p.max_von_mises_Pa * 1e-6, ref * 1e-6, 100 * (p.max_von_mises_Pa / ref - 1),
                  p.max_von_mises_time_s * 1e6, tref * 1e6, 100 * (p.max_von_mises_time_s / tref - 1),
                  ir.fem_check->solver_wall_time_s);
      if (h != 10.0) continue;
      char label[64];
      std::snprintf(label, sizeof label, "FE, x = %.0f mm", x * 1e3);
      series.push_back({label, st.time_s, p.von_mises_Pa, static_cast<int>(i), false});
      plot::StressSeries an{"", {}, {}, static_cast<int>(i), true};
      std::snprintf(label, sizeof label, "F(t - x/c)/A, x = %.0f mm", x * 1e3);
      an.label = label;
      for (int k = 0; k <= 400; ++k) {
        const double t = 2e-4 * k / 400;
        an.time_s.push_back(t);
        an.von_mises_Pa.push_back(ir.result.history.force_N(t - x / cw) / A);
      }
      series.push_back(an);
    }
    if (h == 10.0) {
      plot::StressPlotOptions po;
      po.title = "1-D wave: von Mises on the bar's axis against F(t - x/c)/A (10 mm mesh)";
      figure(plot::stress_time_drawing(series, po), figs, "fem_wave_bar");
    }
  }
  std::printf("\n![1-D wave](figures/fem_wave_bar.svg)\n\n");
}

// ---- 2. Convergence of a probe's peak ------------------------------------------------------------
void convergence(const fs::path& src, const fs::path& work) {
  std::printf("## 2. Convergence of a probe's peak von Mises\n\n");
  std::printf("### The bar, against the analytic wave\n\nA 400 x 20 x 20 mm bar, as in section 1 (point load), "
              "probe at mid-length x = 200 mm; mesh size h = 20, 14.1, 10 mm. Reference F_max/A.\n\n"
              "| mesh size (mm) | nodes | peak (MPa) | error vs F_max/A | time (us) | error vs t_m + x/c | ccx (s) |\n"
              "|---|---|---|---|---|---|---|\n");
  write_box_stl(work / "bar.stl", 0, 400, 20, 20);
  for (double h : {20.0, 20.0 / std::sqrt(2.0), 10.0}) {
    const scene::RunReport rep = run_text(bar_scene(h, 1e-4, "[[200, 0, 0]]"), work / "bar_convergence", work);
    const auto& ir = rep.impacts.at(0);
    const auto& p = ir.fem_check->stress->probes.at(0);
    const auto& c = ir.result.history.compression;
    const double ref = c.max_force_N / 4e-4, tref = c.compression_time_s + 0.2 / std::sqrt(kE / kRho);
    std::printf("| %.1f | %zu | %.4f | %+.2f %% | %.2f | %+.2f %% | %.0f |\n", h, ir.fem_deck->node_count,
                p.max_von_mises_Pa * 1e-6, 100 * (p.max_von_mises_Pa / ref - 1), p.max_von_mises_time_s * 1e6,
                100 * (p.max_von_mises_time_s / tref - 1), ir.fem_check->solver_wall_time_s);
    std::fflush(stdout);
  }
  std::printf("\n### Near and far from a point load on the ellipsoid\n\n");
  std::printf("`samples/eccentric_fem.toml` (the ellipsoid 2000/500/500 mm hit off-centre at 10 m/s, 2 ms; point "
              "load): PROBE1 at (1000, 300, 0) mm, 133 mm under the contact point, and PROBE2 at (-1000, 300, 0) mm, "
              "2 m away; mesh size h (load size h/2.7) refined by sqrt(2) twice; Richardson extrapolation from the "
              "three values of each probe.\n\n");
  std::printf("| mesh size (mm) | nodes | PROBE1 peak (MPa) | at (us) | PROBE2 peak (MPa) | at (us) | FE volume vs part "
              "| ccx (s) |\n|---|---|---|---|---|---|---|---|\n");
  std::vector<std::vector<double>> peaks(2);
  for (double h : {400.0, 400.0 / std::sqrt(2.0), 200.0}) {
    std::ifstream in(src / "samples" / "eccentric_fem.toml");
    std::ostringstream text;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("mesh_size", 0) == 0) line = "mesh_size = " + std::to_string(h);
      if (line.rfind("load_mesh_size", 0) == 0) line = "load_mesh_size = " + std::to_string(h / 2.7);
      text << line << "\n";
    }
    const scene::RunReport rep = run_text(text.str(), work / "convergence", src / "samples");
    const auto& ir = rep.impacts.at(0);
    const auto& pr = ir.fem_check->stress->probes;
    std::printf("| %.0f | %zu |", h, ir.fem_deck->node_count);
    for (int k = 0; k < 2; ++k) {
      peaks[k].push_back(pr.at(k).max_von_mises_Pa);
      std::printf(" %.4f | %.1f |", pr.at(k).max_von_mises_Pa * 1e-6, pr.at(k).max_von_mises_time_s * 1e6);
    }
    std::printf(" %+.2f %% | %.0f |\n", 100 * ir.fem_deck->quality.volume_relative_difference,
                ir.fem_check->solver_wall_time_s);
    std::fflush(stdout);
  }
  std::printf("\n");
  const double r = std::sqrt(2.0);
  for (int k = 0; k < 2; ++k) {
    const auto& p = peaks[k];
    const double d1 = p[1] - p[0], d2 = p[2] - p[1];
    if (d1 != 0 && d2 / d1 > 0 && std::abs(d2) < std::abs(d1)) {
      const double order = std::log(d1 / d2) / std::log(r);
      const double limit = p[2] + d2 / (std::pow(r, order) - 1);
      std::printf("PROBE%d: observed order %.2f, extrapolated peak %.4f MPa, the finest mesh %.1f %% from it.\n", k + 1,
                  order, limit * 1e-6, 100 * (p[2] / limit - 1));
    } else {
      std::printf("PROBE%d: the differences %+.3g and %+.3g MPa do not shrink monotonically: no Richardson "
                  "estimate.\n", k + 1, d1 * 1e-6, d2 * 1e-6);
    }
  }
  std::printf("\n");
}

// ---- 3. Point against patch load near the contact --------------------------------------------------

// Von Mises on the axis of a Hertz circular contact at depth z, over p0 (Johnson, Contact
// Mechanics, Sect. 3.4, eqs. for sigma_r and sigma_z on the axis).
double hertz_axis_von_mises(double zeta, double nu) {
  const double sz = -1.0 / (1.0 + zeta * zeta);
  const double sr = -(1.0 + nu) * (1.0 - zeta * std::atan(1.0 / zeta)) + 0.5 / (1.0 + zeta * zeta);
  return std::abs(sz - sr);
}

void contact_study(const fs::path& work, const fs::path& figs) {
  std::printf("## 3. Point against Hertz-patch load near the contact\n\n");
  // The quasi-static Hertz maximum on the axis.
  double zmax = 0, vmax = 0;
  for (int i = 1; i < 200000; ++i) {
    const double z = i * 1e-5;
    const double v = hertz_axis_von_mises(z, kNu);
    if (v > vmax) vmax = v, zmax = z;
  }
  std::printf("A free steel cube 100 mm hit at the centre of its top face by a blunt body (a sphere r = 500 mm of "
              "mass 20 kg, 1 m/s, R = 0.2): circular contact, a_max and p0 from the Hertz solution (below), contact "
              "time 10 times the cube's wave transit, so the field near the contact is close to the quasi-static "
              "Hertz field. Reference on the axis (Johnson, *Contact Mechanics*, 1985, Sect. 3.4: sigma_z = "
              "-p0/(1 + z^2/a^2), sigma_r = p0[-(1 + nu)(1 - (z/a) atan(a/z)) + 1/(2(1 + z^2/a^2))]): von Mises "
              "peaks at %.3f p0 at z = %.3f a for nu = %.1f (Johnson: 'about 0.62 p0 at 0.48 a'). Probes on the "
              "axis at z = 0.25 a, 0.48 a, a, 2 a. The load element size is 2 a / n (n = contact_elements for the "
              "patch; the same size at the load node for the point load).\n\n",
              vmax, zmax, kNu);
  const fs::path stl = work / "cube.stl";
  fs::create_directories(work);
  write_box_stl(stl, -50, 100, 100, 100);
  auto text = [&](const std::string& load, int n, double a_mm, double h0_mm, const char* run = "calculix") {
    std::ostringstream s;
    s << "length_unit = \"mm\"\n" << materials()
      << "[[bodies]]\nname = \"cube\"\nshape = \"mesh\"\nmesh = \"cube.stl\"\nmaterial = \"steel\"\n"
      << "[[bodies]]\nname = \"punch\"\nshape = \"sphere\"\nradius = 500\nmass_kg = 20\nmaterial = \"steel\"\n"
      << "[[impacts]]\nname = \"contact\"\ntarget = \"cube\"\nimpactor = \"punch\"\npoint = [0, 0, 51]\n"
      << "approach_speed_m_s = 1\nrestitution = 0.2\ncontact_radius = \"mean\"\nmax_projection_distance = 2\n"
      << "[outputs.fem]\nmesh_size = 25\nend_time_s = 1.6e-4\ntime_step_s = 2e-6\nrun = \"" << run << "\"\n"
      << "code_aster = false\n"
      << "load = \"" << load << "\"\n";
    if (load == "hertz-patch") s << "contact_elements = " << n << "\n";
    else s << "load_mesh_size = " << h0_mm << "\n";
    if (a_mm > 0) {
      s << "probes = [";
      for (double zeta : {0.25, zmax, 1.0, 2.0}) s << (zeta == 0.25 ? "" : ", ") << "[0, 0, " << 50 - zeta * a_mm << "]";
      s << "]\n";
    }
    return s.str();
  };
  // A first run (decks only, no probes) gives the contact.
  const scene::RunReport first = run_text(text("hertz-patch", 2, 0, 0, "none"), work / "contact_probe_a", work);
  const auto& ir0 = first.impacts.at(0);
  const double F = ir0.result.history.compression.max_force_N;
  const double a = std::cbrt(3.0 * F * ir0.result.effective_radius_m / (4.0 * ir0.result.effective_modulus_Pa));
  const double p0 = 3.0 * F / (2.0 * M_PI * a * a);
  std::printf("F_max = %.0f N, a_max = %.3f mm, p0 = %.0f MPa, t_m = %.1f us, contact %.1f us.\n\n", F, a * 1e3, p0 * 1e-6,
              ir0.result.history.compression.compression_time_s * 1e6, ir0.result.history.contact_time_s() * 1e6);
  std::printf("| load | n | load element (mm) | nodes | loaded nodes | probe 0.25 a | probe %.2f a | probe a | probe 2 a | "
              "peak in the zone | ccx (s) |\n|---|---|---|---|---|---|---|---|---|---|---|\n", zmax);
  std::printf("| Hertz (quasi-static) | | | | | %.3f | %.3f | %.3f | %.3f | %.3f | |\n", hertz_axis_von_mises(0.25, kNu),
              vmax, hertz_axis_von_mises(1.0, kNu), hertz_axis_von_mises(2.0, kNu), vmax);
  std::vector<plot::StressSeries> series;
  for (const char* load : {"hertz-patch", "point"}) {
    for (int n : {4, 8, 12}) {
      const double h0 = 2.0 * a / n * 1e3;
      const scene::RunReport rep = run_text(text(load, n, a * 1e3, h0), work / "contact", work);
      const auto& ir = rep.impacts.at(0);
      const auto& st = *ir.fem_check->stress;
      std::printf("| %s | %d | %.2f | %zu | %zu |", load, n, ir.fem_deck->quality.load_mesh_size_m * 1e3,
                  ir.fem_deck->node_count, ir.fem_deck->patch.load_node_count);
      for (const auto& p : st.probes) std::printf(" %.3f |", p.max_von_mises_Pa / p0);
      std::printf(" %.3f | %.0f |\n", st.inside_zone.von_mises_Pa / p0, ir.fem_check->solver_wall_time_s);
      if (n == 12 || n == 4) {
        std::vector<double> rel(st.probes[1].von_mises_Pa.size());
        for (std::size_t k = 0; k < rel.size(); ++k) rel[k] = st.probes[1].von_mises_Pa[k];
        series.push_back({std::string(load) + ", n = " + std::to_string(n), st.time_s, rel,
                          std::string(load) == "point" ? (n == 4 ? 2 : 5) : (n == 4 ? 4 : 0), false});
      }
      std::fflush(stdout);
    }
  }
  // The quasi-static Hertz reference at the probe's depth: a(t) = a_max s, p0(t) = p0 s with
  // s = (F(t)/F_max)^(1/3).
  plot::StressSeries ref{"Hertz, quasi-static", {}, {}, 1, true};
  for (int k = 0; k <= 400; ++k) {
    const double t = 1.6e-4 * k / 400;
    const double s = std::cbrt(std::max(0.0, ir0.result.history.force_N(t)) / F);
    ref.time_s.push_back(t);
    ref.von_mises_Pa.push_back(s > 1e-9 ? p0 * s * hertz_axis_von_mises(zmax / s, kNu) : 0.0);
  }
  series.push_back(ref);
  plot::StressPlotOptions po;
  po.title = "Von Mises on the axis at depth 0.48 a_max: point vs Hertz-patch load";
  figure(plot::stress_time_drawing(series, po), figs, "fem_point_vs_patch");
  std::printf("\n![Point vs patch](figures/fem_point_vs_patch.svg)\n\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: validation_fem SOURCE_DIR FIGURE_DIR [wave|convergence|contact ...]\n");
    return 2;
  }
  const fs::path src = argv[1], figs = argv[2];
  std::set<std::string> studies;
  for (int i = 3; i < argc; ++i) studies.insert(argv[i]);
  auto want = [&](const char* s) { return studies.empty() || studies.count(s); };
  const fs::path work = fs::temp_directory_path() / "impactdeck_validation_fem";
  fs::create_directories(figs);
  try {
    if (want("wave")) wave(work, figs);
    if (want("convergence")) convergence(src, work);
    if (want("contact")) contact_study(work, figs);
  } catch (const Error& e) {
    std::fprintf(stderr, "validation_fem: %s\n", e.what());
    return 1;
  }
  return 0;
}
