#pragma once

#include <chrono>
#include <functional>
#include <string>

namespace dynid {

/// How far long work has got: `fraction` in [0, 1] and what it is doing now ("start 2/4"). The
/// library calls it from the thread doing the work, at a handful of points or at most every few
/// thousand steps; an empty function (the default in every options struct) costs nothing.
using ProgressCallback = std::function<void(double fraction, const std::string& what)>;

/// Whether a command shows progress: stderr is a terminal and --quiet was not given (a log file
/// or a pipe gets no carriage-return redraws).
bool progress_wanted(bool quiet);

/// A counting line on stderr, "label: 42 % what", redrawn in place (carriage return) at most ten
/// times a second and cleared when done or destroyed. Disabled, it prints nothing.
class ProgressLine {
 public:
  ProgressLine(std::string label, bool enabled);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// Redraws the line (throttled; fraction 1 always draws).
  void update(double fraction, const std::string& what);
  /// Clears the line (idempotent).
  void finish();
  /// A ProgressCallback that updates this line (empty when disabled); valid while *this lives.
  ProgressCallback callback();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::size_t width_ = 0;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace dynid
