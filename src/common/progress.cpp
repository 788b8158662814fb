#include "dynid/common/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dynid {

bool progress_wanted(bool quiet) {
  return !quiet && ::isatty(STDERR_FILENO) == 1;
}

ProgressLine::ProgressLine(std::string label, bool enabled)
    : label_(std::move(label)), enabled_(enabled) {}

ProgressLine::~ProgressLine() {
  finish();
}

void ProgressLine::update(double fraction, const std::string& what) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && fraction < 1.0 && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  const int percent = static_cast<int>(std::floor(100.0 * std::clamp(fraction, 0.0, 1.0)));
  std::string text = label_ + ": " + std::to_string(percent) + " % " + what;
  // Pad over the previous text, so a shorter line leaves nothing of it behind.
  const std::size_t length = text.size();
  if (length < width_) text.append(width_ - length, ' ');
  width_ = length;
  std::fprintf(stderr, "\r%s", text.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r%s\r", std::string(width_, ' ').c_str());
  std::fflush(stderr);
  drawn_ = false;
  width_ = 0;
}

ProgressCallback ProgressLine::callback() {
  if (!enabled_) return {};
  return [this](double fraction, const std::string& what) { update(fraction, what); };
}

}  // namespace dynid
