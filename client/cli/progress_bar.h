// A progress bar on stderr for long-running client commands. On a terminal it redraws one
// line; otherwise (logs, several producers sharing a file) it prints a line every 10 %.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "core/clock.h"

namespace ort::cli {

class ProgressBar {
 public:
  ProgressBar(std::string label, size_t total, bool enabled);
  // `done` items so far; `detail` is appended (e.g. "12.3 MB, 4.9 Hz").
  void update(size_t done, const std::string& detail);
  void finish();

 private:
  std::string label_;
  size_t total_;
  bool enabled_;
  bool tty_;
  int last_decile_ = -1;
  SteadyClock::time_point last_draw_{};
  bool drawn_ = false;
};

}  // namespace ort::cli
