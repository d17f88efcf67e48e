#pragma once
// One progress line on stderr for anything long (a sweep, a campaign, a sequence, meshing, a ccx
// run): stage, done/total, rate, time left, redrawn in place. Drawn only when stderr is a terminal,
// only when enabled (the CLI: not --quiet), and only once the work has lasted kProgressDelay_s (a
// short run shows nothing); ended with a newline by finish() or the destructor.
// IMPACTDECK_PROGRESS_DELAY_S in the environment replaces the delay (the tests set 0).
#include <chrono>
#include <cstddef>
#include <string>

namespace impactdeck {

/// Seconds of work before a progress line appears.
constexpr double kProgressDelay_s = 2.0;

class ProgressLine {
 public:
  /// `stage` names the work ("sweep", "ccx", ...); `unit` what is counted ("points", "cases",
  /// "s simulated"); `enabled` false (--quiet) silences it, and so does a stderr that is not a
  /// terminal.
  ProgressLine(std::string stage, bool enabled, std::string unit = "");
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// The work done so far of `total` (total 0: unknown, the line shows the count and the rate);
  /// `detail` is shown after it (e.g. "step 1, increment 40"). Cheap when silent; redraws at most
  /// ten times a second.
  void update(double done, double total, const std::string& detail = "");
  /// Ends the line (once shown); later updates draw nothing.
  void finish();
  bool shown() const { return shown_; }
  bool enabled() const { return enabled_; }

  /// The line for a state, without the leading carriage return (for tests).
  static std::string render(const std::string& stage, double done, double total, double elapsed_s,
                            const std::string& unit = "", const std::string& detail = "", int width = 24);

 private:
  std::string stage_, unit_;
  bool enabled_;
  bool shown_ = false;
  double delay_s_;
  std::size_t last_width_ = 0;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace impactdeck
