// The full package: a scene from text (two spheres) through the pipeline, and a CAD part (a STEP
// file given as argument) through the Gmsh CAD plugin of the installed package.
#include <cstdio>
#include <exception>

#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

int main(int argc, char** argv) {
  using namespace impactdeck;
  try {
    const scene::Scene s = scene::parse_scene(R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "a"
shape = "sphere"
radius = 50
material = "steel"
[[bodies]]
name = "b"
shape = "sphere"
radius = 50
material = "steel"
velocity_m_s = [-1, 0, 0]
[[impacts]]
target = "a"
impactor = "b"
point = [50, 0, 0]
restitution = 1.0
contact_radius = "mean"
)", "consumer");
    const scene::RunReport r = scene::run_scene(s);
    std::printf("scene max_force_N %.10g checks %s\n", r.impacts.at(0).result.history.compression.max_force_N,
                r.all_checks_passed() ? "passed" : "FAILED");
    if (!r.all_checks_passed()) return 1;
    if (argc > 1) {
      const auto cad = geometry::CadShape::load(argv[1], LengthUnit::mm);
      std::printf("cad volume_m3 %.10g faces %zu\n", cad->volume_properties().volume_m3, cad->face_count());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
  return 0;
}
