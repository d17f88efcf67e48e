// The sweep physics of bench_goals (the point loop of `impactdeck sweep samples/fig4_sweep.toml
// --cloud uniform`: a steel ball r 50 mm along the normal at 1 m/s onto the free steel ellipsoid
// 2 x 0.5 x 0.5 m, paper rule and modulus) with a contact law chosen by name, in process, built as a
// sweep builds it (LawOptions::tabulated: the plastic laws read their impacts from the table of
// the material pair, built inside the timed loop on first use). Both bodies get Y = 350 MPa, so a
// plastic law is plastic at every point.
// The points run through study::sweep_points (the grouped kernel, the law's solve once per group),
// on N threads taking ranges from an atomic counter; the clock covers that loop only, as the
// sweep's JSON `seconds` does.
//   sweep_law_physics LAW [--points N] [--threads N]
//   -> {"law": "...", "points": N, "threads": N, "seconds": S, "below_elastic": F}  (F: the fraction of valid points with R < 1)
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/contact/contact_model.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/study/sweep.hpp"

using namespace impactdeck;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sweep_law_physics LAW [--points N] [--threads N]\n");
    return 2;
  }
  const std::string law_name = argv[1];
  long points = 1000000;
  unsigned threads = 2;
  for (int i = 2; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--points") == 0) points = std::atol(argv[++i]);
    else if (std::strcmp(argv[i], "--threads") == 0) threads = static_cast<unsigned>(std::atoi(argv[++i]));
  }
  const collision::ElasticMaterial steel{2.05e11, 0.3};
  auto target_shape = std::make_shared<geometry::Ellipsoid>(2.0, 0.5, 0.5);
  auto ball_shape = std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(0.05));
  contact::PreparedBody target =
      contact::body_of_mass("ellipsoid", target_shape, 7850 * target_shape->volume_properties().volume_m3, steel);
  contact::PreparedBody ball =
      contact::body_of_mass("ball", ball_shape, 7850 * ball_shape->volume_properties().volume_m3, steel);
  target.yield_strength_Pa = ball.yield_strength_Pa = 350e6;
  collision::LawOptions options;
  options.restitution.kind = collision::RestitutionModel::Kind::energy_flux;
  options.youngs_modulus_Pa = steel.youngs_modulus_Pa;
  options.poisson_ratio = steel.poisson_ratio;
  options.tabulated = true;  // as scene::sweep_case builds a sweep's law
  const double E_star = 1.0 / (2.0 / steel.youngs_modulus_Pa);  // the paper's Eq. 28
  const contact::ContactModel model(target, ball, collision::ContactRule::paper, E_star,
                                    collision::make_contact_law(law_name, options));
  const std::vector<geometry::SurfacePoint> cloud = study::area_uniform_cloud(*target_shape, points, 1);
  std::vector<study::PointResult> out(cloud.size());

  constexpr std::size_t kRange = 4096;
  std::atomic<std::size_t> next{0};
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> workers;
  for (unsigned k = 0; k < threads; ++k) {
    workers.emplace_back([&] {
      for (std::size_t b; (b = next.fetch_add(kRange)) < cloud.size();) {
        study::sweep_points(model, 1.0, &cloud[b], std::min(kRange, cloud.size() - b), &out[b]);
      }
    });
  }
  for (auto& w : workers) w.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::size_t valid = 0, plastic = 0;
  for (const auto& p : out) {
    if (p.flagged()) continue;
    ++valid;
    if (p.restitution < 1.0) ++plastic;
  }
  std::printf("{\"law\": \"%s\", \"points\": %zu, \"threads\": %u, \"seconds\": %.6f, \"below_elastic\": %.4f}\n",
              law_name.c_str(), cloud.size(), threads, seconds, valid ? double(plastic) / valid : 0.0);
  return valid > 0 ? 0 : 1;
}
