// Publishes the 2D grid of a z band on OCTOMAP_RT_GRID at a rate (--grid-rate HZ with
// --grid-z MIN:MAX and --grid-cell C; off by default), for planners that want the grid
// without asking: the same grid_t rows a grid query gets (request_id -1, client_id ""),
// computed by the same code (daemon/query_answers) under the shared map lock. A thread of its
// own: every period it recomputes the grid if the map changed and publishes the newest one,
// so a subscriber that starts later gets the grid at the next period. A map whose extent is
// too large for one grid (over 4 M cells, or --query-max-reply-bytes) gets the largest window
// the bound allows around the newest scan's origin, each grid_t saying so in `error`.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "core/threads/periodic_thread.h"
#include "daemon/map/map_state.h"
#include "daemon/queries/query_answers.h"
#include "daemon/queries/query_config.h"
#include "daemon/transport/lcm_loop.h"
#include "octomap_rt/grid_query_t.hpp"

namespace ort::daemon {

class GridPublisher {
 public:
  // `bounds`: the grid's work under the lock is bounded as a grid query's (its max_work;
  // a grid past it goes out as the refusal).
  GridPublisher(const GridPublishConfig& cfg, const QueryBounds& bounds, MapState& map, LcmLoop& loop,
                std::string server_id);
  ~GridPublisher();
  GridPublisher(const GridPublisher&) = delete;
  GridPublisher& operator=(const GridPublisher&) = delete;

  void start();
  void stop();  // idempotent
  int64_t published() const { return published_; }
  int64_t clipped() const { return clipped_; }  // grids sent clipped to the bound

 private:
  void publish_newest();  // the periodic task
  void compute_if_changed();
  EncodedReplies clipped_grid(octomap_rt::grid_query_t q, const MapStamp& stamp, const std::string& why);

  GridPublishConfig cfg_;
  QueryBounds bounds_;
  MapState& map_;
  LcmLoop& loop_;
  std::string server_id_;
  uint64_t computed_version_ = UINT64_MAX;
  EncodedReplies grid_;  // the newest grid's rows
  std::atomic<int64_t> published_{0}, clipped_{0};
  PeriodicThread periodic_;  // last: stopped before the members its task uses go
};

}  // namespace ort::daemon
