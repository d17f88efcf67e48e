#pragma once
// A progress bar on stderr for long runs: drawn only when stderr is a terminal, not in quiet mode,
// and only once the run has lasted more than a second; erased with a final newline when done.
#include <chrono>
#include <cstddef>
#include <string>

namespace impactdeck::study {

class ProgressBar {
 public:
  /// `enabled` false (e.g. --quiet) silences it; so does a stderr that is not a terminal.
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(std::size_t done, std::size_t total);
  void finish();
  bool shown() const { return shown_; }

  /// The line drawn for a state (without the leading carriage return), for tests.
  static std::string render(const std::string& label, std::size_t done, std::size_t total, double elapsed_s,
                            int width = 30);

 private:
  std::string label_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace impactdeck::study
