// libFuzzer target: bytes -> a temporary part file (extension from the first byte: stl, obj, ply,
// off) -> load_part (load, validate, mass properties accepted as approximate, surface index) ->
// closest point, curvature fit and Eq. 26 radius at a few points. An InputError is a correct answer
// to bad input; any other exception, a crash, a sanitizer report or a non-finite result is a
// finding (std::abort).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/part.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::geometry;

namespace {

// A failed check names itself on stderr before the abort, so a finding says what broke.
void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz_mesh: check failed: %s\n", what);
  std::abort();
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 1 << 16) return 0;
  static const char* const kExt[] = {".stl", ".obj", ".ply", ".off"};
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("impactdeck_fuzz_mesh_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  const fs::path file = dir / (std::string("part") + kExt[data[0] % 4]);
  {
    std::ofstream o(file, std::ios::binary | std::ios::trunc);
    o.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    PartOptions opt;
    opt.length_unit = LengthUnit::mm;
    opt.accept_approximate_mass = true;
    opt.repair = (data[0] & 4) != 0;
    const Part part = load_part(file, opt);
    const MeshShape& s = *part.shape;
    const auto& vp = s.volume_properties();
    require(std::isfinite(vp.volume_m3) && finite(vp.centroid_m) && vp.inertia_per_density_m5.allFinite(),
            "finite volume properties");
    require(std::isfinite(s.size_m()), "finite size");
    const auto pts = s.sample_surface(3, size);
    for (const auto& p : pts) {
      require(finite(p.point_m) && finite(p.normal), "finite surface sample");
      const SurfacePoint c = s.closest_point(p.point_m + 0.1 * s.size_m() * p.normal);
      require(finite(c.point_m) && finite(c.normal) && std::isfinite(c.distance_m), "finite closest point");
      try {
        const CurvatureFit f = s.curvature_fit(c.point_m);
        require(std::isfinite(f.curvature.k1_per_m) && std::isfinite(f.curvature.k2_per_m), "finite curvatures");
        if (!f.curvature.sharp_feature) {
          // A flat spot (a face of a box) has an infinite radius, a concave one a negative radius:
          // correct answers, not a NaN or a 0.
          const double r = s.paper_radius_m(c);
          require(r != 0 && !std::isnan(r), "Eq. 26 radius not 0 and not NaN (possibly infinite or negative)");
        }
      } catch (const InputError&) {
        // too coarse, sharp, degenerate: a correct answer for this point
      }
    }
  } catch (const InputError&) {
  } catch (const std::exception&) {
    std::abort();
  }
  return 0;
}
