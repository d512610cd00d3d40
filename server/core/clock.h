// The clocks the code reads: steady time for durations (stage times, timeouts), the wall
// clock for LCM utimes, and a thread's CPU time (what a helper thread got of a core). One
// spelling of each, so a stage time is always the same unit.
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>
#include <string>

namespace ort {

using SteadyClock = std::chrono::steady_clock;

// Milliseconds from `a` to `b`.
inline double ms_between(SteadyClock::time_point a, SteadyClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// Milliseconds elapsed since `t`.
inline double ms_since(SteadyClock::time_point t) { return ms_between(t, SteadyClock::now()); }

// Seconds elapsed since `t`.
inline double seconds_since(SteadyClock::time_point t) {
  return std::chrono::duration<double>(SteadyClock::now() - t).count();
}

// Microseconds since the Unix epoch (LCM's utime).
inline int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The wall clock's present moment in UTC, as strftime writes it with `format` (file names,
// lock holders: text a person reads).
inline std::string utc_text(const char* format) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  const size_t n = std::strftime(buf, sizeof buf, format, &tm);
  return std::string(buf, n);
}

// CPU time the calling thread has run, in nanoseconds (0 where the clock is refused).
inline int64_t thread_cpu_ns() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
  return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace ort
