// `impactdeck inspect PART --length-unit mm [--density-kg-m3 D | --mass-kg M] [--at x,y,z ...]
// [--json] [--repair] [--accept-approximate] [--no-self-intersections]`: validation report, mass
// properties and surface queries of a part file (mesh or CAD). The report is built by
// geometry::inspect_part; JSON keys: docs/geometry.md, docs/cad.md.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "conventions.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/geometry/inspect.hpp"

namespace impactdeck::cli {

void register_inspect(CLI::App& app, Context& ctx) {
  struct Args {
    std::string part, unit;
    std::optional<double> density, mass;
    std::vector<std::string> at;
    bool json = false, repair = false, approximate = false, no_self = false;
    double sharp_deg = 30.0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("inspect", "Validate a part file; mass properties; normal and curvature at points");
  cmd->add_option("part", args->part, "Part file: .stl (ascii/binary), .obj, .ply, .off; CAD: .step/.stp, .iges/.igs, .brep")->required();
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
  cmd->callback([args, &ctx] {
    auto unit = parse_length_unit(args->unit);
    if (!unit) throw UsageError("--length-unit '" + args->unit + "': expected m, cm, mm or in" +
                                        length_unit_suggestion(args->unit));
    // > 0 and within [1e-100, 1e100] (numeric.hpp): mass and inertia then stay finite.
    if (args->density && !(*args->density > 0 && within_magnitude_range(*args->density)))
      throw UsageError("--density-kg-m3 must be > 0 and within 1e-100 .. 1e+100");
    if (args->mass && !(*args->mass > 0 && within_magnitude_range(*args->mass)))
      throw UsageError("--mass-kg must be > 0 and within 1e-100 .. 1e+100");
    if (!(args->sharp_deg > 0 && args->sharp_deg < 180)) throw UsageError("--sharp-angle-deg must lie in (0, 180)");
    const double to_m = metres_per(*unit);
    std::vector<Eigen::Vector3d> points;
    for (const auto& s : args->at) points.push_back(geometry::parse_point(s, to_m));

    geometry::InspectOptions opt;
    opt.part = args->part;
    opt.length_unit = *unit;
    opt.density_kg_m3 = args->density;
    opt.mass_kg = args->mass;
    opt.points_m = points;
    opt.point_labels = args->at;
    opt.repair = args->repair;
    opt.accept_approximate = args->approximate;
    opt.check_self_intersections = !args->no_self;
    opt.sharp_angle_deg = args->sharp_deg;
    geometry::InspectReport rep;
    {
      VerboseTimer timer(ctx, "inspect", "inspect " + args->part);
      rep = geometry::inspect_part(opt);
    }
    if (args->json) {
      std::cout << rep.document.dump(2) << "\n";
      for (const auto& w : rep.warnings) ctx.warn(w);
      return;
    }
    ctx.report() << rep.text;
  });
}

}  // namespace impactdeck::cli
