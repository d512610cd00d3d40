// How many threads the cpu-grid back end walks a window with when its walk shares the cores
// with another stage (CpuGridOptions::helpers_yield: `bench` and `build` run the octree stage
// beside it): the caller's thread alone, or all the walk's threads.
//
// Why: the helper threads run at the lowest priority so that they take only what the other
// stage leaves idle. Where that stage is light (skt-corridor: a short octree stage beside a
// long walk) a helper gets most of a core and nearly halves the walk. Where it is heavy
// (fr079-real on 2 cores), or another program takes the cores, a helper gets little CPU, the
// caller waits for the helper's last chunk at every window's join, and two threads marking
// one grid pass its cache lines between the cores: measured, the walk then took more CPU and
// stage 1 longer than the caller walking alone (docs/history/benchmarks-log.md, "the cpu-grid
// walk beside the octree stage on two cores"). The balance moves with the data
// and with whatever else runs, so it is measured where it happens: after a window walked with
// helpers, the CPU time they got per wall-clock millisecond of the walk (their share of a
// core). Helpers that got at least kWorthFrom of a core keep walking; below it the caller
// walks alone, and every kProbeEvery windows the helpers walk one window to measure again.
#pragma once

#include <cstddef>

namespace ort {

class WalkThreadChoice {
 public:
  static constexpr double kWorthFrom = 0.5;  // of a core, each helper, on average
  static constexpr unsigned kProbeEvery = 8;
  // Windows of fewer rays are too short to judge (thread start-up weighs on them): they take
  // the current choice and leave the measurement alone.
  static constexpr size_t kJudgedFrom = 4096;

  explicit WalkThreadChoice(unsigned all_threads) : all_(all_threads) {}

  // Threads for the next window: 1 or all.
  unsigned next() const {
    if (all_ <= 1) return 1;
    if (share_ < 0 || share_ >= kWorthFrom) return all_;  // not measured yet, or the helpers pay
    return alone_ % kProbeEvery == kProbeEvery - 1 ? all_ : 1;
  }

  // A window of `rays` was walked with `threads` (what next() said) in `walk_ms`, and the
  // helper threads (threads - 1 of them) got `helper_cpu_ms` of CPU time between them.
  void record(unsigned threads, size_t rays, double walk_ms, double helper_cpu_ms) {
    if (all_ <= 1 || rays < kJudgedFrom) return;
    if (threads == 1) {
      ++alone_;
      return;
    }
    if (walk_ms > 0) share_ = helper_cpu_ms / (walk_ms * double(threads - 1));
    alone_ = 0;
  }

  // The helpers' share of a core at the last window they walked; < 0 before any.
  double helper_share() const { return share_; }

 private:
  unsigned all_;
  unsigned alone_ = 0;  // windows walked alone since the helpers last walked one
  double share_ = -1;
};

}  // namespace ort
