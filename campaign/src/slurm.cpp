// The Slurm executor: the [slurm] settings (validated data), job arrays split to the cluster's
// MaxArraySize, their submission with the dependent collect job, and `campaign cancel`.
// Everything reaches sbatch, scontrol and scancel as an argument vector, never through a shell.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "detail.hpp"

namespace impactdeck::campaign {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr std::uintmax_t kMaxJobsBytes = std::uintmax_t{1} << 20;  // slurm/jobs.txt
constexpr double kScontrolTimeoutS = 10;

bool is_digits(const std::string& s) { return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos; }

// A Slurm name: letters, digits, '_', '-', '.', at most 64 characters.
bool is_name(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (const char c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') return false;
  }
  return s[0] != '-';
}

// Slurm's time forms: M, M:S, H:M:S, D-H, D-H:M, D-H:M:S; every field digits, the leading one at
// most 8 digits, the others at most 2 and below 60 (24 for hours after days); not zero.
bool is_slurm_time(const std::string& s) {
  std::string rest = s;
  std::vector<std::string> f;
  const auto dash = rest.find('-');
  std::string days;
  if (dash != std::string::npos) {
    days = rest.substr(0, dash);
    rest.erase(0, dash + 1);
    if (!is_digits(days) || days.size() > 8) return false;
  }
  std::size_t start = 0;
  for (;;) {
    const auto colon = rest.find(':', start);
    f.push_back(rest.substr(start, colon == std::string::npos ? std::string::npos : colon - start));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  if (f.size() > 3) return false;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const bool leading = i == 0 && days.empty();
    if (!is_digits(f[i]) || f[i].size() > (leading ? 8u : 2u)) return false;
    if (!leading && std::stoul(f[i]) >= (i == 0 ? 24u : 60u)) return false;
  }
  bool nonzero = !days.empty() && std::stoul(days) > 0;
  for (const auto& x : f) nonzero = nonzero || std::stoul(x) > 0;
  return nonzero;
}

std::string job_list(const std::vector<std::string>& ids, const char* sep) {
  std::string s;
  for (const auto& i : ids) s += (s.empty() ? "" : sep) + i;
  return s;
}

// The #SBATCH lines of the [slurm] values (each validated data) and the setup lines.
void write_settings(std::ostream& s, const SlurmSettings& st, bool with_setup) {
  if (!st.time.empty()) s << "#SBATCH --time=" << st.time << "\n";
  if (!st.partition.empty()) s << "#SBATCH --partition=" << st.partition << "\n";
  if (!st.account.empty()) s << "#SBATCH --account=" << st.account << "\n";
  if (!st.qos.empty()) s << "#SBATCH --qos=" << st.qos << "\n";
  if (!st.mem.empty()) s << "#SBATCH --mem=" << st.mem << "\n";
  if (with_setup && !st.setup.empty()) {
    s << "# [slurm] setup of the campaign file: the user's own shell lines, verbatim\n";
    for (const auto& line : st.setup) s << line << "\n";
    s << "# end of setup\n";
  }
}

void write_script(const fs::path& dir, const fs::path& name, const std::string& text) {
  detail::check_inside(dir, name, detail::Kind::file);  // a link there is refused
  const fs::path script = dir / name;
  write_file_atomically(script, text);
  std::error_code ec;
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add | fs::perm_options::nofollow, ec);
}

// The sbatch command line that submits a script: everything taken from data (the campaign
// folder, the user's options) is an argument of its own, never a line of the script.
std::vector<std::string> sbatch_argv(const fs::path& dir, const fs::path& script, const SlurmOptions& o,
                                     const std::string& dependency) {
  std::vector<std::string> argv = {"sbatch", "--parsable", "--chdir=" + dir.string()};
  if (!dependency.empty()) argv.push_back("--dependency=afterany:" + dependency);
  argv.insert(argv.end(), o.sbatch_options.begin(), o.sbatch_options.end());
  argv.push_back(script.string());
  return argv;
}

std::string quoted(const std::vector<std::string>& argv) {
  std::string line;
  for (const auto& a : argv) line += (line.empty() ? "" : " ") + detail::sh_quote(a);
  return line;
}

void check_sbatch_options(const std::vector<std::string>& options) {
  for (std::size_t i = 0; i < options.size(); ++i) {
    const std::string& o = options[i];
    const std::string place = "value " + std::to_string(i + 1) + " '" + o + "'";
    if (o.size() < 2 || o[0] != '-') {
      throw InputError("--sbatch-option", place, "must be one sbatch option such as --partition=short");
    }
    for (const char c : o) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        throw InputError("--sbatch-option", place, "holds a control character (a newline, a tab, ...): refused");
      }
    }
  }
}

// One sbatch run; the job id it prints, or InputError naming the script.
std::string sbatch(const std::vector<std::string>& argv, const fs::path& script, double timeout_s) {
  const detail::ProgramRun run = detail::run_program(argv, /*merge_stderr=*/true, timeout_s);
  if (run.spawn_error != 0) {
    throw InputError("sbatch", "submit", std::string("cannot run 'sbatch': ") + std::strerror(run.spawn_error) +
                                             " (is Slurm installed here? it must be on the PATH)");
  }
  if (run.timed_out) {
    std::ostringstream s;
    s << "sbatch did not answer within " << timeout_s
      << " s (--sbatch-timeout-s) and was stopped; the job may still have been submitted: check squeue";
    throw InputError(script.string(), "sbatch", s.str());
  }
  const std::string id = run.output.substr(0, run.output.find_first_of(";\n"));
  if (run.exit_code != 0 || id.size() > 20 || !is_digits(id)) {
    std::string msg = run.output.substr(0, 2000);
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
    for (char& c : msg) c = c == '\n' ? ' ' : c;
    throw InputError(script.string(), "sbatch",
                     (run.exit_code != 0 ? "sbatch refused it (exit " + std::to_string(run.exit_code) + ")"
                                         : std::string("sbatch printed no job id")) +
                         ": " + msg);
  }
  return id;
}

void record_job(const fs::path& dir, const std::string& id) {
  detail::FileLock lock(dir / ".campaign.lock", /*wait=*/true);
  detail::job_ids(dir);  // still sound under the lock
  const fs::path jobs = dir / "slurm" / "jobs.txt";
  std::string text;
  if (detail::check_inside(dir, fs::path("slurm") / "jobs.txt", detail::Kind::file)) {
    text = read_input_file(jobs, "job list", kMaxJobsBytes);
  }
  write_file_atomically(jobs, text + id + "\n");
}

}  // namespace

std::string slurm_value_error(const std::string& key, const std::string& v) {
  if (key == "setup") {
    if (v.find('\0') != std::string::npos) return "holds a NUL character: refused";
    if (v.find('\r') != std::string::npos) return "holds a carriage return (CR): refused";
    return {};
  }
  if (key == "partition") {
    if (v.size() > 256) return "must be at most 256 characters";
    std::size_t start = 0;
    for (;;) {
      const auto comma = v.find(',', start);
      if (!is_name(v.substr(start, comma == std::string::npos ? std::string::npos : comma - start))) {
        return "must be a partition name (letters, digits, '_', '-', '.'; at most 64, not starting with '-'), "
               "or several separated by commas";
      }
      if (comma == std::string::npos) return {};
      start = comma + 1;
    }
  }
  if (key == "account" || key == "qos") {
    if (!is_name(v)) return "must be a Slurm " + key + " name (letters, digits, '_', '-', '.'; at most 64, not starting with '-')";
    return {};
  }
  if (key == "time") {
    if (!is_slurm_time(v)) {
      return "must be a Slurm time limit above zero: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS "
             "(e.g. 90 or \"1-12:00:00\")";
    }
    return {};
  }
  if (key == "mem") {
    const std::size_t digits = v.find_first_not_of("0123456789");
    const std::string number = v.substr(0, digits);
    const std::string unit = digits == std::string::npos ? std::string() : v.substr(digits);
    if (number.empty() || number.size() > 12 || (!unit.empty() && (unit.size() != 1 || std::string("KMGT").find(unit) == std::string::npos))) {
      return "must be a memory size: digits with an optional unit K, M, G or T (e.g. 4000 or \"16G\"; no unit: megabytes)";
    }
    return {};
  }
  return "unknown key";
}

double default_task_minutes(bool runs_ccx, std::size_t cases_per_task) {
  return (runs_ccx ? kCaseMinutesCcx : kCaseMinutesNoCcx) * static_cast<double>(cases_per_task) * kTimeSafetyFactor;
}

std::string slurm_time_text(double minutes) {
  const auto m = static_cast<unsigned long long>(std::ceil(std::max(1.0, minutes)));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%llu-%02llu:%02llu:00", m / 1440, (m / 60) % 24, m % 60);
  return buf;
}

namespace detail {

json slurm_json(const SlurmSettings& s) {
  json j = {{"time", s.time}, {"time_given", s.time_given}, {"setup", s.setup}, {"cases_per_task", s.cases_per_task}};
  if (!s.partition.empty()) j["partition"] = s.partition;
  if (!s.account.empty()) j["account"] = s.account;
  if (!s.qos.empty()) j["qos"] = s.qos;
  if (!s.mem.empty()) j["mem"] = s.mem;
  return j;
}

SlurmSettings slurm_from_json(const json& j, const std::string& file) {
  auto bad = [&](const std::string& key, const std::string& reason) {
    throw InputError(file, "key 'slurm." + key + "'", reason);
  };
  if (!j.is_object()) throw InputError(file, "key 'slurm'", "must be an object");
  SlurmSettings s;
  for (const char* key : {"partition", "account", "qos", "time", "mem"}) {
    const auto it = j.find(key);
    if (it == j.end()) continue;
    if (!it->is_string()) bad(key, "must be a string");
    const std::string v = it->get<std::string>();
    if (const std::string why = slurm_value_error(key, v); !why.empty()) bad(key, why);
    const std::string k = key;
    (k == "partition" ? s.partition : k == "account" ? s.account : k == "qos" ? s.qos : k == "time" ? s.time : s.mem) = v;
  }
  if (const auto it = j.find("time_given"); it != j.end()) {
    if (!it->is_boolean()) bad("time_given", "must be true or false");
    s.time_given = it->get<bool>();
  }
  if (const auto it = j.find("cases_per_task"); it != j.end()) {
    if (!it->is_number_unsigned() || it->get<std::size_t>() < 1 || it->get<std::size_t>() > kMaxCasesPerTask) {
      bad("cases_per_task", "must be a whole number in [1, " + std::to_string(kMaxCasesPerTask) + "]");
    }
    s.cases_per_task = it->get<std::size_t>();
  }
  if (const auto it = j.find("setup"); it != j.end()) {
    if (!it->is_array()) bad("setup", "must be a list of shell lines (strings)");
    for (std::size_t i = 0; i < it->size(); ++i) {
      const json& e = (*it)[i];
      const std::string k = "setup[" + std::to_string(i) + "]";
      if (!e.is_string()) bad(k, "must be a shell line (string)");
      if (const std::string why = slurm_value_error("setup", e.get<std::string>()); !why.empty()) bad(k, why);
      s.setup.push_back(e.get<std::string>());
    }
  }
  return s;
}

std::vector<std::string> job_ids(const fs::path& dir) {
  std::vector<std::string> ids;
  const fs::path rel = fs::path("slurm") / "jobs.txt";
  if (!check_inside(dir, rel, Kind::file)) return ids;
  const fs::path file = dir / rel;
  std::istringstream in(read_input_file(file, "job list", kMaxJobsBytes));
  std::size_t line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (line.empty()) continue;
    if (line.size() > 20 || !is_digits(line)) {
      throw InputError(file.string(), "line " + std::to_string(line_no),
                       "'" + line + "' is not a Slurm job id (digits only): the file was not written by impactdeck");
    }
    ids.push_back(line);
  }
  return ids;
}

}  // namespace detail

std::size_t cluster_max_array_size() {
  const detail::ProgramRun r = detail::run_program({"scontrol", "show", "config"}, false, kScontrolTimeoutS);
  if (r.spawn_error != 0 || r.exit_code != 0 || r.timed_out) return kDefaultMaxArraySize;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("MaxArraySize", 0) != 0) continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) break;
    std::string v = line.substr(eq + 1);
    v.erase(0, v.find_first_not_of(' '));
    while (!v.empty() && (v.back() == ' ' || v.back() == '\r')) v.pop_back();
    if (!is_digits(v) || v.size() > 9) break;
    return std::stoul(v);
  }
  return kDefaultMaxArraySize;
}

SlurmScripts write_sbatch(const fs::path& dir_in, const SlurmOptions& o) {
  check_sbatch_options(o.sbatch_options);
  const detail::Plan plan = detail::read_plan(dir_in);
  const fs::path& dir = plan.dir;
  const std::size_t n = plan.cases.size();
  if (n == 0) throw InputError(plan.file.string(), "key 'cases'", "the campaign has no cases");
  SlurmScripts out;
  out.max_array_size = o.max_array_size > 0 ? o.max_array_size : cluster_max_array_size();
  if (out.max_array_size == 0) {
    throw InputError(plan.file.string(), "scontrol show config: MaxArraySize",
                     "is 0: job arrays are disabled on this cluster, so the campaign '" + dir.string() +
                         "' cannot be submitted as job arrays (run it here with 'impactdeck campaign run " +
                         dir.string() + "', or ask the cluster's administrators for MaxArraySize > 0)");
  }
  const std::size_t cpt = plan.slurm.cases_per_task;
  out.cases_per_task = cpt;
  const std::size_t tasks = (n + cpt - 1) / cpt;
  const std::size_t per_array = std::max<std::size_t>(1, out.max_array_size - 1);
  const std::size_t arrays = (tasks + per_array - 1) / per_array;
  const fs::path exe = fs::absolute(o.executable);
  if (!detail::check_inside(dir, "slurm", detail::Kind::folder)) detail::make_folder(dir / "slurm");
  const std::string qdir = detail::sh_quote(dir.string());
  for (std::size_t k = 0; k < arrays; ++k) {
    SlurmArray a;
    a.first_task = k * per_array;
    a.tasks = std::min(per_array, tasks - a.first_task);
    a.first_case = a.first_task * cpt;
    a.last_case = std::min(n, (a.first_task + a.tasks) * cpt) - 1;
    const fs::path name = k == 0 ? fs::path("campaign.sbatch") : fs::path("campaign." + std::to_string(k) + ".sbatch");
    a.script = dir / name;
    // Only constants, validated [slurm] values and sh-quoted paths: the folder and the user's
    // options reach sbatch as arguments of its own (sbatch_argv), never as #SBATCH lines, whose
    // text no quoting protects. The setup lines are the user's own shell code.
    std::ostringstream s;
    s << "#!/bin/sh\n"
      << "# impactdeck campaign (docs/campaign-format.md): job array " << k + 1 << " of " << arrays << ", tasks "
      << a.first_task << " ... " << a.first_task + a.tasks - 1 << " of the campaign, cases " << a.first_case
      << " ... " << a.last_case << ",\n# " << cpt << " case(s) per task in sequence. Each case is idempotent: a case with a\n"
      << "# published result.json is not run again. Submit it with\n"
      << "# 'impactdeck campaign run DIR --executor slurm', or as 'campaign run --dry-run' prints.\n"
      << "#SBATCH --job-name=impactdeck-campaign\n"
      << "#SBATCH --array=0-" << a.tasks - 1;
    if (o.max_parallel > 0) s << "%" << o.max_parallel;
    s << "\n#SBATCH --cpus-per-task=" << o.cpus_per_task << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --output=slurm/%A_%a.out\n";  // relative to --chdir, the campaign folder
    write_settings(s, plan.slurm, true);
    s << "cd " << qdir << " || exit 3\n"
      << "task=${SLURM_ARRAY_TASK_ID:-}\n"
      << "case $task in ''|*[!0-9]*|0?*|??????????*)\n"
      << "  echo \"impactdeck: error: SLURM_ARRAY_TASK_ID '$task' is not an array task number\" >&2; exit 3 ;;\n"
      << "esac\n"
      << "id=$(( (" << a.first_task << " + task) * " << cpt << " ))\n"
      << "end=$(( id + " << cpt << " )); [ \"$end\" -le " << n << " ] || end=" << n << "\n"
      << "rc=0\n"
      << "while [ \"$id\" -lt \"$end\" ]; do\n"
      << "  " << detail::sh_quote(exe.string()) << " campaign run-case " << qdir << " \"$id\" --threads "
      << o.cpus_per_task << " || rc=$?\n"
      << "  id=$(( id + 1 ))\n"
      << "done\n"
      << "exit \"$rc\"\n";
    write_script(dir, name, s.str());
    out.arrays.push_back(a);
  }
  std::ostringstream c;
  c << "#!/bin/sh\n"
    << "# impactdeck campaign: 'campaign collect' once the arrays are over (submitted with\n"
    << "# --dependency=afterany:THEIR_JOB_IDS by 'impactdeck campaign run DIR --executor slurm').\n"
    << "#SBATCH --job-name=impactdeck-collect\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --output=slurm/collect_%j.out\n";
  write_settings(c, plan.slurm, true);
  c << "cd " << qdir << " || exit 3\n"
    << "exec " << detail::sh_quote(exe.string()) << " campaign collect " << qdir << "\n";
  write_script(dir, "collect.sbatch", c.str());
  out.collect_script = dir / "collect.sbatch";
  return out;
}

std::vector<std::string> sbatch_commands(const fs::path& dir_in, const SlurmScripts& sc, const SlurmOptions& o) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  // A shell script: each array's job id kept in a variable (sbatch --parsable prints ID or
  // ID;CLUSTER), the collect job depending on them all. Data appears only inside sh quotes.
  std::vector<std::string> lines;
  std::string dependency;
  for (std::size_t k = 0; k < sc.arrays.size(); ++k) {
    const std::string var = "job" + std::to_string(k);
    lines.push_back(var + "=$(" + quoted(sbatch_argv(dir, sc.arrays[k].script, o, "")) + ") || exit");
    dependency += ":${" + var + "%%;*}";
  }
  const std::vector<std::string> collect = sbatch_argv(dir, sc.collect_script, o, "");
  std::string line;
  for (std::size_t i = 0; i < collect.size(); ++i) {  // sbatch --parsable --chdir=DIR, then the dependency
    line += (line.empty() ? "" : " ") + detail::sh_quote(collect[i]);
    if (i == 2) line += " \"--dependency=afterany" + dependency + "\"";
  }
  lines.push_back(line);
  return lines;
}

SlurmSubmission submit_sbatch(const fs::path& dir_in, const SlurmScripts& sc, const SlurmOptions& o) {
  check_sbatch_options(o.sbatch_options);
  if (!(o.sbatch_timeout_s > 0 && o.sbatch_timeout_s <= kMaxSbatchTimeoutS)) {
    throw UsageError("--sbatch-timeout-s must lie in (0, " + std::to_string(static_cast<int>(kMaxSbatchTimeoutS)) + "]");
  }
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  detail::job_ids(dir);  // the job list the ids are added to must be sound before anything is submitted
  SlurmSubmission r;
  for (const auto& a : sc.arrays) {
    r.array_jobs.push_back(sbatch(sbatch_argv(dir, a.script, o, ""), a.script, o.sbatch_timeout_s));
    record_job(dir, r.array_jobs.back());
  }
  r.collect_job = sbatch(sbatch_argv(dir, sc.collect_script, o, job_list(r.array_jobs, ":")), sc.collect_script,
                         o.sbatch_timeout_s);
  record_job(dir, r.collect_job);
  return r;
}

std::vector<std::string> cancel_jobs(const fs::path& dir_in) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  campaign_json(dir);  // a campaign folder
  const std::vector<std::string> ids = detail::job_ids(dir);
  if (ids.empty()) return ids;
  std::vector<std::string> argv = {"scancel"};
  argv.insert(argv.end(), ids.begin(), ids.end());
  const detail::ProgramRun run = detail::run_program(argv, /*merge_stderr=*/true, 60);
  if (run.spawn_error != 0) {
    throw InputError("scancel", "cancel", std::string("cannot run 'scancel': ") + std::strerror(run.spawn_error) +
                                              " (is Slurm installed here? it must be on the PATH)");
  }
  // A job that has already ended is not an error: the campaign is as cancelled as it can be.
  bool other_error = run.timed_out;
  std::istringstream lines(run.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("already completing or completed") == std::string::npos &&
        line.find("Invalid job id specified") == std::string::npos && line.find("error") != std::string::npos) {
      other_error = true;
    }
  }
  if (run.exit_code != 0 && (other_error || run.output.empty())) {
    std::string msg = run.output.substr(0, 2000);
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
    for (char& ch : msg) ch = ch == '\n' ? ' ' : ch;
    throw InputError((dir / "slurm" / "jobs.txt").string(), "scancel",
                     (run.timed_out ? std::string("scancel did not finish within 60 s")
                                    : "scancel failed (exit " + std::to_string(run.exit_code) + ")") +
                         ": " + msg);
  }
  return ids;
}

}  // namespace impactdeck::campaign
