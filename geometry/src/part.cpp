#include "impactdeck/geometry/part.hpp"

#include <chrono>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/stage.hpp"
#include "side_task.hpp"
#include "text_mesh_readers.hpp"

namespace impactdeck::geometry {

namespace {
// Runs f as `stage`, recording its wall time when it completes (a stage that throws is not listed).
template <class F>
auto timed(std::vector<StageSeconds>& stages, Stage stage, F&& f) {
  double seconds = 0;
  auto done = [&] { stages.push_back({stage_name(stage), seconds}); };
  if constexpr (std::is_void_v<decltype(f())>) {
    { ScopedTimer t([&](double s) { seconds = s; }); f(); }
    done();
  } else {
    auto v = [&] { ScopedTimer t([&](double s) { seconds = s; }); return f(); }();
    done();
    return v;
  }
}
}  // namespace

const std::vector<std::string>& part_stages() {
  static const std::vector<std::string> names{stage_name(Stage::mesh_load), stage_name(Stage::mesh_validation),
                                              stage_name(Stage::mass_properties), stage_name(Stage::sharp_edges),
                                              stage_name(Stage::curvature_index)};
  return names;
}

namespace {

// What --repair did, for the messages about what it could not fix.
std::string repairs_text(const RepairLog& log) {
  if (log.actions.empty()) return "it changed nothing";
  std::string t = "it did: ";
  for (std::size_t i = 0; i < log.actions.size(); ++i) t += (i ? "; " : "") + log.actions[i];
  return t;
}

}  // namespace

Part load_part(const std::filesystem::path& file, const PartOptions& opt) {
  Part part;
  part.file = file;
  const std::string where = file.string();
  part.loaded = timed(part.stages, Stage::mesh_load, [&] { return load_mesh(file, opt.length_unit); });
  detail::check_part_extent(part.loaded, where);  // size range, memory for the stages below
  part.warnings = part.loaded.warnings;
  {
    const auto& v = part.loaded.mesh.vertices_m;
    Eigen::Vector3d lo = v.empty() ? Eigen::Vector3d::Zero() : v.front(), hi = lo;
    for (const auto& p : v) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    if (std::string w = implausible_size_warning((hi - lo).norm(), opt.length_unit); !w.empty()) {
      part.warnings.push_back(where + ": " + w);
    }
  }
  TriangleMesh mesh = std::move(part.loaded.mesh);
  part.loaded.mesh = TriangleMesh();

  // The validation's shells and mass integrals are those of the mesh it validated (the repaired
  // one after a repair): the mass_properties stage reuses them.
  ValidationByproducts by;
  ValidationReport report = timed(part.stages, Stage::mesh_validation, [&] {
    part.validation = validate_mesh(mesh, opt.validation, &by);
    if (!opt.repair) return part.validation;
    part.repairs = repair_mesh(mesh);
    part.validation_after_repair = validate_mesh(mesh, opt.validation, &by);
    return *part.validation_after_repair;
  });
  if (mesh.triangles.empty()) throw InputError(where, "faces", "no triangle is left after repair");
  if (!report.self_intersections_checked) {
    part.warnings.push_back(where + ": self-intersections were not checked (turned off)");
  }
  // Orientation is not a matter of approximation: a reversed shell would count as negative volume.
  // (For an open or non-manifold surface, "outward" is undefined: that case is the approximation
  // handled below.)
  const bool solid_topology = report.closed && report.non_manifold_edges == 0;
  if (solid_topology && (!report.consistently_oriented || !report.outward_oriented)) {
    std::ostringstream s;
    if (!report.consistently_oriented) {
      s << "the orientation of the triangles is inconsistent (" << report.orientation_conflicts
        << " edges traversed twice in the same direction)";
    } else if (!report.inward_shells.empty()) {
      s << "shell " << report.inward_shells.front() << " (of " << report.shells
        << ") is oriented inward (normals point into the material)";
    } else {
      s << "the surface is oriented inward (negative signed volume)";
    }
    if (opt.repair) {
      s << " after --repair (" << repairs_text(part.repairs) << "), which could not orient it outward";
    } else {
      s << "; rerun with --repair (scene: repair = true) to orient it outward";
    }
    throw InputError(where, "orientation", s.str());
  }
  if (!report.valid_solid()) {
    part.approximation_reason = report.approximation_reason();
    if (!opt.accept_approximate_mass) {
      const std::string fix = opt.repair ? "; this is what is left after --repair (" + repairs_text(part.repairs) +
                                               "): accept the approximation with --accept-approximate (scene: "
                                               "approximate_mass_properties = true)"
                                         : "; rerun with --repair, or accept the approximation with "
                                           "--accept-approximate (scene: approximate_mass_properties = true)";
      throw InputError(where, "mass properties",
                       part.approximation_reason + ": volume, mass and inertia would be approximate" + fix);
    }
    part.approximate_mass = true;
    part.warnings.push_back(where + ": APPROXIMATE mass properties: " + part.approximation_reason);
  }

  MeshMassProperties mass = timed(part.stages, Stage::mass_properties, [&] {
    by.shells = ShellLabels();
    return std::move(by.mass);
  });
  // An open surface has no inside: its holes are capped flat, and the volume's range over other
  // caps is stated (cap_holes).
  std::optional<HoleCaps> caps;
  auto integrate = [&] {
    if (!part.approximate_mass || report.closed) return compute_mass_properties(mesh, label_shells(mesh));
    caps = cap_holes(mesh, by.edges);
    MeshMassProperties m = compute_mass_properties(caps->capped, label_shells(caps->capped));
    m.volume.area_m2 = mass.volume.area_m2;  // the part's surface, not its caps
    return m;
  };
  if (part.approximate_mass && !report.closed) mass = integrate();
  if (part.approximate_mass && mass.volume.volume_m3 < 0) {
    // A negative signed volume means the normals point the other way. Accepted approximation:
    // take the orientation as reversed, and say so.
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
    mass = integrate();
    part.warnings.push_back(where + ": the open surface's signed volume was negative: its orientation "
                            "was taken as reversed for the approximation");
  }
  if (caps) {
    const double v = mass.volume.volume_m3;
    part.open_volume = Part::OpenVolume{caps->loops, caps->boundary_edges, v + caps->volume_min_offset_m3,
                                        v + caps->volume_max_offset_m3};
    std::ostringstream s;
    s << where << ": open surface: volume " << v << " m^3 with its " << caps->loops
      << " hole(s) capped flat; any cone-shaped cap with its apex inside the bounding box gives "
      << part.open_volume->volume_min_m3 << " to " << part.open_volume->volume_max_m3 << " m^3";
    part.warnings.push_back(s.str());
  }
  if (opt.build_surface_index) by.edges = EdgeTable();  // the index builds its own
  if (!(mass.volume.volume_m3 > 0) || !mass.volume.inertia_per_density_m5.allFinite()) {
    std::ostringstream s;
    s << "the enclosed volume is not positive (" << mass.volume.volume_m3 << " m^3)";
    throw InputError(where, "mass properties", s.str());
  }
  part.mass = mass;
  if (!opt.build_surface_index) {
    // Only what a report needs; the mesh is released with this function.
    timed(part.stages, Stage::sharp_edges, [&] {
      // The mean edge length on a second thread beside the count (a large mesh).
      double mean_edge = 0;
      detail::SideTask side(mesh.triangles.size() >= 20000, [&] { mean_edge = mesh.mean_edge_length_m(); });
      // The validation's edge table (a reversal above keeps its undirected edges and their faces).
      part.sharp_edges = count_sharp_edges(mesh, by.edges, opt.shape.sharp_angle_deg);
      side.join();
      by.edges = EdgeTable();
      part.mean_edge_length_m = mean_edge;
    });
    part.stages_skipped.push_back(stage_name(Stage::curvature_index));
    return part;
  }
  part.shape = timed(part.stages, Stage::curvature_index, [&] {
    return std::make_shared<const MeshShape>(std::move(mesh), mass, opt.shape);
  });
  part.sharp_edges = part.shape->sharp_edge_count();
  part.mean_edge_length_m = part.shape->mean_edge_length_m();
  return part;
}

}  // namespace impactdeck::geometry
