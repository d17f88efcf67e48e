// `impactdeck campaign plan|run|run-case|status|cancel|collect`: many cases of one scene
// (docs/campaign-format.md), here or on a Slurm cluster.
#include <filesystem>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "conventions.hpp"
#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/collect.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::cli {
namespace fs = std::filesystem;

namespace {

fs::path self_executable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error(ExitCode::internal_error, "cannot find the impactdeck executable (/proc/self/exe)");
  return p;
}

}  // namespace

void register_campaign(CLI::App& app, Context& ctx) {
  struct Args {
    std::string file, out, dir, executor = "local";
    std::size_t id = 0, jobs = 1;
    int threads = 1, cpus_per_task = 0;
    bool dry_run = false, json = false;
    std::vector<std::string> sbatch;
    double sbatch_timeout_s = campaign::kDefaultSbatchTimeoutS;
  };
  auto a = std::make_shared<Args>();
  CLI::App* top = app.add_subcommand("campaign", "Many cases of one scene, here or on a Slurm cluster (docs/campaign-format.md)");
  top->require_subcommand(1);

  CLI::App* plan = top->add_subcommand("plan", "Expand a campaign file into case folders and campaign.json");
  plan->add_option("file", a->file, "Campaign file (TOML)")->required();
  plan->add_option("-o,--out", a->out, "Campaign folder to create")->required();
  plan->callback([a, &ctx] {
    refuse_stdout_folder(a->out, "campaign plan");
    VerboseTimer timer(ctx, "campaign plan", "plan " + a->file);
    const campaign::Campaign c = campaign::read_campaign(a->file);
    const campaign::PlanResult r = campaign::plan_campaign(c, a->out);
    for (const auto& w : r.warnings) ctx.warn(w);
    ctx.report() << (r.already_planned ? "already planned: " : "planned: ") << r.cases << " cases in " << a->out
              << " (input hash " << r.input_hash << ")\n";
  });

  CLI::App* run = top->add_subcommand("run", "Run every case that is not done (resumes a killed campaign)");
  run->add_option("dir", a->dir, "Campaign folder (from 'campaign plan')")->required();
  run->add_option("--jobs", a->jobs, "Cases at once (local); slurm: at most this many array tasks at once (%K)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  run->add_option("--threads", a->threads, "ccx threads per case (default 1)")->check(CLI::Range(1, 1024));
  run->add_option("--executor", a->executor, "local (default) or slurm")->check(CLI::IsMember({"local", "slurm"}));
  run->add_option("--cpus-per-task", a->cpus_per_task, "slurm: CPUs per array task, the ccx threads (default: --threads)")
      ->check(CLI::Range(1, 1024));
  run->add_option("--sbatch-option", a->sbatch,
                  "slurm: an extra sbatch option, e.g. --partition=short (repeatable; one argument of sbatch's command line)")
      ->allow_extra_args(false);
  run->add_option("--sbatch-timeout-s", a->sbatch_timeout_s,
                  "slurm: seconds one sbatch may take before it is stopped (default 120)")
      ->check(CLI::Range(1e-3, campaign::kMaxSbatchTimeoutS));
  run->add_flag("--dry-run", a->dry_run, "slurm: write campaign.sbatch, do not submit");
  run->callback([a, run, &ctx] {
    VerboseTimer timer(ctx, "campaign run", "cases of " + a->dir);
    if (a->executor == "slurm") {
      campaign::SlurmOptions o;
      o.max_parallel = run->count("--jobs") > 0 ? a->jobs : 0;  // no --jobs: no %K limit
      o.cpus_per_task = a->cpus_per_task > 0 ? a->cpus_per_task : a->threads;
      o.sbatch_options = a->sbatch;
      o.sbatch_timeout_s = a->sbatch_timeout_s;
      o.executable = self_executable();
      const campaign::SlurmScripts scripts = campaign::write_sbatch(a->dir, o);
      std::string names;
      for (const auto& arr : scripts.arrays) names += (names.empty() ? "" : ", ") + arr.script.string();
      if (a->dry_run) {
        ctx.report() << "wrote " << names << " and " << scripts.collect_script.string() << " (not submitted: "
                  << scripts.arrays.size() << " job array(s), MaxArraySize " << scripts.max_array_size
                  << "); submit them with:\n";
        for (const auto& line : campaign::sbatch_commands(a->dir, scripts, o)) ctx.report() << line << "\n";
        return;
      }
      const campaign::SlurmSubmission sub = campaign::submit_sbatch(a->dir, scripts, o);
      for (std::size_t i = 0; i < sub.array_jobs.size(); ++i) {
        const campaign::SlurmArray& arr = scripts.arrays[i];
        ctx.report() << "submitted job " << sub.array_jobs[i] << " (" << arr.script.string() << ": " << arr.tasks
                  << " array task(s), cases " << arr.first_case << " ... " << arr.last_case << ")\n";
      }
      std::string after;
      for (const auto& j : sub.array_jobs) after += (after.empty() ? "" : ", ") + j;
      ctx.report() << "submitted job " << sub.collect_job << " (" << scripts.collect_script.string()
                << ": 'campaign collect' after job(s) " << after << "); follow them with 'impactdeck campaign status "
                << a->dir << "'\n";
      return;
    }
    if (a->dry_run || a->cpus_per_task > 0 || !a->sbatch.empty() || run->count("--sbatch-timeout-s") > 0) {
      throw UsageError("--dry-run, --cpus-per-task, --sbatch-option and --sbatch-timeout-s need --executor slurm");
    }
    campaign::LocalOptions o;
    o.jobs = a->jobs;
    o.ccx_threads = a->threads;
    o.executable = self_executable();
    o.progress_bar = !ctx.quiet;
    const campaign::RunSummary s = campaign::run_local(a->dir, o);
    ctx.report() << "campaign: " << s.total << " cases: " << s.done << " run now, " << s.skipped << " already done, "
              << s.failed << " failed";
    if (s.checks_failed) ctx.report() << ", " << s.checks_failed << " with a failed self-check";
    if (s.other) ctx.report() << ", " << s.other << " not run (locked by another process)";
    ctx.report() << "\n";
    if (s.failed) {  // the cases by their folders; each folder's failure.json says why
      const fs::path dir = fs::absolute(a->dir).lexically_normal();
      std::string list;
      for (std::size_t i = 0; i < s.failed_ids.size() && i < 10; ++i) list += (i ? ", " : "") + std::to_string(s.failed_ids[i]);
      if (s.failed_ids.size() > 10) list += ", ...";
      std::cerr << "impactdeck: error: "
                << InputError::compose((dir / "cases" / std::to_string(s.failed_ids.front())).string(), "failure.json",
                                       std::to_string(s.failed) + " of " + std::to_string(s.total) +
                                           " case(s) failed (cases " + list + "; the reasons: 'impactdeck campaign status " +
                                           dir.string() + "')")
                << "\n";
    }
    ctx.exit_code = s.exit_code();
  });

  CLI::App* one = top->add_subcommand("run-case", "Run one case (idempotent: a done case is not run again)");
  one->add_option("dir", a->dir, "Campaign folder")->required();
  one->add_option("id", a->id, "Case id (0 ... N-1)")->required();
  one->add_option("--threads", a->threads, "ccx threads (default 1)")->check(CLI::Range(1, 1024));
  one->callback([a, &ctx] {
    VerboseTimer timer(ctx, "campaign run-case", "case " + std::to_string(a->id));
    const campaign::CaseOutcome o = campaign::run_case(a->dir, a->id, a->threads, ctx.progress());
    if (o.already_done) {
      ctx.report() << "case " << a->id << ": already done\n";
    } else if (o.state == campaign::CaseState::done) {
      ctx.report() << "case " << a->id << ": done" << (o.checks_passed ? "" : " (a self-check failed)") << "\n";
    } else {
      std::cerr << "impactdeck: error: case " << a->id << ": " << o.message << "\n";
    }
    ctx.exit_code = o.exit_code;
  });

  CLI::App* status = top->add_subcommand("status", "Case states (and squeue's view of the campaign's jobs)");
  status->add_option("dir", a->dir, "Campaign folder")->required();
  status->add_flag("--json", a->json, "Print one JSON document on stdout (keys: docs/cli.md)");
  status->callback([a, &ctx] {
    const std::string text = campaign::status_report(a->dir, a->json);
    if (a->json) write_stdout(text);  // data asked for: printed under -q too
    else ctx.report() << text;
  });

  CLI::App* cancel = top->add_subcommand("cancel", "scancel the campaign's Slurm jobs (those in DIR/slurm/jobs.txt)");
  cancel->add_option("dir", a->dir, "Campaign folder")->required();
  cancel->callback([a, &ctx] {
    const std::vector<std::string> ids = campaign::cancel_jobs(a->dir);
    if (ids.empty()) {
      ctx.report() << "no Slurm job recorded for " << a->dir << ": nothing to cancel\n";
      return;
    }
    std::string list;
    for (const auto& i : ids) list += (list.empty() ? "" : " ") + i;
    ctx.report() << "cancelled job(s) " << list << "\n";
  });

  CLI::App* coll = top->add_subcommand("collect", "Table (CSV, JSON) of every case, the worst case, the map");
  coll->add_option("dir", a->dir, "Campaign folder")->required();
  coll->add_flag("--json", a->json, "Print one JSON document on stdout (keys: docs/cli.md)");
  coll->callback([a, &ctx] {
    VerboseTimer timer(ctx, "campaign collect", "collect " + a->dir);
    if (a->json) {
      // The document goes to stdout before the commit: a stdout that fails rolls the collect back.
      check_stdout_writable();
      campaign::collect(a->dir, [](const campaign::CollectResult& r) { write_stdout(campaign::collect_json(r)); });
      return;
    }
    const campaign::CollectResult r = campaign::collect(a->dir);
    ctx.report() << "collected " << r.done << " done, " << r.failed << " failed, " << r.pending << " pending: "
              << r.csv.string() << ", " << r.json.string() << "\n";
    if (r.worst_id) ctx.report() << "worst case: " << *r.worst_id << " (copied to " << r.worst_case->string() << ")\n";
    if (r.map_svg) ctx.report() << "map: " << r.map_svg->string() << ", " << r.map_vtp->string() << "\n";
    ctx.report() << "report: " << r.report_html.string() << "\n";
  });
}

}  // namespace impactdeck::cli
