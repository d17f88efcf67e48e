#include "impactdeck/study/progress.hpp"

#include <cstdio>
#include <iostream>

#include <unistd.h>

namespace impactdeck::study {

ProgressBar::ProgressBar(std::string label, bool enabled)
    : label_(std::move(label)), enabled_(enabled && ::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { finish(); }

std::string ProgressBar::render(const std::string& label, std::size_t done, std::size_t total, double elapsed,
                                int width) {
  const double f = total > 0 ? static_cast<double>(done) / static_cast<double>(total) : 1.0;
  const int filled = static_cast<int>(f * width + 0.5);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(static_cast<std::size_t>(width), ' ');
  char buf[160];
  const double eta = f > 0.0 ? elapsed * (1.0 - f) / f : 0.0;
  std::snprintf(buf, sizeof buf, "%s [%s] %3d%% %zu/%zu  %.0f s left", label.c_str(), bar.c_str(),
                static_cast<int>(f * 100.0), done, total, eta);
  return buf;
}

void ProgressBar::update(std::size_t done, std::size_t total) {
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (elapsed < 1.0) return;
  shown_ = true;
  std::cerr << '\r' << render(label_, done, total, elapsed) << std::flush;
}

void ProgressBar::finish() {
  if (shown_) std::cerr << "\n" << std::flush;
  shown_ = false;
  enabled_ = false;
}

}  // namespace impactdeck::study
