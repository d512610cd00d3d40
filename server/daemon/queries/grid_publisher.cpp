#include "daemon/queries/grid_publisher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "core/clock.h"
#include "daemon/queries/reply_stamp.h"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"

namespace ort::daemon {

GridPublisher::GridPublisher(const GridPublishConfig& cfg, const QueryBounds& bounds, MapState& map, LcmLoop& loop,
                             std::string server_id)
    : cfg_(cfg), bounds_(bounds), map_(map), loop_(loop), server_id_(std::move(server_id)) {}

GridPublisher::~GridPublisher() { stop(); }

void GridPublisher::start() {
  if (cfg_.rate_hz <= 0) return;
  PeriodicOptions o;
  o.run_first = true;
  o.fixed_rate = true;  // a slow grid: the next one at once, no catch-up burst
  periodic_.start(
      1.0 / cfg_.rate_hz, [this] { publish_newest(); }, o);
}

void GridPublisher::stop() { periodic_.stop(); }

void GridPublisher::compute_if_changed() {
  octomap_rt::grid_query_t q{};
  q.request_id = -1;
  q.wait_seq = -1;
  q.z_min = cfg_.z_min, q.z_max = cfg_.z_max, q.cell_size = cfg_.cell_size;
  q.reply_channel = cfg_.channel;
  const QueryMessage msg(q);
  std::shared_lock lock(map_.mutex);
  const MapHoldNote note(map_.holders, "grid publisher");
  if (map_.version == computed_version_) return;
  computed_version_ = map_.version;
  const MapStamp stamp{static_cast<int64_t>(map_.version), map_.last_scan_utime, static_cast<int64_t>(map_.epoch)};
  try {
    query::WorkBudget budget;
    budget.max_work = bounds_.max_work;
    grid_ = answer_query(*map_.tree, msg, stamp, server_id_, bounds_, budget);
  } catch (const std::exception& e) {  // query::QueryError: e.g. the map's extent is too large
    grid_ = clipped_grid(q, stamp, e.what());
  }
}

// One far scan makes the map's extent too large for a grid for good: the grid then goes out
// for the largest square window the bound allows, centred on the newest scan's origin (where
// the robots are), each message saying so in `error` (status REPLY_OK).
EncodedReplies GridPublisher::clipped_grid(octomap_rt::grid_query_t q, const MapStamp& stamp, const std::string& why) {
  const double res = map_.tree->getResolution();
  const double cell = q.cell_size > 0 ? q.cell_size : res;
  const int64_t max_cells = std::min<int64_t>(kMaxGridCells, static_cast<int64_t>(bounds_.max_reply_bytes));
  const int64_t side = std::max<int64_t>(1, static_cast<int64_t>(std::sqrt(static_cast<double>(max_cells))) - 2);
  const double half = 0.5 * static_cast<double>(side) * cell;
  const octomap::point3d& o = map_.last_scan_origin;
  q.use_window = 1;
  q.window_min[0] = o.x() - half, q.window_min[1] = o.y() - half;
  q.window_max[0] = o.x() + half, q.window_max[1] = o.y() + half;
  const QueryMessage msg(q);
  try {
    query::WorkBudget budget;
    budget.max_work = bounds_.max_work;
    EncodedReplies out = answer_query(*map_.tree, msg, stamp, server_id_, bounds_, budget);
    if (out.status != octomap_rt::occupancy_reply_t::REPLY_OK) return out;
    const std::string note = "clipped: " + why + "; this is the " + std::to_string(side) + " x " +
                             std::to_string(side) + " cells around the newest scan's origin";
    for (std::vector<uint8_t>& m : out.messages) {
      octomap_rt::grid_t g;
      if (g.decode(m.data(), 0, static_cast<int>(m.size())) < 0) continue;
      g.error = note;
      m = encode_message(g);
    }
    clipped_++;
    return out;
  } catch (const std::exception& e) {
    return error_reply(msg, octomap_rt::occupancy_reply_t::REPLY_BAD_REQUEST, e.what(), stamp, server_id_);
  }
}

void GridPublisher::publish_newest() {
  compute_if_changed();
  for (size_t i = 0; i < grid_.messages.size(); ++i) {
    // Paced like the answers: a burst of 60 KB datagrams overruns receive buffers.
    if (i > 0) std::this_thread::sleep_for(std::chrono::microseconds(500));
    loop_.publish(grid_.channel, grid_.messages[i].data(), grid_.messages[i].size());
  }
  published_++;
}

}  // namespace ort::daemon
