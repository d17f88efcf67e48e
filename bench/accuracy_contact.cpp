// How far the paper's averaged radius (Eq. 26) and the mean-curvature radius are from the full
// elliptical Hertz contact over an ellipsoid's surface (issue #7): a table and an SVG map of the
// F_max difference. F_max ~ k_H^(2/5) ~ R^(1/5) at fixed reduced mass and velocity, so the map
// isolates the contact-radius rule. Usage: accuracy_contact [map.svg]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"

using namespace impactdeck;

namespace {

struct Sample {
  double lon, lat;      // parametric angles on the ellipsoid, radians
  double paper, mean;   // F_max(rule) / F_max(elliptical) - 1
};

std::vector<Sample> map_for(const geometry::Ellipsoid& e, double ball_r, int nlon, int nlat) {
  std::vector<Sample> out;
  const Eigen::Vector3d ax = e.semi_axes_m();
  for (int j = 0; j < nlat; ++j) {
    const double lat = -M_PI_2 + M_PI * (j + 0.5) / nlat;
    for (int i = 0; i < nlon; ++i) {
      const double lon = -M_PI + 2 * M_PI * (i + 0.5) / nlon;
      const Eigen::Vector3d p(ax.x() * std::cos(lat) * std::cos(lon), ax.y() * std::cos(lat) * std::sin(lon),
                              ax.z() * std::sin(lat));
      const geometry::SurfacePoint sp = e.closest_point(p);
      const geometry::Curvature k = e.curvature(sp);
      const double kb = 1.0 / ball_r;
      const collision::RelativeCurvatures rc = collision::relative_curvatures(
          k.k1_per_m, k.k2_per_m, k.d1, k.d2, kb, kb, k.d1, k.d2, sp.normal);
      const double r_ell = collision::elliptical_contact(rc).equivalent_radius_m;
      const double r_paper = 1.0 / (1.0 / e.paper_radius_m(sp) + kb);
      const double r_mean = 1.0 / (k.mean_per_m() + kb);
      out.push_back({lon, lat, std::pow(r_paper / r_ell, 0.2) - 1.0, std::pow(r_mean / r_ell, 0.2) - 1.0});
    }
  }
  return out;
}

// Diverging colour for a value in [-vmax, vmax]: blue - white - red.
std::string colour(double v, double vmax) {
  const double t = std::clamp(v / vmax, -1.0, 1.0);
  int r = 255, g = 255, b = 255;
  if (t > 0) { g = b = static_cast<int>(255 * (1 - t)); } else { r = g = static_cast<int>(255 * (1 + t)); }
  char s[16];
  std::snprintf(s, sizeof s, "#%02x%02x%02x", r, g, b);
  return s;
}

void write_svg(const std::string& path, const std::vector<Sample>& m, int nlon, int nlat, double vmax,
               const std::string& title) {
  const int cw = 8, ch = 8, left = 60, top = 44;
  const int W = left + nlon * cw + 120, H = top + nlat * ch + 60;
  std::ofstream o(path);
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H << "' font-family='sans-serif' font-size='12'>\n";
  o << "<rect width='100%' height='100%' fill='white'/>\n";
  o << "<text x='" << left << "' y='16' font-size='13'>" << title << "</text>\n";
  o << "<text x='" << left << "' y='32' font-size='11'>blue: Eq. 26 gives a lower F_max than the elliptical "
       "contact; red: higher</text>\n";
  for (int j = 0; j < nlat; ++j)
    for (int i = 0; i < nlon; ++i) {
      const Sample& s = m[j * nlon + i];
      o << "<rect x='" << left + i * cw << "' y='" << top + (nlat - 1 - j) * ch << "' width='" << cw
        << "' height='" << ch << "' fill='" << colour(s.paper, vmax) << "'/>\n";
    }
  o << "<text x='" << left << "' y='" << top + nlat * ch + 18 << "'>longitude -180° … 180° (x axis = long axis at 0°)</text>\n";
  o << "<text x='10' y='" << top + nlat * ch / 2 << "' transform='rotate(-90 10 " << top + nlat * ch / 2 << ")'>latitude -90° … 90°</text>\n";
  // Colour bar.
  const int bx = left + nlon * cw + 20;
  for (int k = 0; k < 100; ++k) {
    const double v = vmax * (1 - 2.0 * k / 99);
    o << "<rect x='" << bx << "' y='" << top + k * nlat * ch / 100 << "' width='20' height='" << nlat * ch / 100 + 1
      << "' fill='" << colour(v, vmax) << "'/>\n";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "+%.1f %%", 100 * vmax);
  o << "<text x='" << bx + 25 << "' y='" << top + 10 << "'>" << buf << "</text>\n";
  o << "<text x='" << bx + 25 << "' y='" << top + nlat * ch / 2 << "'>0</text>\n";
  std::snprintf(buf, sizeof buf, "−%.1f %%", 100 * vmax);
  o << "<text x='" << bx + 25 << "' y='" << top + nlat * ch << "'>" << buf << "</text>\n";
  o << "</svg>\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::printf("## Contact radius rules against the elliptical Hertz contact\n\n");
  std::printf("A steel ball (r = 50 mm) on ellipsoids b = c = 500 mm, a = g b, hit along the normal. "
              "Difference in F_max of the paper's Eq. 26 radius and of the mean-curvature radius "
              "against the full elliptical Hertz contact (F_max ~ R^(1/5) at fixed reduced mass). "
              "Grid of 72 x 36 parametric points.\n\n");
  std::printf("| g = a/b | Eq. 26: min | Eq. 26: max | mean curvature: min | mean curvature: max |\n|---|---|---|---|---|\n");
  const int nlon = 72, nlat = 36;
  std::vector<Sample> paper_map;
  for (double g : {0.25, 1.0, 2.0, 4.0, 10.0}) {
    const geometry::Ellipsoid e(0.5 * g, 0.5, 0.5);
    const std::vector<Sample> m = map_for(e, 0.05, nlon, nlat);
    double pmin = 1e9, pmax = -1e9, mmin = 1e9, mmax = -1e9;
    for (const Sample& s : m) {
      pmin = std::min(pmin, s.paper); pmax = std::max(pmax, s.paper);
      mmin = std::min(mmin, s.mean); mmax = std::max(mmax, s.mean);
    }
    std::printf("| %g | %+.3f %% | %+.3f %% | %+.4f %% | %+.4f %% |\n", g, 100 * pmin, 100 * pmax, 100 * mmin, 100 * mmax);
    if (g == 4.0) paper_map = m;
  }
  if (argc > 1) {
    double vmax = 0;
    for (const Sample& s : paper_map) vmax = std::max(vmax, std::abs(s.paper));
    write_svg(argv[1], paper_map, nlon, nlat, vmax,
              "F_max(Eq. 26) / F_max(elliptical) − 1, ellipsoid 2000 × 500 × 500 mm, ball r = 50 mm");
    // The file name only: the page must not carry the generating machine's paths.
    std::printf("\nMap for g = 4 (the paper's 2000 × 500 × 500 mm ellipsoid): `%s`.\n",
                std::filesystem::path(argv[1]).filename().c_str());
  }
  return 0;
}
