// `impactdeck mesh-ellipsoid A B C --subdivisions N -o FILE.stl [--ascii]`: a well-shaped test part
// (subdivided icosahedron mapped onto the ellipsoid). Semi-axes in the file's own unit.
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "conventions.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mesh_io.hpp"

namespace impactdeck::cli {

void register_mesh_ellipsoid(CLI::App& app, Context& ctx) {
  struct Args {
    double a = 0, b = 0, c = 0;
    int subdivisions = 5;
    std::string out;
    bool ascii = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "mesh-ellipsoid", "Write an ellipsoid as a subdivided icosahedron (20·4^N triangles) to an STL file");
  cmd->add_option("A", args->a, "Semi-axis along x (in the unit you will declare when reading it)")->required();
  cmd->add_option("B", args->b, "Semi-axis along y")->required();
  cmd->add_option("C", args->c, "Semi-axis along z")->required();
  cmd->add_option("--subdivisions", args->subdivisions, "Icosahedron subdivisions N, 0..10 (default 5: 20480 triangles)");
  cmd->add_option("-o,--out,--output", args->out, "Output STL file (written atomically); - writes it to stdout")->required();
  cmd->add_flag("--ascii", args->ascii, "ASCII STL instead of binary");
  cmd->callback([args, &ctx] {
    VerboseTimer timer(ctx, "mesh-ellipsoid", "mesh and write");
    const auto mesh = geometry::make_ellipsoid_mesh(args->a, args->b, args->c, args->subdivisions);
    if (args->out == kStdStream) {  // the STL alone on stdout (built whole first: a failure prints nothing)
      std::ostringstream stl;
      if (args->ascii) geometry::write_stl_ascii(stl, "stdout", mesh, LengthUnit::m, "ellipsoid");
      else geometry::write_stl_binary(stl, "stdout", mesh, LengthUnit::m, "impactdeck mesh-ellipsoid");
      write_stdout(stl.str());
      return;
    }
    if (args->ascii) geometry::write_stl_ascii(args->out, mesh, LengthUnit::m, "ellipsoid");
    else geometry::write_stl_binary(args->out, mesh, LengthUnit::m, "impactdeck mesh-ellipsoid");
    ctx.report() << "wrote " << args->out << ": " << mesh.triangle_count() << " triangles, " << mesh.vertex_count()
                 << " vertices\n";
  });
}

}  // namespace impactdeck::cli
