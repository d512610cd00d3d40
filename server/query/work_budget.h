// What one query may cost under the map's read lock: a count of work units (nodes visited,
// voxels a ray may walk) and a deadline, plus a flag that cuts it at once (the server is
// stopping). The query walks charge it as they go and stop where it runs out; the caller
// then answers what was done and says where the query was cut.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>

#include "core/clock.h"

namespace ort::query {

enum class Cut : int8_t { kNone = 0, kWork = 1, kTime = 2, kStopping = 3 };
const char* to_string(Cut c);

struct WorkBudget {
  uint64_t max_work = std::numeric_limits<uint64_t>::max();
  SteadyClock::time_point deadline = SteadyClock::time_point::max();
  const std::atomic<bool>* stop = nullptr;  // set: a true value cuts the query
  uint64_t used = 0;
  Cut cut = Cut::kNone;

  // Adds n units; false (and `cut` set) once a bound is passed. The clock and the stop flag
  // are read every kCheckEvery units, so a walk of tiny steps does not pay a clock read each.
  bool charge(uint64_t n) {
    if (cut != Cut::kNone) return false;
    used += n;
    if (used > max_work) return stop_with(Cut::kWork);
    if ((since_check_ += n) < kCheckEvery) return true;
    since_check_ = 0;
    return check_now();
  }
  // Whether `n` more units would still be within max_work (asked before an indivisible step).
  bool fits(uint64_t n) const { return cut == Cut::kNone && n <= max_work && used <= max_work - n; }
  // Reads the clock and the stop flag now.
  bool check_now() {
    if (cut != Cut::kNone) return false;
    if (stop && stop->load(std::memory_order_relaxed)) return stop_with(Cut::kStopping);
    if (SteadyClock::now() >= deadline) return stop_with(Cut::kTime);
    return true;
  }
  bool stop_with(Cut c) {
    cut = c;
    return false;
  }

  static constexpr uint64_t kCheckEvery = 256;

 private:
  uint64_t since_check_ = 0;
};

}  // namespace ort::query
