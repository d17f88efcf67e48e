// `impactdeck inspect PART --length-unit mm [--density-kg-m3 D | --mass-kg M] [--at x,y,z ...]
// [--json] [--repair] [--accept-approximate] [--no-self-intersections]`: validation report, mass
// properties and surface queries of a part file. JSON keys: docs/geometry.md.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/geometry/part.hpp"

namespace impactdeck::cli {
namespace {

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x + 0.0) : nlohmann::json(nullptr); }
nlohmann::json vec(const Eigen::Vector3d& v) { return {num(v.x()), num(v.y()), num(v.z())}; }
nlohmann::json mat(const Eigen::Matrix3d& m) {
  nlohmann::json j = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) j.push_back({num(m(i, 0)), num(m(i, 1)), num(m(i, 2))});
  return j;
}
std::string text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(7) << "(" << v.x() + 0.0 << ", " << v.y() + 0.0 << ", " << v.z() + 0.0 << ")";
  return s.str();
}

Eigen::Vector3d parse_point(const std::string& s, double to_m) {
  std::stringstream in(s);
  Eigen::Vector3d p;
  std::string item;
  int k = 0;
  while (std::getline(in, item, ',')) {
    if (k >= 3) break;
    try {
      std::size_t used = 0;
      p[k] = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(p[k])) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw UsageError("--at '" + s + "': expected three numbers x,y,z");
    }
    ++k;
  }
  if (k != 3 || std::getline(in, item, ',')) throw UsageError("--at '" + s + "': expected three numbers x,y,z");
  return p * to_m;
}

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

}  // namespace

void register_inspect(CLI::App& app, Context& /*ctx*/) {
  struct Args {
    std::string part, unit;
    std::optional<double> density, mass;
    std::vector<std::string> at;
    bool json = false, repair = false, approximate = false, no_self = false;
    double sharp_deg = 30.0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("inspect", "Validate a part file; mass properties; normal and curvature at points");
  cmd->add_option("part", args->part, "Part file: .stl (ascii/binary), .obj, .ply, .off")->required();
  cmd->add_option("--length-unit", args->unit, "Unit of the file's coordinates: m, cm, mm or in (never guessed)")->required();
  auto* d = cmd->add_option("--density-kg-m3", args->density, "Density, kg/m^3");
  auto* m = cmd->add_option("--mass-kg", args->mass, "Total mass, kg (density = mass / volume)");
  d->excludes(m);
  m->excludes(d);
  cmd->add_option("--at", args->at, "Surface query at x,y,z (file unit; projected onto the surface); repeatable")
      ->take_all();
  cmd->add_flag("--json", args->json, "One JSON document on stdout (keys: docs/geometry.md)");
  cmd->add_flag("--repair", args->repair, "Repair: merge duplicates, stitch borders, orient outward (listed)");
  cmd->add_flag("--accept-approximate", args->approximate,
                "Accept approximate mass properties of an open / non-manifold / self-intersecting part");
  cmd->add_flag("--no-self-intersections", args->no_self, "Skip the self-intersection test (huge parts)");
  cmd->add_option("--sharp-angle-deg", args->sharp_deg, "Dihedral angle above which an edge is sharp (default 30)");
  cmd->callback([args] {
    auto unit = parse_length_unit(args->unit);
    if (!unit) throw UsageError("--length-unit '" + args->unit + "': expected m, cm, mm or in");
    if (args->density && !(*args->density > 0 && std::isfinite(*args->density)))
      throw UsageError("--density-kg-m3 must be > 0");
    if (args->mass && !(*args->mass > 0 && std::isfinite(*args->mass))) throw UsageError("--mass-kg must be > 0");
    if (!(args->sharp_deg > 0 && args->sharp_deg < 180)) throw UsageError("--sharp-angle-deg must lie in (0, 180)");
    const double to_m = metres_per(*unit);
    std::vector<Eigen::Vector3d> points;
    for (const auto& s : args->at) points.push_back(parse_point(s, to_m));

    geometry::PartOptions opt;
    opt.length_unit = *unit;
    opt.repair = args->repair;
    opt.accept_approximate_mass = args->approximate;
    opt.validation.check_self_intersections = !args->no_self;
    opt.shape.sharp_angle_deg = args->sharp_deg;
    opt.build_surface_index = !points.empty();  // the index serves the --at queries only
    const geometry::Part part = geometry::load_part(args->part, opt);
    const auto& vp = part.mass.volume;
    const auto& rep = part.validation_after_repair ? *part.validation_after_repair : part.validation;

    std::optional<double> density;
    if (args->density) density = *args->density;
    if (args->mass) density = *args->mass / vp.volume_m3;
    const Eigen::Matrix3d inertia = vp.inertia_per_density_m5 * density.value_or(1.0);
    const auto pa = geometry::principal_axes(vp.inertia_per_density_m5);
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
    j["volume_m3"] = num(vp.volume_m3);
    j["area_m2"] = num(vp.area_m2);
    j["density_kg_m3"] = density ? num(*density) : nlohmann::json(nullptr);
    j["mass_kg"] = density ? num(*density * vp.volume_m3) : nlohmann::json(nullptr);
    j["center_of_mass_m"] = vec(vp.centroid_m);
    j["inertia_per_density_m5"] = mat(vp.inertia_per_density_m5);
    j["inertia_kg_m2"] = density ? mat(inertia) : nlohmann::json(nullptr);
    j["principal_moments_kg_m2"] = density ? vec(pa.moments * *density) : nlohmann::json(nullptr);
    j["principal_moments_per_density_m5"] = vec(pa.moments);
    j["principal_axes"] = mat(pa.axes);  // columns are the axes
    j["principal_moment_relative_gaps"] = {num(pa.relative_gaps[0]), num(pa.relative_gaps[1])};
    j["principal_axes_well_defined"] = pa.axes_well_defined();
    j["sharp_edges"] = part.sharp_edges;
    j["mean_edge_length_m"] = num(part.mean_edge_length_m);
    nlohmann::json queries = nlohmann::json::array();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const geometry::MeshShape& shape = *part.shape;
      const auto sp = shape.closest_point(points[i]);
      nlohmann::json q;
      q["query_m"] = vec(points[i]);
      q["surface_point_m"] = vec(sp.point_m);
      q["distance_m"] = num(sp.distance_m);
      q["normal"] = vec(sp.normal);
      try {
        const auto fit = shape.curvature_fit(sp.point_m);
        const auto& c = fit.curvature;
        q["sharp_feature"] = c.sharp_feature;
        if (c.sharp_feature) {
          q["principal_curvatures_1_per_m"] = nullptr;
          q["principal_directions"] = nullptr;
          q["curvature_error_estimate_1_per_m"] = nullptr;
        } else {
          q["principal_curvatures_1_per_m"] = {num(c.k1_per_m), num(c.k2_per_m)};
          q["principal_directions"] = {vec(c.d1), vec(c.d2)};
          q["curvature_error_estimate_1_per_m"] = num(c.error_estimate_per_m);
          q["fit_condition_number"] = num(fit.condition_number);
          q["fit_points"] = fit.neighbourhood_points;
          q["planar_neighbourhood"] = fit.planar;
        }
        try {
          q["paper_radius_m"] = c.sharp_feature ? nlohmann::json(nullptr) : num(shape.paper_radius_m(sp));
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

    if (args->json) {
      std::cout << j.dump(2) << "\n";
      for (const auto& w : warnings) std::cerr << "impactdeck: warning: " << w << "\n";
      return;
    }
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
    std::cout << o.str();
  });
}

}  // namespace impactdeck::cli
