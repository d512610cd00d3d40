#include "cli/progress_bar.h"

#include <unistd.h>

#include <cstdio>

#include "core/clock.h"

namespace ort::cli {

ProgressBar::ProgressBar(std::string label, size_t total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}

void ProgressBar::update(size_t done, const std::string& detail) {
  if (!enabled_) return;
  const double frac = total_ ? static_cast<double>(done) / total_ : 1.0;
  if (tty_) {
    // Redraw at most 20 times a second: stderr writes would otherwise pace the producer.
    const auto now = SteadyClock::now();
    if (drawn_ && done != total_ && now - last_draw_ < std::chrono::milliseconds(50)) return;
    last_draw_ = now;
    drawn_ = true;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(frac * kWidth);
    std::string bar(filled, '#');
    bar.append(kWidth - filled, '.');
    std::fprintf(stderr, "\r%s [%s] %zu/%zu %s\033[K", label_.c_str(), bar.c_str(), done, total_, detail.c_str());
    std::fflush(stderr);
    return;
  }
  const int decile = static_cast<int>(frac * 10);
  if (decile == last_decile_) return;
  last_decile_ = decile;
  std::fprintf(stderr, "%s %3d%% %zu/%zu %s\n", label_.c_str(), decile * 10, done, total_, detail.c_str());
}

void ProgressBar::finish() {
  if (enabled_ && tty_ && drawn_) std::fprintf(stderr, "\n");
}

}  // namespace ort::cli
