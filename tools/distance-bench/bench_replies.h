// octomap-rt-distance-bench's reply side: when the last message of each distance query
// arrived (box: all its chunks), its refusal if any, and the per-phase statistics.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/clock.h"
#include "daemon/mapping_server.h"

namespace ort::bench {

class DistanceReplies {
 public:
  DistanceReplies(daemon::MappingServer& server, const std::string& channel);
  // Seconds from `sent` to the last message of `id`; < 0 when it was refused (the reason is
  // kept for the phase's report) or did not come within `timeout_s`.
  double wait(int64_t id, SteadyClock::time_point sent, double timeout_s);
  // Refusals and time-outs so far, by text ("timed out after 30 s", the server's error).
  std::map<std::string, int64_t> failures() const;

 private:
  void on(const uint8_t* data, size_t size);

  mutable std::mutex m_;
  std::condition_variable cv_;
  std::map<int64_t, int> remaining_;  // messages still expected (box: num_chunks)
  std::map<int64_t, SteadyClock::time_point> done_;
  std::map<int64_t, std::string> errors_;
  std::map<std::string, int64_t> failures_;
};

// Latencies of one phase [ms], with the queries that got no answer.
struct LatencyStats {
  std::vector<double> ms;
  int64_t failed = 0;
  void add(double seconds) {
    if (seconds >= 0)
      ms.push_back(seconds * 1e3);
    else
      ++failed;
  }
  // The p-th percentile (nearest rank), -1 without samples.
  double pct(double p) const;
};

}  // namespace ort::bench
