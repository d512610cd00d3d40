#include "shard_client/shard_rays.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numeric>

#include "octomap_rt/occupancy_reply_t.hpp"
#include "shard_client/shard_distance.h"

namespace ort::client {
namespace {

using Occ = octomap_rt::occupancy_reply_t;

bool key_of(const float* p, double resolution, int64_t k[3]) {
  for (int a = 0; a < 3; ++a)
    if (!voxel_key(p[a], resolution, k[a])) return false;
  return true;
}

}  // namespace

void merge_shard_rays(octomap_rt::ray_reply_t& out, const std::vector<std::optional<octomap_rt::ray_reply_t>>& got,
                      std::span<const float> origins, const protocol::ShardSet& set, double resolution) {
  const size_t asked = origins.size() / 3;
  size_t n = asked;
  bool any = false;
  out.cut = Occ::CUT_NONE, out.cut_at = -1;
  for (const auto& g : got) {
    if (!g) continue;
    any = true;
    n = std::min(n, size_t(std::max(0, g->num_rays)));
    if (g->cut != Occ::CUT_NONE && (out.cut_at < 0 || g->cut_at < out.cut_at)) out.cut = g->cut, out.cut_at = g->cut_at;
  }
  if (!any) n = 0;
  out.num_rays = static_cast<int32_t>(n);
  out.hit.assign(n, 0), out.end_state.assign(n, Occ::OCC_UNKNOWN), out.end_xyz.assign(3 * n, 0.0f);
  out.num_xyz = static_cast<int32_t>(3 * n);
  for (size_t j = 0; j < n; ++j) {
    int64_t origin[3];
    const bool inside = key_of(&origins[3 * j], resolution, origin);
    int best = -1;
    int64_t best_steps = std::numeric_limits<int64_t>::max();
    bool best_owned = false;
    for (size_t i = 0; i < got.size(); ++i) {
      if (!got[i]) continue;
      const float* e = &got[i]->end_xyz[3 * j];
      int64_t k[3];
      int64_t steps = 0;  // an origin outside the key range: every shard answers the origin alike
      bool owned = false;
      if (inside && key_of(e, resolution, k)) {
        steps = std::abs(k[0] - origin[0]) + std::abs(k[1] - origin[1]) + std::abs(k[2] - origin[2]);
        owned = protocol::shard_of(set, protocol::region_coords(set.region_depth, uint16_t(k[0]), uint16_t(k[1]),
                                                                uint16_t(k[2]))) == i;
      }
      if (steps < best_steps || (steps == best_steps && owned && !best_owned))
        best = static_cast<int>(i), best_steps = steps, best_owned = owned;
    }
    const auto& g = *got[best];
    out.hit[j] = g.hit[j], out.end_state[j] = g.end_state[j];
    std::copy(&g.end_xyz[3 * j], &g.end_xyz[3 * j] + 3, &out.end_xyz[3 * j]);
  }
}

std::vector<uint32_t> shards_for_rays(const protocol::ShardSet& set, std::span<const float> origins,
                                      std::span<const float> directions, float max_range, double resolution) {
  std::vector<uint32_t> every(set.count);
  std::iota(every.begin(), every.end(), 0u);
  if (set.rule != protocol::ShardRule::kBoxes || !(max_range > 0) || !std::isfinite(max_range)) return every;
  constexpr int64_t kKeyTop = 65535;
  std::vector<bool> asked(set.count, false);
  for (size_t j = 0; j + 2 < origins.size() && j + 2 < directions.size(); j += 3) {
    const double d[3] = {directions[j], directions[j + 1], directions[j + 2]};
    const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(norm > 0) || !std::isfinite(norm)) return every;
    std::array<int64_t, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      int64_t k0 = 0, k1 = 0;
      if (!voxel_key(origins[j + a], resolution, k0)) return every;
      // castRay stops at the first key whose centre lies past max_range: within a voxel's diagonal.
      const double end = double(origins[j + a]) + d[a] / norm * (double(max_range) + 2 * resolution);
      if (!std::isfinite(end)) return every;
      if (!voxel_key(end, resolution, k1)) k1 = end < 0 ? 0 : kKeyTop;
      lo[a] = std::min(k0, k1) - 2, hi[a] = std::max(k0, k1) + 2;
    }
    for (uint32_t i : shards_meeting(set, lo, hi)) asked[i] = true;
  }
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < set.count; ++i)
    if (asked[i]) out.push_back(i);
  return out.empty() ? std::vector<uint32_t>{0} : out;  // no ray: one shard answers the empty batch
}

}  // namespace ort::client
