#pragma once
// Sub-commands of the `impactdeck` CLI. Each registers itself on the app and stores its exit code
// in `exit_code` when it runs. The CLI only wires the libraries together.
#include <CLI/CLI.hpp>

namespace impactdeck::cli {

struct Context {
  int exit_code = 0;
};

void register_run(CLI::App& app, Context& ctx);
void register_sweep(CLI::App& app, Context& ctx);
void register_study(CLI::App& app, Context& ctx);
void register_inspect(CLI::App& app, Context& ctx);
void register_mesh_ellipsoid(CLI::App& app, Context& ctx);
void register_fem_check(CLI::App& app, Context& ctx);
void register_compare_contact(CLI::App& app, Context& ctx);
void register_campaign(CLI::App& app, Context& ctx);

}  // namespace impactdeck::cli
