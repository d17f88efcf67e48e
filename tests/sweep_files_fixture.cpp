// Writes the sweep files that tests/vtk_reader_test.py reads with VTK's own XML reader (Debian's
// python3-vtk9, what ParaView uses) and tests/meshio_reader_test.py with meshio: for two sweeps,
// the CSV, the raw VTP with UInt32 and with UInt64 block sizes, the compressed VTP and the
// compressed VTU (the file a sweep writes by default).
//   1. samples/fig4_sweep.toml: the paper's grid and 500 area-uniform points on the ellipsoid;
//   2. the 100 mm cube of tests/data/bad (mesh): its 8 corners (flagged sharp_feature = 1) and
//      200 area-uniform points.
//   sweep_files_fixture OUT_DIR SOURCE_DIR
#include <cstdio>
#include <filesystem>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/study/sweep_output.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {
void write(const fs::path& out, const std::string& name, const study::SweepResult& r) {
  study::write_sweep_csv(out / (name + ".csv"), r, {});
  study::SweepWriteOptions raw;
  raw.vtk_compress = false;
  study::write_sweep_vtp(out / (name + "_u32.vtp"), r, {}, raw);
  study::SweepWriteOptions wide = raw;
  wide.vtp_uint64_headers = true;
  study::write_sweep_vtp(out / (name + "_u64.vtp"), r, {}, wide);
  study::write_sweep_vtp(out / (name + "_zlib.vtp"), r, {});  // compressed: the default
  study::write_sweep_vtu(out / (name + ".vtu"), r, {});
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: sweep_files_fixture OUT_DIR SOURCE_DIR\n");
    return 2;
  }
  try {
    const fs::path out = argv[1], src = argv[2];
    fs::create_directories(out);
    {
      const scene::Scene sc = scene::load_scene(src / "samples" / "fig4_sweep.toml");
      const study::SweepCase ss = scene::sweep_case(sc);
      const auto cloud = study::make_cloud(*ss.setup.target.shape, study::CloudKind::both, 8, 500, 3);
      write(out, "ellipsoid", study::run_sweep(ss.setup, cloud));
    }
    {
      const scene::Scene sc = scene::load_scene(src / "tests" / "data" / "bad" / "scenes" / "mesh_sharp_edge.toml");
      const study::SweepCase ss = scene::sweep_case(sc);
      auto cloud = study::make_cloud(*ss.setup.target.shape, study::CloudKind::vertices, 8, 0, 1);
      const auto faces = study::make_cloud(*ss.setup.target.shape, study::CloudKind::area_uniform, 8, 200, 5);
      cloud.insert(cloud.end(), faces.begin(), faces.end());
      const study::SweepResult r = study::run_sweep(ss.setup, cloud);
      if (r.sharp_count != 8) {
        std::fprintf(stderr, "expected the 8 corners flagged, got %zu\n", r.sharp_count);
        return 1;
      }
      write(out, "cube", r);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_files_fixture: %s\n", e.what());
    return 1;
  }
  return 0;
}
