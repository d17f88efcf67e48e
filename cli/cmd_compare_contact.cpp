// `impactdeck compare-contact SCENE [--impact NAME] [--out DIR] [--json] [--threshold REL]
// [--refine N]`: run one impact as the hybrid deck and as a full-contact CalculiX model, and
// compare both with the analytic Hertz force (docs/contact-vs-hybrid.md). Exit 4 when the contact
// model's F_max differs from the analytic one by more than the threshold.
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "cli_limits.hpp"
#include "set_option.hpp"
#include "commands.hpp"
#include "conventions.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::cli {

void register_compare_contact(CLI::App& app, Context& ctx) {
  struct Args {
    std::string scene, out = ".";
    std::vector<std::string> set;
    bool json = false;
    scene::CompareOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "compare-contact", "Run an impact as the hybrid deck and as a full-contact CalculiX model; compare with Hertz");
  cmd->add_option("scene", args->scene, "Scene file (TOML)")->required();
  add_set_option(cmd, args->set);
  cmd->add_option("--impact", args->options.impact, "Impact name (default: the scene's first)");
  cmd->add_option("-o,--out", args->out, "Output folder (created): hybrid/, contact*/, compare_force.svg");
  cmd->add_flag("--json", args->json, "Print one JSON document on stdout (keys: docs/cli.md)");
  cmd->add_option("--threshold", args->options.threshold,
                  "Max |F_max contact / analytic - 1| before exit 4 (default 0.03)")
      ->check(positive_number());
  cmd->add_option("--refine", args->options.refine,
                  "Extra contact runs, each with sqrt(2) times more elements across the contact (default 0)")
      ->check(CLI::Range(0, 6));
  cmd->add_option("--contact-elements", args->options.contact.contact_elements,
                  "Elements across the smaller Hertz contact semi-axis, coarsest run (default 3)")
      ->check(positive_number());
  cmd->add_option("--contact-increments", args->options.contact.contact_increments,
                  "Increments across the analytic contact duration (default 40)")
      ->check(CLI::Range(4, 100000));
  cmd->add_option("--static-increments", args->options.contact.static_increments,
                  "Plastic (quasi-static) runs: increments of each load and unload (default 16)")
      ->check(CLI::Range(2, 10000));
  cmd->add_option("--penalty-factor", args->options.contact.penalty_factor,
                  "Penalty slope K = factor E* / h_c (default 20)")
      ->check(positive_number());
  cmd->add_option("--solver-timeout-s", args->options.solver_timeout_s,
                  "Wall-time limit of each ccx run (default: from each deck's size)")
      ->check(positive_number());
  cmd->add_option("--floor-block-factor", args->options.contact.floor_block_factor,
                  "A plane floor is a block of half-width and depth this many contact radii (default 40)")
      ->check(CLI::Range(4.0, 1000.0));
  cmd->add_option("--material-model", args->options.material_model,
                  "elastic (default) or plastic: both bodies elastic-plastic where their material has "
                  "yield_strength_Pa, compared with each contact law")
      ->transform(CLI::CheckedTransformer(std::map<std::string, fem_export::MaterialModel>{
          {"elastic", fem_export::MaterialModel::elastic}, {"plastic", fem_export::MaterialModel::plastic}}));
  cmd->add_flag("--no-hybrid", [args](std::int64_t) { args->options.run_hybrid = false; },
                "Run the full-contact model only");
  cmd->add_flag("--decks-only", [args](std::int64_t) { args->options.run_solvers = false; },
                "Write the hybrid and full-contact decks (meshes, impact.inp) and run no solver");
  cmd->callback([args, &ctx] {
    refuse_stdout_folder(args->out, "compare-contact");
    check_stdout_writable();  // refused before any work (a later failure rolls the comparison back)
    const scene::Scene sc = scene::load_scene(args->scene, overrides_from(args->set));
    // One transaction (docs/reliability.md): the decks and ccx's results are staged inside --out
    // and published together when the comparison completed, whatever its verdict; a failure or a
    // kill leaves --out as it was.
    RunTransaction txn(args->out);
    for (const auto& w : txn.warnings()) ctx.warn(w);
    scene::CompareOptions o = args->options;
    o.out_dir = args->out;
    o.progress = ctx.progress();
    o.place_output = [&txn, &args](const std::string& name, bool is_folder) {
      return is_folder ? txn.folder(name, args->out, "--out") : txn.file(name, args->out, "--out");
    };
    const scene::CompareReport r = txn.run([&] {
      VerboseTimer timer(ctx, "compare-contact", "hybrid and contact runs");
      scene::CompareReport report = scene::compare_contact(sc, o);
      scene::map_paths(report, [&txn](const std::filesystem::path& p) { return txn.public_path(p); });
      // stdout before the commit: when it fails the comparison is rolled back (docs/reliability.md).
      if (args->json) write_stdout(scene::to_json(report).dump(2) + "\n");
      else if (!ctx.quiet) write_stdout(scene::format_compare(report));
      txn.commit();
      return report;
    });
    if (r.verdict == scene::CompareVerdict::disagree) {
      std::cerr << "impactdeck: error: contact F_max differs from the analytic force beyond the threshold; in doubt: "
                << r.in_doubt << "\n";
      ctx.exit_code = static_cast<int>(ExitCode::check_failed);
    }
  });
}

}  // namespace impactdeck::cli
