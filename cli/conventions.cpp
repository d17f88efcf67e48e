#include "conventions.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <functional>
#include <iomanip>
#include <memory>
#include <iostream>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/version.hpp"

namespace impactdeck::cli {

void Context::warn(const std::string& text) const {
  if (!quiet) std::cerr << "impactdeck: warning: " << InputError::one_line(text) << "\n";
}

// Progress (lines, bars) goes to a terminal only: a log file or a pipe gets none.
std::ostream* Context::progress() const { return quiet || ::isatty(STDERR_FILENO) != 1 ? nullptr : &std::cerr; }

void Context::note(const std::string& command, const std::string& text) const {
  if (verbose) std::cerr << "impactdeck: " << command << ": " << InputError::one_line(text) << "\n";
}

std::ostream& Context::report() const {
  static std::ostream nowhere(nullptr);  // no buffer: every write is dropped
  return quiet ? nowhere : std::cout;
}

void write_stdout(const std::string& text) {
  struct sigaction ignore {}, old {};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ignore, &old);
  std::cout.flush();  // what went before (std::cout shares stdout's buffer: synced with stdio)
  errno = 0;
  const bool written = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
  int e = written ? 0 : errno;  // the first failure's reason
  const bool flushed = std::fflush(stdout) == 0;
  if (!flushed && e == 0) e = errno;
  const bool failed = !written || !flushed || std::ferror(stdout) || !std::cout;
  ::sigaction(SIGPIPE, &old, nullptr);
  if (failed) {
    throw InputError("stdout", "", std::string("write failed: ") +
                                       (e ? std::strerror(e) : "disk full, or the output was closed") +
                                       " (before the commit: the run was rolled back, nothing was published)");
  }
}

void refuse_stdout_folder(const std::string& out, const std::string& command) {
  if (out == kStdStream) {
    throw UsageError("-o -: '" + command + "' writes a folder of files, not one file: stdout cannot hold it (give a folder)");
  }
}

VerboseTimer::VerboseTimer(const Context& ctx, std::string command, std::string stage)
    : ctx_(ctx), command_(std::move(command)), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}

VerboseTimer::~VerboseTimer() {
  if (!ctx_.verbose) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::ostringstream t;
  t << stage_ << ": " << std::setprecision(3) << s << " s";
  ctx_.note(command_, t.str());
}

void check_stdout_writable() {
  std::cout.flush();
  if (::write(STDOUT_FILENO, "", 0) < 0) {
    throw InputError("stdout", "", std::string("write failed: ") + std::strerror(errno) +
                                       " (checked before the run: nothing was computed or written)");
  }
}

namespace {

bool visible(const CLI::App* a) { return !a->get_group().empty(); }

std::vector<CLI::App*> children(const CLI::App& app) {
  std::vector<CLI::App*> out;
  for (CLI::App* s : const_cast<CLI::App&>(app).get_subcommands([](CLI::App*) { return true; }))
    if (visible(s)) out.push_back(s);
  return out;
}

std::vector<const CLI::Option*> flags_of(const CLI::App& app) {
  std::vector<const CLI::Option*> out;
  for (const CLI::Option* o : app.get_options())
    if (o->nonpositional()) out.push_back(o);
  return out;
}

std::vector<std::string> flag_names(const CLI::Option& o) {
  std::vector<std::string> out;
  for (const auto& s : o.get_snames()) out.push_back("-" + s);
  for (const auto& l : o.get_lnames()) out.push_back("--" + l);
  return out;
}

std::string path_of(const CLI::App& app) {
  std::string p;
  // The root is "impactdeck" whatever argv[0] was (CLI11 names the root after it when parsing).
  for (const CLI::App* a = &app; a; a = a->get_parent())
    p = (a->get_parent() ? a->get_name() : std::string("impactdeck")) + (p.empty() ? "" : " " + p);
  return p;
}

// roff: backslashes escaped, a line never starts with a control character.
std::string roff(const std::string& text) {
  std::string s;
  for (char c : text) {
    if (c == '\\') s += "\\e";
    else if (c == '-') s += "\\-";
    else s += c;
  }
  if (!s.empty() && (s[0] == '.' || s[0] == '\'')) s = "\\&" + s;
  return s;
}

std::string positional_synopsis(const CLI::App& app) {
  std::string s;
  for (const CLI::Option* o : app.get_options()) {
    if (!o->get_positional()) continue;
    const std::string name = o->get_name();
    s += " " + (o->get_required() ? "\\fI" + roff(name) + "\\fR" : "[\\fI" + roff(name) + "\\fR]");
  }
  return s;
}

void man_command(const CLI::App& app, std::ostream& out) {
  const auto subs = children(app);
  if (app.get_parent()) {
    out << ".SS \"" << roff(path_of(app)) << (subs.empty() ? positional_synopsis(app) : " \\fICOMMAND\\fR")
        << (flags_of(app).empty() ? "" : " [\\fIOPTIONS\\fR]") << "\"\n"
        << roff(app.get_description()) << "\n";
    for (const CLI::Option* o : app.get_options()) {
      if (!o->get_positional()) continue;
      out << ".TP\n\\fI" << roff(o->get_name()) << "\\fR\n" << roff(o->get_description()) << "\n";
    }
    for (const CLI::Option* o : flags_of(app)) {
      std::string names;
      for (const auto& n : flag_names(*o)) names += (names.empty() ? "" : ", ") + ("\\fB" + roff(n) + "\\fR");
      if (o->get_type_size_max() > 0 && o->get_items_expected_max() > 0)
        names += " \\fI" + roff(o->get_type_name().empty() ? "VALUE" : o->get_type_name()) + "\\fR";
      out << ".TP\n" << names << "\n" << roff(o->get_description().empty() ? "Print help and exit" : o->get_description())
          << "\n";
    }
  }
  for (const CLI::App* s : subs) man_command(*s, out);
}

void completion_cases(const CLI::App& app, const std::string& path, std::ostream& out) {
  std::string subs, flags;
  for (const CLI::App* s : children(app)) subs += (subs.empty() ? "" : " ") + s->get_name();
  for (const CLI::Option* o : flags_of(app))
    for (const auto& n : flag_names(*o)) flags += (flags.empty() ? "" : " ") + n;
  out << "    \"" << path << "\") subs='" << subs << "'; flags='" << flags << "' ;;\n";
  for (const CLI::App* s : children(app)) completion_cases(*s, path + " " + s->get_name(), out);
}

void collect_paths(const CLI::App& app, const std::string& path, std::vector<std::string>& out) {
  for (const CLI::App* s : children(app)) {
    out.push_back(path + " " + s->get_name());
    collect_paths(*s, path + " " + s->get_name(), out);
  }
}

}  // namespace

void add_verbosity_flags(CLI::App& app, Context& ctx) {
  for (CLI::App* s : children(app)) {
    if (children(*s).empty()) {
      CLI::Option* q = s->add_flag("-q,--quiet", ctx.quiet,
                                   "Quiet: no progress and no warnings on stderr (errors only; warnings stay in the "
                                   "report and --json)");
      CLI::Option* v = s->add_flag("-v,--verbose", ctx.verbose,
                                   "Verbose: also the settings and each stage's wall time on stderr");
      q->excludes(v);
    }
    add_verbosity_flags(*s, ctx);
  }
}

std::string explain_command_line(CLI::App& app, const std::vector<std::string>& args) {
  const CLI::App* cur = &app;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--") return "";
    if (a.size() > 1 && a[0] == '-') {
      const std::string name = a.substr(0, a.find('='));
      const CLI::Option* match = nullptr;
      std::vector<std::string> names;
      for (const CLI::Option* o : cur->get_options()) {
        if (!o->nonpositional()) continue;
        for (const auto& n : flag_names(*o)) {
          names.push_back(n);
          if (n == name) match = o;
        }
      }
      if (!match) {
        if (name.size() > 1 && name[1] != '-') return "";  // short-flag clusters: left to CLI11's message
        return "unknown option '" + name + "' of '" + path_of(*cur) + "'" + did_you_mean(name, names);
      }
      if (a.find('=') == std::string::npos && match->get_type_size_max() > 0 && match->get_items_expected_max() > 0)
        ++i;  // its value
      continue;
    }
    const auto subs = children(*cur);
    const CLI::App* next = nullptr;
    std::vector<std::string> names;
    std::string list;
    for (const CLI::App* s : subs) {
      names.push_back(s->get_name());
      list += (list.empty() ? "" : ", ") + s->get_name();
      if (s->get_name() == a) next = s;
    }
    if (next) {
      cur = next;
    } else if (!subs.empty()) {
      return "unknown command '" + a + "' of '" + path_of(*cur) + "' (commands: " + list + ")" + did_you_mean(a, names);
    }
  }
  return "";
}

void write_man_page(const CLI::App& app, std::ostream& out) {
  out << ".\\\" Generated by `impactdeck man` from the command-line definition: do not edit.\n"
      << ".TH IMPACTDECK 1 \"\" \"impactdeck " << kVersion << "\" \"User Commands\"\n"
      << ".SH NAME\nimpactdeck \\- " << roff(app.get_description().substr(app.get_description().find(':') + 2)) << "\n"
      << ".SH SYNOPSIS\n.B impactdeck\n\\fICOMMAND\\fR [\\fIOPTIONS\\fR]\n.br\n.B impactdeck\n\\fB\\-\\-help\\fR | "
         "\\fB\\-\\-version\\fR\n"
      << ".SH DESCRIPTION\nEvery command takes \\fB\\-\\-help\\fR, and \\fB\\-q\\fR (quiet: errors only on stderr) "
         "or \\fB\\-v\\fR (verbose: settings and stage times on stderr). Lengths are in the unit the scene or "
         "\\fB\\-\\-length\\-unit\\fR declares; everything else is SI. The documents named below are in the "
         "source tree's docs/ folder.\n"
      << ".SH COMMANDS\n";
  man_command(app, out);
  out << ".SH EXIT STATUS\n"
         ".TP\n0\nok\n"
         ".TP\n1\ninternal error, or a broken installation\n"
         ".TP\n2\nusage error (unknown command or flag, missing argument)\n"
         ".TP\n3\ninvalid input: a file, key or value, a limit, a solver failure, an output that cannot be "
         "written; one line on stderr names file, place and reason\n"
         ".TP\n4\na physics self-check failed; run publishes its outputs as the evidence (the report says FAILED)\n"
         ".SH ENVIRONMENT\n.TP\nIMPACTDECK_GMSH_PLUGIN\npath of the Gmsh mesher plugin (docs/fem.md)\n"
         ".SH SEE ALSO\n\\fBgmsh\\fR(1), \\fBccx\\fR(1); docs/cli.md, docs/scene-format.md\n";
}

void write_bash_completion(const CLI::App& app, std::ostream& out) {
  std::vector<std::string> paths;
  collect_paths(app, "", paths);
  out << "# bash completion for impactdeck. Generated by `impactdeck completion bash` from the command-line\n"
         "# definition: do not edit.\n"
         "_impactdeck() {\n"
         "  local cur=${COMP_WORDS[COMP_CWORD]} path='' i subs flags\n"
         "  for ((i = 1; i < COMP_CWORD; i++)); do\n"
         "    case \"$path ${COMP_WORDS[i]}\" in\n";
  std::string alternatives;
  for (const auto& p : paths) alternatives += (alternatives.empty() ? "" : "|") + ("\"" + p + "\"");
  out << "      " << alternatives << ") path=\"$path ${COMP_WORDS[i]}\" ;;\n"
      << "    esac\n"
         "  done\n"
         "  case \"$path\" in\n";
  completion_cases(app, "", out);
  out << "    *) subs=''; flags='' ;;\n"
         "  esac\n"
         "  if [[ $cur == -* ]]; then\n"
         "    COMPREPLY=($(compgen -W \"$flags\" -- \"$cur\"))\n"
         "  elif [[ -n $subs ]]; then\n"
         "    COMPREPLY=($(compgen -W \"$subs\" -- \"$cur\"))\n"
         "  else\n"
         "    COMPREPLY=()  # an argument: files (complete -o default)\n"
         "  fi\n"
         "}\n"
         "complete -o default -F _impactdeck impactdeck\n";
}

void register_generated_docs(CLI::App& app, Context& /*ctx*/) {
  // Both print on stdout, or write FILE atomically with -o (the build writes them so, to install).
  auto out = std::make_shared<std::string>();
  auto emit = [out](const std::function<void(std::ostream&)>& write) {
    if (out->empty() || *out == kStdStream) return write(std::cout);
    write_file_atomically(*out, [&](std::ostream& o) { write(o); });
  };
  CLI::App* man = app.add_subcommand("man", "Print the man page (roff), generated from this command's definition");
  man->group("");  // hidden: not in --help, the man page or the completion
  man->add_option("-o,--out", *out, "Write the page to this file instead of stdout (- : stdout)");
  man->callback([&app, emit] { emit([&app](std::ostream& o) { write_man_page(app, o); }); });
  CLI::App* completion = app.add_subcommand("completion", "Print a shell completion script");
  completion->group("");
  auto shell = std::make_shared<std::string>();
  completion->add_option("shell", *shell, "Shell: bash")->required()->check(CLI::IsMember({"bash"}));
  completion->add_option("-o,--out", *out, "Write the script to this file instead of stdout (- : stdout)");
  completion->callback([&app, emit, shell] { emit([&app](std::ostream& o) { write_bash_completion(app, o); }); });
}

}  // namespace impactdeck::cli
