#include "bench_replies.h"

#include <algorithm>
#include <cmath>

#include "core/clock.h"
#include "octomap_rt/distance_box_chunk_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"

namespace ort::bench {

DistanceReplies::DistanceReplies(daemon::MappingServer& server, const std::string& channel) {
  server.lcm_loop().subscribe(channel, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
    on(static_cast<const uint8_t*>(rb.data), rb.data_size);
  });
}

void DistanceReplies::on(const uint8_t* data, size_t size) {
  const auto now = SteadyClock::now();
  octomap_rt::distance_box_chunk_t box;
  octomap_rt::distance_points_reply_t points;
  int64_t id = 0;
  int total = 1;
  std::string error;
  if (box.decode(data, 0, static_cast<int>(size)) >= 0) {
    id = box.request_id, total = std::max(1, box.num_chunks), error = box.error;
  } else if (points.decode(data, 0, static_cast<int>(size)) >= 0) {
    id = points.request_id, error = points.error;
  } else {
    return;
  }
  std::lock_guard lock(m_);
  auto it = remaining_.find(id);
  if (it == remaining_.end()) it = remaining_.emplace(id, total).first;
  if (!error.empty()) errors_[id] = error, it->second = 1;
  if (--it->second == 0) done_[id] = now, cv_.notify_all();
}

double DistanceReplies::wait(int64_t id, SteadyClock::time_point sent, double timeout_s) {
  std::unique_lock lock(m_);
  if (!cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return done_.count(id) > 0; })) {
    ++failures_["no answer within " + std::to_string(static_cast<int>(timeout_s)) + " s"];
    return -1;
  }
  if (auto e = errors_.find(id); e != errors_.end()) {
    ++failures_[e->second];
    return -1;
  }
  return std::chrono::duration<double>(done_[id] - sent).count();
}

std::map<std::string, int64_t> DistanceReplies::failures() const {
  std::lock_guard lock(m_);
  return failures_;
}

double LatencyStats::pct(double p) const {
  if (ms.empty()) return -1;
  std::vector<double> v = ms;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

}  // namespace ort::bench
