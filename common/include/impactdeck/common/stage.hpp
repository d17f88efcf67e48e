#pragma once
// The stages of `run` (scene/pipeline) and of loading a part (geometry/part): one enum, one name
// each. The names are a contract: `stages_run`, `stages_skipped` and `stage_times_s` of
// `run --json`, `inspect --json` and `sweep --json` (docs/cli.md).
#include <chrono>

namespace impactdeck {

enum class Stage {
  scene,
  mesh_load,
  mesh_validation,
  mass_properties,
  sharp_edges,  ///< a part's stage (inspect without --at); not one of run's
  curvature_index,
  contact_geometry,
  impact,
  force_table,
  fem_mesh,
  fem_decks,
  fem_run,
  compare_contact,  ///< [outputs.fem] compare_contact = true (scene/compare_contact.hpp)
  cloud,            ///< `sweep`: the point cloud on the target (generated or read)
  sweep,            ///< `sweep`: the impact at every point of the cloud
  write_outputs,
};

/// The stage's name in JSON and messages ("mesh_load", "fem_run", ...).
constexpr const char* stage_name(Stage s) {
  switch (s) {
    case Stage::scene: return "scene";
    case Stage::mesh_load: return "mesh_load";
    case Stage::mesh_validation: return "mesh_validation";
    case Stage::mass_properties: return "mass_properties";
    case Stage::sharp_edges: return "sharp_edges";
    case Stage::curvature_index: return "curvature_index";
    case Stage::contact_geometry: return "contact_geometry";
    case Stage::impact: return "impact";
    case Stage::force_table: return "force_table";
    case Stage::fem_mesh: return "fem_mesh";
    case Stage::fem_decks: return "fem_decks";
    case Stage::fem_run: return "fem_run";
    case Stage::compare_contact: return "compare_contact";
    case Stage::cloud: return "cloud";
    case Stage::sweep: return "sweep";
    case Stage::write_outputs: return "write_outputs";
  }
  return "?";
}

/// Wall time of a scope, measured where the work runs: `record(seconds)` is called when the scope
/// ends (by an exception too). Nothing is subtracted after the fact.
template <class Record>
class ScopedTimer {
 public:
  explicit ScopedTimer(Record record) : record_(std::move(record)), start_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() { record_(std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count()); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  Record record_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace impactdeck
