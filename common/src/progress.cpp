#include "impactdeck/common/progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <unistd.h>

namespace impactdeck {

namespace {

double delay_from_environment() {
  if (const char* e = std::getenv("IMPACTDECK_PROGRESS_DELAY_S")) {
    char* end = nullptr;
    const double d = std::strtod(e, &end);
    if (end != e && std::isfinite(d) && d >= 0) return d;
  }
  return kProgressDelay_s;
}

// A count as text: integers as such up to a million, then with a unit prefix ("1.25 M").
std::string amount(double x) {
  char b[32];
  if (std::abs(x) >= 1e6) std::snprintf(b, sizeof b, "%.3g M", x / 1e6);
  else if (x == std::floor(x)) std::snprintf(b, sizeof b, "%.0f", x);
  else std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}

std::string duration(double s) {
  char b[32];
  if (s < 60) std::snprintf(b, sizeof b, "%.0f s", s);
  else if (s < 3600) std::snprintf(b, sizeof b, "%.0f min %02.0f s", std::floor(s / 60), std::fmod(s, 60.0));
  else std::snprintf(b, sizeof b, "%.0f h %02.0f min", std::floor(s / 3600), std::floor(std::fmod(s, 3600.0) / 60));
  return b;
}

}  // namespace

ProgressLine::ProgressLine(std::string stage, bool enabled, std::string unit)
    : stage_(std::move(stage)), unit_(std::move(unit)), enabled_(enabled && ::isatty(STDERR_FILENO) == 1),
      delay_s_(delay_from_environment()), start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

ProgressLine::~ProgressLine() { finish(); }

std::string ProgressLine::render(const std::string& stage, double done, double total, double elapsed,
                                 const std::string& unit, const std::string& detail, int width) {
  std::string line = stage;
  const std::string u = unit.empty() ? "" : " " + unit;
  if (total > 0) {
    const double f = std::clamp(done / total, 0.0, 1.0);
    const int filled = static_cast<int>(f * width + 0.5);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(static_cast<std::size_t>(width), ' ');
    char pct[16];
    std::snprintf(pct, sizeof pct, "%3d%%", static_cast<int>(f * 100.0));
    line += " [" + bar + "] " + pct + " " + amount(done) + "/" + amount(total) + u;
  } else {
    line += " " + amount(done) + u;
  }
  if (elapsed > 0 && done > 0) line += ", " + amount(done / elapsed) + u + "/s";
  if (total > 0 && done > 0 && done < total) line += ", " + duration(elapsed * (total - done) / done) + " left";
  else line += ", " + duration(elapsed) + " elapsed";
  if (!detail.empty()) line += " (" + detail + ")";
  return line;
}

void ProgressLine::update(double done, double total, const std::string& detail) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < delay_s_) return;
  if (shown_ && now - last_draw_ < std::chrono::milliseconds(100) && done < total) return;
  last_draw_ = now;
  std::string line = render(stage_, done, total, elapsed, unit_, detail);
  const std::size_t width = line.size();
  if (width < last_width_) line.append(last_width_ - width, ' ');  // erase a longer previous line
  last_width_ = width;
  shown_ = true;
  std::cerr << '\r' << line << std::flush;
}

void ProgressLine::finish() {
  if (shown_) std::cerr << "\n" << std::flush;
  shown_ = false;
  enabled_ = false;
}

}  // namespace impactdeck
