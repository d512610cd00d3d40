// A thread's own priority (Linux: each thread has its own nice value, and a thread starts with
// its creator's). Threads whose work should take only what the others leave idle lower theirs:
// the cpu-grid walk's helpers, the read replica and its octree stage's helpers.
#pragma once

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace ort {

// Raises the calling thread's nice value by `by` (to at most 19, the lowest priority), from
// whatever it has now: a server started under `nice` keeps its threads' order. Best effort: a
// refusal leaves the thread as it was.
inline void lower_this_thread_priority(int by) {
  if (by <= 0) return;
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int now = getpriority(PRIO_PROCESS, tid);
  if (now == -1 && errno != 0) return;
  (void)setpriority(PRIO_PROCESS, tid, std::min(19, now + by));
}

}  // namespace ort
