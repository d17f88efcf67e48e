// One case of a campaign: its lock, its state, and `campaign run-case`.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

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

namespace detail {

FileLock::FileLock(const fs::path& path, bool wait) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path.string(), "lock", "cannot be opened");
  if (wait) {
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno != EINTR) break;
    }
    locked_ = true;
    return;
  }
  // A few tries: `campaign status` probes locks for an instant; a real writer holds it for minutes.
  for (int i = 0; i < 40 && !locked_; ++i) {
    if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) {
      locked_ = true;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
}

FileLock::~FileLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

bool FileLock::probe_locked(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0;
  ::close(fd);
  return held;
}

std::string read_text(const fs::path& p) {
  // A regular file only (a FIFO in a case folder would block `campaign collect`), within a
  // quarter of the free memory.
  std::error_code ec;
  if (!fs::exists(p, ec)) throw InputError(p.string(), "file", "cannot be opened (missing or unreadable)");
  return read_input_file(p, "campaign file", available_memory_bytes() / 4, "a quarter of the free memory");
}

nlohmann::json read_json(const fs::path& p) {
  try {
    return nlohmann::json::parse(read_text(p));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(p.string(), "file", std::string("is not valid JSON: ") + e.what());
  }
}

}  // namespace detail

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

std::size_t case_count(const fs::path& dir) {
  const nlohmann::json j = detail::read_json(campaign_json(dir));
  if (!j.contains("cases") || !j["cases"].is_array()) {
    throw InputError((dir / "campaign.json").string(), "key 'cases'", "missing: not a campaign plan");
  }
  return j["cases"].size();
}

CaseState case_state(const fs::path& dir, std::size_t id) {
  const fs::path f = case_folder(dir, id);
  std::error_code ec;
  if (fs::is_regular_file(f / "result.json", ec)) return CaseState::done;
  if (fs::is_regular_file(f / "failure.json", ec)) return CaseState::failed;
  if (detail::FileLock::probe_locked(f / ".lock")) return CaseState::running;
  return CaseState::planned;
}

void refresh_states(const fs::path& dir) {
  detail::FileLock lock(dir / ".campaign.lock", /*wait=*/true);
  nlohmann::json j = detail::read_json(campaign_json(dir));
  for (auto& c : j["cases"]) c["state"] = to_string(case_state(dir, c.value("id", std::size_t{0})));
  write_file_atomically(dir / "campaign.json", j.dump(2) + "\n");
}

CaseOutcome run_case(const fs::path& dir_in, std::size_t id, int ccx_threads, std::ostream* progress) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  const nlohmann::json plan = detail::read_json(campaign_json(dir));
  const auto& cases = plan.at("cases");
  if (id >= cases.size()) {
    throw InputError(dir.string(), "case " + std::to_string(id),
                     "no such case (the campaign has " + std::to_string(cases.size()) + ", ids 0 to " +
                         std::to_string(cases.size() == 0 ? 0 : cases.size() - 1) + ")");
  }
  const fs::path folder = case_folder(dir, id);
  detail::FileLock lock(folder / ".lock", /*wait=*/false);
  if (!lock.locked()) {
    throw InputError(folder.string(), "lock", "the case is being run by another process (its folder is locked)");
  }
  CaseOutcome out;
  std::error_code ec;
  if (fs::is_regular_file(folder / "result.json", ec)) {  // published: done, idempotently
    out.state = CaseState::done;
    out.already_done = true;
    out.checks_passed = detail::read_json(folder / "result.json").value("all_checks_passed", true);
    out.exit_code = out.checks_passed ? 0 : static_cast<int>(ExitCode::check_failed);
    return out;
  }
  fs::remove(folder / "failure.json", ec);
  const fs::path out_dir = folder / "out";
  fs::remove_all(out_dir, ec);  // a killed run's leftovers
  fs::create_directories(out_dir, ec);
  auto fail = [&](int code, const std::string& reason) {
    const nlohmann::json f = {{"id", id}, {"state", "failed"}, {"exit_code", code}, {"reason", reason}};
    write_file_atomically(folder / "failure.json", f.dump(2) + "\n");
    out.state = CaseState::failed;
    out.exit_code = code;
    out.message = reason;
  };
  try {
    const std::string text = detail::read_text(folder / "scene.toml");
    if (fnv1a64_hex(text) != cases[id].value("scene_hash", "")) {
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
