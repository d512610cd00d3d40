// Region lists across a shard set (docs/PROTOCOL.md, "Shards"): the nodes of a box at a depth,
// as one daemon's MODE_REGION answer lists them (query/region_extract.h), from the shards
// owning a region the box meets. A node at the shards' region depth or finer belongs to the one
// shard owning its region; so does a stored leaf coarser than that (a shard keeps only its own
// regions' voxels, so it can prune only its own regions together). A node coarser than the
// region depth asked at that depth stands for a subtree several shards hold parts of: each
// shard lists its part's value, and the one map's is the largest (OctoMap's inner node), so the
// node is occupied when any shard's part is. The merged list is the one map's nodes, each once,
// shard by shard (not in OctoMap's visiting order).
#pragma once

#include <vector>

#include "octomap_rt/region_chunk_t.hpp"

namespace ort::client {

// The shards' answers (each its chunks in order; an empty list: no answer) merged into one
// chunk (chunk_index 0 of 1, total_voxels = its voxels); its status is OK when any shard
// answered. Throws std::invalid_argument when the shards' resolutions differ.
octomap_rt::region_chunk_t merge_region_lists(const std::vector<const std::vector<octomap_rt::region_chunk_t>*>& got);

}  // namespace ort::client
