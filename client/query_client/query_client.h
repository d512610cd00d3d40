// The client side of the query service (what `octomap-rt query`, `octomap-rt map` and the
// example planner use): one request out on the server's channel, its replies back on this
// client's own reply channel, matched by request id, with a timeout.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/distance_path_reply_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "octomap_rt/grid_t.hpp"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "octomap_rt/region_chunk_t.hpp"
#include "protocol/channels.h"
#include "query_client/distance_box.h"

namespace ort::client {

class QueryTimeout : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Read-your-writes and map-state conditions every query may carry.
struct WaitFor {
  int64_t min_snapshot_id = 0;
  std::string robot_id;  // "": do not wait for a scan
  int64_t seq = -1;
  int timeout_ms = 0;  // how long the server may wait
};

struct Box {
  double min[3], max[3];
};

// A whole 2D grid, reassembled from its grid_t rows.
struct Grid {
  octomap_rt::grid_t header;  // the first chunk (cells cleared)
  std::vector<int8_t> cells;  // width * height, row-major, OCC_*
};

// What a distance query asks (docs/PROTOCOL.md, "Distance queries").
struct DistanceRequest {
  double max_distance = 2.0;  // [m]
  bool unknown_occupied = false;
  bool gradient = false;
  int cell_voxels = 1;  // boxes: cells of this many finest voxels a side
};

class QueryClient {
 public:
  // `url`: as ort::protocol::lcm_url_or_default(); `client_id`: 1..64 of [A-Za-z0-9_.-].
  // `ns`: the server's namespace (protocol/channels.h; "" = today's channel names).
  QueryClient(const std::string& url, std::string client_id, std::chrono::milliseconds timeout,
              const std::string& ns = "");
  ~QueryClient();

  octomap_rt::occupancy_reply_t points(const std::vector<float>& xyz, int depth = 0, const WaitFor& w = {});
  octomap_rt::ray_reply_t rays(const std::vector<float>& origins, const std::vector<float>& directions, float max_range,
                               bool ignore_unknown, const WaitFor& w = {});
  // mode: box_query_t.MODE_COUNTS or MODE_ANY_OCCUPIED.
  octomap_rt::box_reply_t boxes(const std::vector<Box>& boxes, int8_t mode, const WaitFor& w = {});
  std::vector<octomap_rt::region_chunk_t> region(const Box& box, int depth, bool include_free, const WaitFor& w = {});
  Grid grid(double z_min, double z_max, double cell_size, const Box* window, const WaitFor& w = {});
  // Distance to the nearest obstacle: of points, of every cell of a box, along a polyline.
  octomap_rt::distance_points_reply_t distance_points(const std::vector<float>& xyz, const DistanceRequest& d,
                                                      const WaitFor& w = {});
  DistanceBox distance_box(const Box& box, const DistanceRequest& d, const WaitFor& w = {});
  octomap_rt::distance_path_reply_t distance_path(const std::vector<float>& vertices, const DistanceRequest& d,
                                                  const WaitFor& w = {});
  // op: map_edit_t.OP_*; box ignored for OP_RESET; flags: map_edit_t.FLAG_*.
  octomap_rt::map_edit_ack_t edit(int8_t op, const Box& box, const std::string& token, int8_t flags = 0);

  const std::string& reply_channel() const { return reply_channel_; }

  // Requests asked again after a BUSY reply (every reply type's status 3), since construction.
  int64_t busy_retries() const { return busy_retries_; }

 private:
  // Publishes `request` (already addressed) on `channel` and collects raw replies with this
  // request id until `done(replies)` says so; a BUSY reply is asked again (backing off)
  // until the timeout, and the last BUSY is returned when time runs out; throws QueryTimeout.
  template <class Reply, class Request, class Done>
  std::vector<Reply> exchange(const std::string& channel, Request& request, Done&& done);
  template <class Request>
  void address(Request& r, const WaitFor& w);
  // A distance query of points or a path's vertices (one reply of type Reply).
  template <class Reply>
  Reply distance_xyz(int8_t mode, const std::vector<float>& xyz, const DistanceRequest& d, const WaitFor& w);

  std::unique_ptr<lcm::LCM> lcm_;
  protocol::Channels channels_;
  std::string client_id_, reply_channel_;
  std::chrono::milliseconds timeout_;
  int64_t next_request_ = 1;
  int64_t busy_retries_ = 0;
};

}  // namespace ort::client
