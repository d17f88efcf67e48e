// libFuzzer target: scene text -> parse -> run (no output files). Any InputError is a correct
// answer to bad input; any other exception, a crash, a sanitizer report or a NaN in a report is a
// finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"

namespace {

void check_finite(const nlohmann::json& j) {
  if (j.is_number_float() && !std::isfinite(j.get<double>())) std::abort();
  if (j.is_structured())
    for (const auto& v : j) check_finite(v);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 1 << 16) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    impactdeck::scene::Scene s = impactdeck::scene::parse_scene(text, "fuzz.toml");
    s.outputs.force_table_csv.reset();  // no files: the fuzzer must not write
    s.outputs.force_plot_svg.reset();
    s.outputs.fem.reset();               // nor mesh (Gmsh) or run ccx
    for (auto& b : s.bodies)
      if (!b.shape->input_files().empty()) return 0;  // a part file: the mesh fuzzer covers meshes
    const auto report = impactdeck::scene::run_scene(s);
    check_finite(impactdeck::scene::to_json(s, report));
  } catch (const impactdeck::InputError&) {
  }
  return 0;
}
