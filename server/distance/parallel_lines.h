// Runs a body over independent lines of a grid on a few threads: the distance transform's
// passes (squared_edt.h, incremental_edt.h) and the box reply's frames split this way.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace ort::distance {

// Runs body(line) for line in [0, lines) on `threads` workers (the caller is one of them),
// batches of `batch` lines taken in turn; fewer workers where there are few lines.
template <class Body>
void parallel_lines(int64_t lines, int threads, Body&& body, int64_t batch = 16) {
  const int workers = static_cast<int>(std::clamp<int64_t>(threads, 1, std::max<int64_t>(1, lines / batch)));
  std::atomic<int64_t> next{0};
  auto work = [&] {
    for (;;) {
      const int64_t first = next.fetch_add(batch);
      if (first >= lines) return;
      for (int64_t l = first; l < std::min(lines, first + batch); ++l) body(l);
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace ort::distance
