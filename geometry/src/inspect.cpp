// inspect_part (inspect.hpp): the report of `impactdeck inspect`, moved here from the CLI unchanged
// for mesh parts; CAD parts (STEP, IGES, BREP) get their own keys (docs/cad.md).
#include "impactdeck/geometry/inspect.hpp"

#include <cmath>
#include <iomanip>
#include <memory>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/part.hpp"
#include "impactdeck/common/json_number.hpp"
#include "impactdeck/common/stage.hpp"

namespace impactdeck::geometry {
namespace {

nlohmann::json mat(const Eigen::Matrix3d& m) {
  nlohmann::json j = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) j.push_back({json_number(m(i, 0)), json_number(m(i, 1)), json_number(m(i, 2))});
  return j;
}
std::string text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(7) << "(" << v.x() + 0.0 << ", " << v.y() + 0.0 << ", " << v.z() + 0.0 << ")";
  return s.str();
}

}  // namespace

Eigen::Vector3d parse_point(const std::string& s, double to_m, const std::string& flag) {
  std::stringstream in(s);
  Eigen::Vector3d p;
  std::string item;
  int k = 0;
  while (std::getline(in, item, ',')) {
    if (k >= 3) break;
    try {
      std::size_t used = 0;
      p[k] = std::stod(item, &used);
      // Within 1e20 m of the origin, as the parts are (text_mesh_readers.hpp): squared distances stay finite.
      if (used != item.size() || !std::isfinite(p[k]) || std::abs(p[k] * to_m) > 1e20) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw UsageError(flag + " '" + s + "': expected three numbers x,y,z, each within 1e20 m of the origin");
    }
    ++k;
  }
  if (k != 3 || std::getline(in, item, ',')) throw UsageError(flag + " '" + s + "': expected three numbers x,y,z");
  return p * to_m;
}

namespace {

nlohmann::json validation_json(const geometry::ValidationReport& r) {
  return {{"triangles", r.triangles},
          {"vertices", r.vertices},
          {"shells", r.shells},
          {"closed", r.closed},
          {"boundary_edges", r.boundary_edges},
          {"non_manifold_edges", r.non_manifold_edges},
          {"non_manifold_vertices", r.non_manifold_vertices},
          {"orientation_conflicts", r.orientation_conflicts},
          {"consistently_oriented", r.consistently_oriented},
          {"outward_oriented", r.outward_oriented},
          {"shell_nesting_depth", r.shell_nesting_depth},
          {"degenerate_triangles", r.degenerate_triangles},
          {"self_intersections_checked", r.self_intersections_checked},
          {"self_intersections", r.self_intersections_checked ? nlohmann::json(r.self_intersecting_pairs)
                                                              : nlohmann::json(nullptr)}};
}


InspectReport inspect_cad(const InspectOptions& args, const std::vector<Eigen::Vector3d>& points);

}  // namespace

InspectReport inspect_part(const InspectOptions& a) {
  struct Args {
    std::string part, unit;
    std::optional<double> density, mass;
    std::vector<std::string> at;
    bool repair, approximate, no_self;
    double sharp_deg;
  };
  const auto unit = std::optional<LengthUnit>(a.length_unit);
  if (a.density_kg_m3 && a.mass_kg) throw UsageError("give --density-kg-m3 or --mass-kg, not both");
  if (a.density_kg_m3 && !(*a.density_kg_m3 > 0 && std::isfinite(*a.density_kg_m3)))
    throw UsageError("--density-kg-m3 must be > 0");
  if (a.mass_kg && !(*a.mass_kg > 0 && std::isfinite(*a.mass_kg))) throw UsageError("--mass-kg must be > 0");
  if (!(a.sharp_angle_deg > 0 && a.sharp_angle_deg < 180)) throw UsageError("--sharp-angle-deg must lie in (0, 180)");
  const std::vector<Eigen::Vector3d>& points = a.points_m;
  if (cad_format(a.part)) return inspect_cad(a, points);
  const auto args = std::make_shared<Args>(Args{a.part.string(), to_string(a.length_unit), a.density_kg_m3, a.mass_kg,
                                                a.point_labels, a.repair, a.accept_approximate,
                                                !a.check_self_intersections, a.sharp_angle_deg});
  for (std::size_t i = args->at.size(); i < points.size(); ++i) {
    std::ostringstream s;
    s << std::setprecision(17) << points[i].x() / metres_per(a.length_unit) << "," << points[i].y() / metres_per(a.length_unit)
      << "," << points[i].z() / metres_per(a.length_unit);
    args->at.push_back(s.str());
  }
    PartOptions opt;
    opt.length_unit = *unit;
    opt.repair = args->repair;
    opt.accept_approximate_mass = args->approximate;
    opt.validation.check_self_intersections = !args->no_self;
    opt.shape.sharp_angle_deg = args->sharp_deg;
    opt.build_surface_index = !points.empty();  // the index serves the --at queries only
    const Part part = load_part(args->part, opt);
    const auto& vp = part.mass.volume;
    const auto& rep = part.validation_after_repair ? *part.validation_after_repair : part.validation;

    std::optional<double> density;
    if (args->density) density = *args->density;
    if (args->mass) density = *args->mass / vp.volume_m3;
    const Eigen::Matrix3d inertia = vp.inertia_per_density_m5 * density.value_or(1.0);
    const auto pa = principal_axes(vp.inertia_per_density_m5);
    std::vector<std::string> warnings = part.warnings;
    if (!density) warnings.push_back("no --density-kg-m3 or --mass-kg: mass_kg, inertia_kg_m2 and principal_moments_kg_m2 are null");
    if (!pa.axes_well_defined()) warnings.push_back(pa.describe_degeneracy());

    nlohmann::json j;
    j["impactdeck_version"] = kVersion;
    j["file"] = args->part;
    j["format"] = part.loaded.format;
    j["length_unit"] = to_string(*unit);
    j["triangles"] = rep.triangles;
    j["vertices"] = rep.vertices;
    j["shells"] = rep.shells;
    j["closed"] = rep.closed;
    j["outward_oriented"] = rep.outward_oriented;
    j["self_intersections"] = rep.self_intersections_checked ? nlohmann::json(rep.self_intersecting_pairs) : nlohmann::json(nullptr);
    j["load"] = {{"file_vertices", part.loaded.file_vertices},
                 {"merged_vertices", part.loaded.merged_vertices},
                 {"polygons_triangulated", part.loaded.polygons_triangulated},
                 {"lines_ignored", part.loaded.lines_ignored},
                 {"points_ignored", part.loaded.points_ignored}};
    j["validation"] = validation_json(part.validation);
    if (part.validation_after_repair) j["validation_after_repair"] = validation_json(*part.validation_after_repair);
    j["repairs"] = part.repairs.actions;
    j["mass_properties_approximate"] = part.approximate_mass;
    j["approximation_reason"] = part.approximate_mass ? nlohmann::json(part.approximation_reason) : nlohmann::json(nullptr);
    j["volume_m3"] = json_number(vp.volume_m3);
    if (const auto& ov = part.open_volume) {
      j["open_surface"] = {{"holes", ov->holes},
                           {"boundary_edges", ov->boundary_edges},
                           {"volume_min_m3", json_number(ov->volume_min_m3)},
                           {"volume_max_m3", json_number(ov->volume_max_m3)}};
    } else {
      j["open_surface"] = nullptr;
    }
    j["area_m2"] = json_number(vp.area_m2);
    j["density_kg_m3"] = density ? json_number(*density) : nlohmann::json(nullptr);
    j["mass_kg"] = density ? json_number(*density * vp.volume_m3) : nlohmann::json(nullptr);
    j["center_of_mass_m"] = json_vector(vp.centroid_m);
    j["inertia_per_density_m5"] = mat(vp.inertia_per_density_m5);
    j["inertia_kg_m2"] = density ? mat(inertia) : nlohmann::json(nullptr);
    j["principal_moments_kg_m2"] = density ? json_vector(pa.moments * *density) : nlohmann::json(nullptr);
    j["principal_moments_per_density_m5"] = json_vector(pa.moments);
    j["principal_axes"] = mat(pa.axes);  // columns are the axes
    j["principal_moment_relative_gaps"] = {json_number(pa.relative_gaps[0]), json_number(pa.relative_gaps[1])};
    j["principal_axes_well_defined"] = pa.axes_well_defined();
    j["sharp_edges"] = part.sharp_edges;
    j["mean_edge_length_m"] = json_number(part.mean_edge_length_m);
    nlohmann::json queries = nlohmann::json::array();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const MeshShape& shape = *part.shape;
      const auto sp = shape.closest_point(points[i]);
      nlohmann::json q;
      q["query_m"] = json_vector(points[i]);
      q["surface_point_m"] = json_vector(sp.point_m);
      q["distance_m"] = json_number(sp.distance_m);
      q["normal"] = json_vector(sp.normal);
      try {
        const auto fit = shape.curvature_fit(sp.point_m);
        const auto& c = fit.curvature;
        q["sharp_feature"] = c.sharp_feature;
        if (c.sharp_feature) {
          q["principal_curvatures_1_per_m"] = nullptr;
          q["principal_directions"] = nullptr;
          q["curvature_error_estimate_1_per_m"] = nullptr;
        } else {
          q["principal_curvatures_1_per_m"] = {json_number(c.k1_per_m), json_number(c.k2_per_m)};
          q["principal_directions"] = {json_vector(c.d1), json_vector(c.d2)};
          q["curvature_error_estimate_1_per_m"] = json_number(c.error_estimate_per_m);
          q["fit_condition_number"] = json_number(fit.condition_number);
          q["fit_points"] = fit.neighbourhood_points;
          q["planar_neighbourhood"] = fit.planar;
        }
        try {
          q["paper_radius_m"] = c.sharp_feature ? nlohmann::json(nullptr) : json_number(shape.paper_radius_m(sp));
        } catch (const InputError& e) {
          q["paper_radius_m"] = nullptr;
          warnings.push_back("--at " + args->at[i] + ": " + e.reason());
        }
      } catch (const InputError& e) {
        throw InputError(args->part, "--at " + args->at[i], e.reason());
      }
      queries.push_back(q);
    }
    j["points"] = queries;
    nlohmann::json stages = nlohmann::json::object(), run = nlohmann::json::array();
    for (const auto& s : part.stages) {
      stages[s.name] = s.seconds;
      run.push_back(s.name);
    }
    j["stages_run"] = run;
    j["stages_skipped"] = part.stages_skipped;
    j["stage_times_s"] = stages;
    j["warnings"] = warnings;

    std::ostringstream o;
    o << std::setprecision(7);
    o << "impactdeck inspect " << args->part << " (" << part.loaded.format << ", unit " << to_string(*unit) << ")\n";
    o << "  triangles " << rep.triangles << ", vertices " << rep.vertices << " (" << part.loaded.merged_vertices
      << " duplicate vertex records merged), shells " << rep.shells << "\n";
    o << "  closed " << (rep.closed ? "yes" : "no") << " (boundary edges " << rep.boundary_edges
      << "), non-manifold edges " << rep.non_manifold_edges << ", vertices " << rep.non_manifold_vertices << "\n";
    o << "  orientation " << (rep.consistently_oriented ? "consistent" : "INCONSISTENT") << ", "
      << (rep.outward_oriented ? "outward" : "NOT outward") << "; degenerate triangles " << rep.degenerate_triangles << "\n";
    o << "  self-intersections " << (rep.self_intersections_checked ? std::to_string(rep.self_intersecting_pairs) + " pairs" : std::string("not checked")) << "\n";
    for (const auto& a : part.repairs.actions) o << "  repair: " << a << "\n";
    if (part.approximate_mass) o << "  MASS PROPERTIES ARE APPROXIMATE: " << part.approximation_reason << "\n";
    o << "  volume " << vp.volume_m3 << " m^3, area " << vp.area_m2 << " m^2\n";
    if (const auto& ov = part.open_volume) {
      o << "  open surface: " << ov->holes << " hole(s) capped flat; volume between " << ov->volume_min_m3 << " and "
        << ov->volume_max_m3 << " m^3 for any cone-shaped cap with its apex inside the bounding box\n";
    }
    if (density) o << "  mass " << *density * vp.volume_m3 << " kg (density " << *density << " kg/m^3)\n";
    o << "  centre of mass " << text(vp.centroid_m) << " m\n";
    const Eigen::Matrix3d& shown = density ? inertia : vp.inertia_per_density_m5;
    o << "  inertia about the centre of mass (" << (density ? "kg m^2" : "per unit density, m^5") << "):\n";
    for (int r = 0; r < 3; ++r) o << "    " << text(shown.row(r).transpose()) << "\n";
    o << "  principal moments " << text(pa.moments * density.value_or(1.0)) << ", gaps "
      << pa.relative_gaps[0] << ", " << pa.relative_gaps[1] << "\n";
    for (int k = 0; k < 3; ++k) o << "    axis " << k + 1 << " " << text(pa.axes.col(k)) << "\n";
    o << "  sharp edges " << part.sharp_edges << ", mean edge length " << part.mean_edge_length_m << " m\n";
    for (std::size_t i = 0; i < queries.size(); ++i) {
      const auto& q = queries[i];
      o << "  at " << args->at[i] << ": surface point " << q["surface_point_m"].dump() << " m, normal "
        << q["normal"].dump() << "\n";
      if (q["sharp_feature"].get<bool>()) {
        o << "    SHARP EDGE OR CORNER: curvature undefined, the local radius is your call\n";
      } else {
        o << "    principal curvatures " << q["principal_curvatures_1_per_m"].dump() << " 1/m (error estimate "
          << q["curvature_error_estimate_1_per_m"].dump() << "), Eq. 26 radius "
          << (q["paper_radius_m"].is_null() ? std::string("infinite (flat)") : q["paper_radius_m"].dump() + " m") << "\n";
      }
    }
    for (const auto& w : warnings) o << "  warning: " << w << "\n";
    InspectReport out;
    out.document = std::move(j);
    out.text = o.str();
    out.warnings = std::move(warnings);
    return out;
}

namespace {

// CAD parts: the B-rep's own facts instead of a triangle mesh's validation (docs/cad.md).
InspectReport inspect_cad(const InspectOptions& a, const std::vector<Eigen::Vector3d>& points) {
  CadShapeOptions co;
  co.sharp_angle_deg = a.sharp_angle_deg;
  const auto shape = CadShape::load(a.part, a.length_unit, co);
  const VolumeProperties vp = shape->volume_properties();
  std::optional<double> density = a.density_kg_m3;
  if (a.mass_kg) density = *a.mass_kg / vp.volume_m3;
  const auto pa = principal_axes(vp.inertia_per_density_m5);
  std::vector<std::string> warnings = shape->warnings();
  if (!density) warnings.push_back("no --density-kg-m3 or --mass-kg: mass_kg, inertia_kg_m2 and principal_moments_kg_m2 are null");
  if (!pa.axes_well_defined()) warnings.push_back(pa.describe_degeneracy());
  const double to_unit = 1.0 / metres_per(a.length_unit);

  nlohmann::json j;
  j["impactdeck_version"] = kVersion;
  j["file"] = a.part.string();
  j["format"] = to_string(shape->format());
  j["length_unit"] = to_string(a.length_unit);
  j["file_length_unit"] = shape->file_unit() ? nlohmann::json(shape->file_unit()->name) : nlohmann::json(nullptr);
  j["solids"] = shape->solid_count();
  j["faces"] = shape->face_count();
  j["edges"] = shape->edge_count();
  j["closed"] = true;  // a B-rep solid is closed by construction
  j["mass_properties_approximate"] = false;
  j["approximation_reason"] = nullptr;
  j["open_surface"] = nullptr;
  j["mass_properties_source"] = "exact (OpenCASCADE, B-rep solid)";
  j["mass_properties_relative_error_estimate"] = json_number(shape->mass_relative_error_estimate());
  j["triangulation"] = {{"triangles", shape->triangulation().mesh().triangle_count()},
                        {"vertices", shape->triangulation().mesh().vertex_count()},
                        {"volume_relative_difference", json_number(shape->triangulation_volume_relative_difference())}};
  j["volume_m3"] = json_number(vp.volume_m3);
  j["area_m2"] = json_number(vp.area_m2);
  j["density_kg_m3"] = density ? json_number(*density) : nlohmann::json(nullptr);
  j["mass_kg"] = density ? json_number(*density * vp.volume_m3) : nlohmann::json(nullptr);
  j["center_of_mass_m"] = json_vector(vp.centroid_m);
  j["inertia_per_density_m5"] = mat(vp.inertia_per_density_m5);
  j["inertia_kg_m2"] = density ? mat(vp.inertia_per_density_m5 * *density) : nlohmann::json(nullptr);
  j["principal_moments_kg_m2"] = density ? json_vector(pa.moments * *density) : nlohmann::json(nullptr);
  j["principal_moments_per_density_m5"] = json_vector(pa.moments);
  j["principal_axes"] = mat(pa.axes);
  j["principal_moment_relative_gaps"] = {json_number(pa.relative_gaps[0]), json_number(pa.relative_gaps[1])};
  j["principal_axes_well_defined"] = pa.axes_well_defined();
  j["sharp_edges"] = shape->sharp_edge_count();
  std::ostringstream o;
  o << std::setprecision(7);
  o << "impactdeck inspect " << a.part.string() << " (" << to_string(shape->format()) << ", unit "
    << to_string(a.length_unit) << (shape->file_unit() ? ", as the file states" : ", declared: a BREP states none") << ")\n";
  o << "  solids " << shape->solid_count() << ", faces " << shape->face_count() << ", edges " << shape->edge_count()
    << " (" << shape->sharp_edge_count() << " sharp)\n";
  o << "  volume " << vp.volume_m3 << " m^3, area " << vp.area_m2 << " m^2 (from the B-rep, relative error estimate "
    << std::setprecision(2) << shape->mass_relative_error_estimate() << std::setprecision(7) << ")\n";
  if (density) o << "  mass " << *density * vp.volume_m3 << " kg (density " << *density << " kg/m^3)\n";
  o << "  centre of mass " << text(vp.centroid_m) << " m\n";
  const Eigen::Matrix3d shown = vp.inertia_per_density_m5 * density.value_or(1.0);
  o << "  inertia about the centre of mass (" << (density ? "kg m^2" : "per unit density, m^5") << "):\n";
  for (int r = 0; r < 3; ++r) o << "    " << text(shown.row(r).transpose()) << "\n";
  nlohmann::json queries = nlohmann::json::array();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string label = i < a.point_labels.size() ? a.point_labels[i] : text(points[i] * to_unit);
    const CadLocation loc = shape->locate(points[i]);
    const SurfacePoint& sp = loc.point;
    nlohmann::json q;
    q["query_m"] = json_vector(points[i]);
    q["surface_point_m"] = json_vector(sp.point_m);
    q["distance_m"] = json_number(sp.distance_m);
    q["normal"] = json_vector(sp.normal);
    q["face"] = loc.face;
    q["edge"] = loc.edge >= 0 ? nlohmann::json(loc.edge) : nlohmann::json(nullptr);
    Curvature c;
    try {
      c = shape->curvature(sp);
    } catch (const InputError& e) {
      throw InputError(a.part.string(), "--at " + label, e.reason());
    }
    q["sharp_feature"] = c.sharp_feature;
    o << "  at " << label << ": surface point " << q["surface_point_m"].dump() << " m, normal " << q["normal"].dump()
      << ", face " << loc.face << "\n";
    if (c.sharp_feature) {
      q["principal_curvatures_1_per_m"] = nullptr;
      q["principal_directions"] = nullptr;
      q["curvature_error_estimate_1_per_m"] = nullptr;
      q["paper_radius_m"] = nullptr;
      o << "    SHARP EDGE OR CORNER: curvature undefined, the local radius is your call\n";
    } else {
      q["principal_curvatures_1_per_m"] = {json_number(c.k1_per_m), json_number(c.k2_per_m)};
      q["principal_directions"] = {json_vector(c.d1), json_vector(c.d2)};
      q["curvature_error_estimate_1_per_m"] = json_number(c.error_estimate_per_m);
      try {
        q["paper_radius_m"] = json_number(shape->paper_radius_m(sp));
      } catch (const InputError& e) {
        q["paper_radius_m"] = nullptr;
        warnings.push_back("--at " + label + ": " + e.reason());
      }
      o << "    principal curvatures " << q["principal_curvatures_1_per_m"].dump() << " 1/m (exact; check "
        << q["curvature_error_estimate_1_per_m"].dump() << "), Eq. 26 radius "
        << (q["paper_radius_m"].is_null() ? std::string("infinite (flat)") : q["paper_radius_m"].dump() + " m") << "\n";
    }
    queries.push_back(q);
  }
  j["points"] = queries;
  j["stage_times_s"] = {{stage_name(Stage::mesh_load), shape->load_seconds()}};
  j["warnings"] = warnings;
  for (const auto& w : warnings) o << "  warning: " << w << "\n";
  InspectReport out;
  out.document = std::move(j);
  out.text = o.str();
  out.warnings = std::move(warnings);
  return out;
}

}  // namespace

}  // namespace impactdeck::geometry
