// Queries across a shard set (docs/PROTOCOL.md, "Shards"): each shard answers for its own
// regions, so a point goes to the shard owning its region (a coarse depth above the region
// depth asks every shard and takes the largest value, as OctoMap's inner nodes do), a box is
// counted on every shard and summed, and a ray is cast on every shard it may reach
// (shards_for_rays), each stopping in its own regions, and gets the stop the ray meets first
// (shard_rays.h); a distance is the smallest of the shards' within reach (shard_distance.h).
// A shard that does not answer leaves its part unknown, and the answer says so.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "protocol/shards/shard_set.h"
#include "query_client/query_client.h"
#include "shard_client/shard_distance.h"
#include "shard_client/shard_region.h"

namespace ort::client {

// What every routed answer carries besides the reply itself.
struct ShardAnswer {
  std::vector<uint32_t> missing;      // shards that did not answer (timeout or refusal)
  std::vector<std::string> errors;    // why, one per missing shard
  std::vector<int64_t> snapshot_ids;  // each shard's map state id, by index (-1: none)
  bool partial() const { return !missing.empty(); }
  std::string shortfall() const;  // "shard 2 did not answer: ...; its part is unknown"
};

// Read-your-writes and map-state conditions of a routed query. Every shard hears and applies
// every scan (a scan touching none of its regions too), so a robot's wait (its scan `seq`
// applied) holds on each shard asked alike; map state ids are each shard's own, so the least
// one is given per shard (by index, e.g. an earlier answer's `shards.snapshot_ids`; a shard
// past the list's end or at -1: none). A shard that cannot meet them within `timeout_ms`
// answers REPLY_NOT_READY: it is then missing from the answer, which is partial and says so.
struct ShardWait {
  std::string robot_id;  // "": do not wait for a scan
  int64_t seq = -1;
  int timeout_ms = 0;  // how long each shard may wait
  std::vector<int64_t> min_snapshot_ids;
  // The conditions shard i is asked with.
  WaitFor on_shard(uint32_t i) const;
};

template <class Reply>
struct Routed {
  Reply reply{};  // merged; status REPLY_OK unless every shard refused
  ShardAnswer shards;
};

class ShardQueries {
 public:
  // `set` and `resolution` as the shards announced them (ShardRoster); one QueryClient per
  // shard on its own namespace protocol::shard_namespace(ns, i).
  ShardQueries(const std::string& url, const std::string& client_id, std::chrono::milliseconds timeout,
               const std::string& ns, const protocol::ShardSet& set, double resolution);

  // Every query takes the conditions `w` (ShardWait), each shard asked with its own.
  Routed<octomap_rt::occupancy_reply_t> points(const std::vector<float>& xyz, int depth = 0, const ShardWait& w = {});
  Routed<octomap_rt::box_reply_t> boxes(const std::vector<Box>& boxes, int8_t mode, const ShardWait& w = {});
  // The one map's castRay answers, stopping at unknown space unless `ignore_unknown` (shard_rays.h).
  Routed<octomap_rt::ray_reply_t> rays(const std::vector<float>& origins, const std::vector<float>& directions,
                                       float max_range, bool ignore_unknown, const ShardWait& w = {});

  // Distances (shard_distance.h): the shards with a region within reach of what is asked; per
  // cell the smallest distance, gradients from the merged field. Points go in batches of at
  // most kMaxQueryPoints asked points (7 a point with the gradient). A missing shard's
  // obstacles are left out: the distances are then upper bounds (partial).
  Routed<octomap_rt::distance_points_reply_t> distance_points(const std::vector<float>& xyz, const DistanceRequest& d,
                                                              const ShardWait& w = {});
  Routed<DistanceBox> distance_box(const Box& box, const DistanceRequest& d, const ShardWait& w = {});
  Routed<octomap_rt::distance_path_reply_t> distance_path(const std::vector<float>& vertices, const DistanceRequest& d,
                                                          const ShardWait& w = {});

  // A grid of a z band (shard_grid_edit.h): with a window, the shards owning a region in it; without,
  // every shard, merged on the union of their extents (the map's extent).
  Routed<Grid> grid(double z_min, double z_max, double cell_size, const Box* window, const ShardWait& w = {});
  // A box's nodes at a depth (QueryClient::region; shard_region.h): from the shards owning a region
  // the box meets, merged into one chunk, each node of the one map once.
  Routed<octomap_rt::region_chunk_t> region(const Box& box, int depth, bool include_free, const ShardWait& w = {});
  // A map edit (QueryClient::edit) sent to the shards owning a region the box meets (every shard
  // for OP_RESET); reply status REPLY_OK when each applied it, else REPLY_NOT_READY with the
  // shards that did not (`shards.missing`: a refusal says why). Throws std::invalid_argument for
  // FLAG_INCLUDE_UNKNOWN (every shard refuses it).
  Routed<octomap_rt::map_edit_ack_t> edit(int8_t op, const Box& box, const std::string& token, int8_t flags = 0);

  // The shard owning the voxel of point (x, y, z); set.count for a point outside the key range.
  uint32_t shard_of_point(double x, double y, double z) const;

 private:
  protocol::ShardSet set_;
  double resolution_;
  std::vector<std::unique_ptr<QueryClient>> clients_;
};

}  // namespace ort::client
