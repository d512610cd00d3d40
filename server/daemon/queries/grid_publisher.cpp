#include "daemon/queries/grid_publisher.h"

#include <algorithm>
#include <chrono>

#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"

namespace ort::daemon {

GridPublisher::GridPublisher(const GridPublishConfig& cfg, MapState& map, LcmLoop& loop, std::string server_id)
    : cfg_(cfg), map_(map), loop_(loop), server_id_(std::move(server_id)) {}

GridPublisher::~GridPublisher() { stop(); }

void GridPublisher::start() {
  if (cfg_.rate_hz > 0 && !thread_.joinable()) thread_ = std::thread([this] { run(); });
}

void GridPublisher::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void GridPublisher::compute_if_changed() {
  octomap_rt::grid_query_t q{};
  q.request_id = -1;
  q.wait_seq = -1;
  q.z_min = cfg_.z_min, q.z_max = cfg_.z_max, q.cell_size = cfg_.cell_size;
  q.reply_channel = cfg_.channel;
  const QueryMessage msg(q);
  std::shared_lock lock(map_.mutex);
  if (map_.version == computed_version_) return;
  computed_version_ = map_.version;
  const MapStamp stamp{static_cast<int64_t>(map_.version), map_.last_scan_utime};
  try {
    grid_ = answer_query(*map_.tree, msg, stamp, server_id_);
  } catch (const std::exception& e) {  // query::QueryError: e.g. the map's extent is too large
    grid_ = error_reply(msg, octomap_rt::occupancy_reply_t::REPLY_BAD_REQUEST, e.what(), stamp, server_id_);
  }
}

void GridPublisher::run() {
  const auto period = std::chrono::duration<double>(1.0 / cfg_.rate_hz);
  auto next = std::chrono::steady_clock::now();
  for (;;) {
    compute_if_changed();
    for (size_t i = 0; i < grid_.messages.size(); ++i) {
      // Paced like the answers: a burst of 60 KB datagrams overruns receive buffers.
      if (i > 0) std::this_thread::sleep_for(std::chrono::microseconds(500));
      loop_.publish(grid_.channel, grid_.messages[i].data(), grid_.messages[i].size());
    }
    published_++;
    next = std::max(next + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period),
                    std::chrono::steady_clock::now());  // behind (a slow grid): no catch-up burst
    std::unique_lock lock(mutex_);
    if (wake_.wait_until(lock, next, [&] { return stop_; })) return;
  }
}

}  // namespace ort::daemon
