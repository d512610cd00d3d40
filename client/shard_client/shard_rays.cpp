#include "shard_client/shard_rays.h"

#include <algorithm>
#include <cstdlib>
#include <limits>

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

}  // namespace ort::client
