// One case of a campaign: its lock, its state, and `campaign run-case`.

#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"
#include "detail.hpp"

namespace impactdeck::campaign {
namespace fs = std::filesystem;

const char* to_string(CaseState s) {
  switch (s) {
    case CaseState::planned: return "planned";
    case CaseState::running: return "running";
    case CaseState::done: return "done";
    case CaseState::failed: return "failed";
  }
  return "?";
}

fs::path case_folder(const fs::path& dir, std::size_t id) { return dir / "cases" / std::to_string(id); }

std::size_t case_count(const fs::path& dir) { return detail::read_plan(dir).cases.size(); }

CaseState case_state(const fs::path& dir, std::size_t id) {
  const fs::path rel = fs::path("cases") / std::to_string(id);
  if (!detail::check_inside(dir, rel, detail::Kind::folder)) return CaseState::planned;
  if (detail::check_inside(dir, rel / "result.json", detail::Kind::file)) return CaseState::done;
  if (detail::check_inside(dir, rel / "failure.json", detail::Kind::file)) return CaseState::failed;
  if (detail::FileLock::probe_locked(dir / rel / ".lock")) return CaseState::running;
  return CaseState::planned;
}

void refresh_states(const fs::path& dir) {
  detail::FileLock lock(dir / ".campaign.lock", /*wait=*/true);
  detail::Plan plan = detail::read_plan(dir);
  for (auto& c : plan.doc["cases"]) c["state"] = to_string(case_state(plan.dir, c["id"].get<std::size_t>()));
  write_file_atomically(plan.file, plan.doc.dump(2) + "\n");
}

CaseOutcome run_case(const fs::path& dir_in, std::size_t id, int ccx_threads, std::ostream* progress) {
  const detail::Plan plan = detail::read_plan(dir_in);
  const fs::path& dir = plan.dir;
  if (id >= plan.cases.size()) {
    throw InputError(dir.string(), "case " + std::to_string(id),
                     "no such case (the campaign has " + std::to_string(plan.cases.size()) + ", ids 0 to " +
                         std::to_string(plan.cases.empty() ? 0 : plan.cases.size() - 1) + ")");
  }
  // Everything the case touches is checked before anything is done: the folder and each entry
  // in it a real folder or file, no symbolic link anywhere below the campaign folder.
  const fs::path rel = fs::path("cases") / std::to_string(id);
  const fs::path folder = dir / rel;
  if (!detail::check_inside(dir, rel, detail::Kind::folder)) {
    throw InputError(folder.string(), "folder", "missing: the plan's case folder is gone");
  }
  for (const char* name : {".lock", "result.json", "failure.json", "scene.toml", "run.log"})
    detail::check_inside(dir, rel / name, detail::Kind::file);
  detail::check_inside(dir, rel / "out", detail::Kind::folder);
  detail::FileLock lock(folder / ".lock", /*wait=*/false);
  if (!lock.locked()) {
    throw InputError(folder.string(), "lock", "the case is being run by another process (its folder is locked)");
  }
  CaseOutcome out;
  std::error_code ec;
  if (detail::check_inside(dir, rel / "result.json", detail::Kind::file)) {  // published: done, idempotently
    out.state = CaseState::done;
    out.already_done = true;
    const nlohmann::json result = detail::read_result(dir, id);
    out.checks_passed = result.value("all_checks_passed", true);
    out.exit_code = out.checks_passed ? 0 : static_cast<int>(ExitCode::check_failed);
    return out;
  }
  fs::remove(folder / "failure.json", ec);
  const fs::path out_dir = folder / "out";
  fs::remove_all(out_dir, ec);  // a killed run's leftovers (remove_all never follows a link)
  fs::create_directory(out_dir, ec);
  auto fail = [&](int code, const std::string& reason) {
    const nlohmann::json f = {{"id", id}, {"state", "failed"}, {"exit_code", code}, {"reason", reason}};
    write_file_atomically(folder / "failure.json", f.dump(2) + "\n");
    out.state = CaseState::failed;
    out.exit_code = code;
    out.message = reason;
  };
  try {
    const std::string text = read_input_file(folder / "scene.toml", "scene file", kMaxSceneBytes);
    if (fnv1a64_hex(text) != plan.cases[id].scene_hash) {
      throw InputError((folder / "scene.toml").string(), "file", "changed since the campaign was planned (hash differs)");
    }
    const scene::Scene sc = scene::load_scene(folder / "scene.toml");
    scene::RunOptions opt;
    opt.out_dir = out_dir;
    opt.progress = progress;
    opt.solver_threads = ccx_threads;
    const scene::RunReport rep = scene::run_scene(sc, opt);
    const nlohmann::json result = scene::to_json(sc, rep);
    write_file_atomically(folder / "result.json", result.dump(2) + "\n");  // the case is done now
    out.state = CaseState::done;
    out.checks_passed = rep.all_checks_passed();
    out.exit_code = out.checks_passed ? 0 : static_cast<int>(ExitCode::check_failed);
  } catch (const Error& e) {
    fail(static_cast<int>(e.code()), e.what());
  } catch (const std::exception& e) {
    fail(static_cast<int>(ExitCode::internal_error), std::string("internal error: ") + e.what());
  }
  return out;
}

}  // namespace impactdeck::campaign
