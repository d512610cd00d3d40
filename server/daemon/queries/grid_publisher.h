// Publishes the 2D grid of a z band on OCTOMAP_RT_GRID at a rate (--grid-rate HZ with
// --grid-z MIN:MAX and --grid-cell C; off by default), for planners that want the grid
// without asking: the same grid_t rows a grid query gets (request_id -1, client_id ""),
// computed by the same code (daemon/query_answers) under the shared map lock. A thread of its
// own: every period it recomputes the grid if the map changed and publishes the newest one,
// so a subscriber that starts later gets the grid at the next period. A grid the map cannot
// give (over 4 M cells) goes out as one grid_t with status REPLY_BAD_REQUEST and the reason.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "daemon/map/map_state.h"
#include "daemon/queries/query_answers.h"
#include "daemon/queries/query_config.h"
#include "daemon/transport/lcm_loop.h"

namespace ort::daemon {

class GridPublisher {
 public:
  GridPublisher(const GridPublishConfig& cfg, MapState& map, LcmLoop& loop, std::string server_id);
  ~GridPublisher();
  GridPublisher(const GridPublisher&) = delete;
  GridPublisher& operator=(const GridPublisher&) = delete;

  void start();
  void stop();  // idempotent
  int64_t published() const { return published_; }

 private:
  void run();
  void compute_if_changed();

  GridPublishConfig cfg_;
  MapState& map_;
  LcmLoop& loop_;
  std::string server_id_;
  std::thread thread_;
  std::mutex mutex_;  // stop_
  std::condition_variable wake_;
  bool stop_ = false;
  uint64_t computed_version_ = UINT64_MAX;
  EncodedReplies grid_;  // the newest grid's rows
  std::atomic<int64_t> published_{0};
};

}  // namespace ort::daemon
