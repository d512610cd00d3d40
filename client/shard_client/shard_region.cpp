#include "shard_client/shard_region.h"

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>
#include <utility>

#include "octomap_rt/occupancy_reply_t.hpp"
#include "shard_client/shard_ask.h"
#include "shard_client/shard_distance.h"
#include "shard_client/shard_queries.h"

namespace ort::client {

using Occ = octomap_rt::occupancy_reply_t;

octomap_rt::region_chunk_t merge_region_lists(const std::vector<const std::vector<octomap_rt::region_chunk_t>*>& got) {
  octomap_rt::region_chunk_t out{};
  out.status = Occ::REPLY_BAD_REQUEST;
  out.error = "no shard answered";
  // A node is its depth and center: every shard computes a node's center from the same key and
  // depth (OcTree::keyToCoord), so equal nodes have bit-equal centers.
  std::map<std::pair<int8_t, std::array<float, 3>>, size_t> seen;
  bool any = false;
  for (const auto* chunks : got) {
    if (!chunks || chunks->empty() || chunks->front().status != Occ::REPLY_OK) continue;
    const auto& first = chunks->front();
    if (any && first.resolution != out.resolution)
      throw std::invalid_argument("the shards' region lists differ in resolution");
    if (!any) {
      out = first;
      out.state.clear(), out.depth.clear(), out.center_xyz.clear();
      out.server_id.clear();
      any = true;
    }
    for (const auto& c : *chunks) {
      out.utime = std::max(out.utime, c.utime);
      out.snapshot_id = std::max(out.snapshot_id, c.snapshot_id);
      out.map_utime = std::max(out.map_utime, c.map_utime);
      for (int32_t i = 0; i < c.num_voxels; ++i) {
        const std::array<float, 3> center{c.center_xyz[3 * i], c.center_xyz[3 * i + 1], c.center_xyz[3 * i + 2]};
        const auto [it, fresh] = seen.try_emplace({c.depth[i], center}, out.state.size());
        if (!fresh) {  // a coarse node several shards hold parts of: occupied when any part is
          if (c.state[i] == Occ::OCC_OCCUPIED) out.state[it->second] = Occ::OCC_OCCUPIED;
          continue;
        }
        out.state.push_back(c.state[i]);
        out.depth.push_back(c.depth[i]);
        out.center_xyz.insert(out.center_xyz.end(), center.begin(), center.end());
      }
    }
  }
  out.chunk_index = 0, out.num_chunks = 1;
  out.num_voxels = static_cast<int32_t>(out.state.size());
  out.num_xyz = static_cast<int32_t>(out.center_xyz.size());
  out.total_voxels = out.num_voxels;
  return out;
}

Routed<octomap_rt::region_chunk_t> ShardQueries::region(const Box& box, int depth, bool include_free,
                                                        const ShardWait& w) {
  std::vector<uint32_t> which = detail::every_shard(set_.count);
  std::array<int64_t, 3> klo{}, khi{};
  bool inside = true;
  for (int a = 0; a < 3; ++a)
    inside = inside && voxel_key(std::max(box.min[a], -resolution_ * 32767.0), resolution_, klo[a]) &&
             voxel_key(std::min(box.max[a], resolution_ * 32767.0), resolution_, khi[a]);
  if (inside) which = shards_meeting(set_, klo, khi);
  if (which.empty()) which = {0};  // a box no shard owns a region of: one shard answers it empty
  using Chunks = std::vector<octomap_rt::region_chunk_t>;
  Routed<octomap_rt::region_chunk_t> out;
  const auto got = detail::ask_each<Chunks>(which, set_.count, out.shards, [&](uint32_t i) {
    Chunks c = clients_[i]->region(box, depth, include_free, w.on_shard(i));
    if (c.empty()) throw std::runtime_error("no reply");
    return c;
  });
  std::vector<const Chunks*> views;
  for (const auto& g : got) views.push_back(g ? &*g : nullptr);
  out.reply = merge_region_lists(views);
  return out;
}

}  // namespace ort::client
