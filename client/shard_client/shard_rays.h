// Rays across a shard set (docs/PROTOCOL.md, "Shards"): every shard takes the ray's walk (OctoMap's
// castRay, the same keys on every shard) and stops only in its own regions, at the first occupied
// voxel, or unknown one unless the ray ignores unknown space; past max_range and at the key
// range's edge every shard stops alike. The walk steps one key on one axis at a time, so a key's
// place on it is its L1 key distance from the origin's key: the ray's answer is the shard's stop
// nearest the origin in that count, the owner's answer where several stop at one voxel (past
// max_range, say). That is the one map's castRay answer exactly. A shard that did not answer may
// own an earlier stop: the answer is then partial (the ray may stop short of its first hit there).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "octomap_rt/ray_reply_t.hpp"
#include "protocol/shards/shard_set.h"

namespace ort::client {

// Fills out's num_rays, hit, end_state, end_xyz, cut and cut_at from the shards' replies to the
// same rays (`got` by shard index, nullopt: no answer). The rays answered are those every
// answering shard answered (a shard cut by its bound answers the first rays only: `cut` is the
// earliest cut's).
void merge_shard_rays(octomap_rt::ray_reply_t& out, const std::vector<std::optional<octomap_rt::ray_reply_t>>& got,
                      std::span<const float> origins, const protocol::ShardSet& set, double resolution);

// The shards a batch of rays must be asked (in index order): for the boxes rule with a finite
// max_range, those whose box meets a ray's key box (its origin's key and the key past its range,
// widened by 2 keys: a superset of the keys castRay walks); a shard no ray reaches would only
// answer "no stop", which every asked shard's answer already covers. Every shard otherwise
// (the hash rule's regions meet nearly every ray), and for a ray outside the key range or
// without a usable direction (every shard answers or refuses those alike).
std::vector<uint32_t> shards_for_rays(const protocol::ShardSet& set, std::span<const float> origins,
                                      std::span<const float> directions, float max_range, double resolution);

}  // namespace ort::client
