#include "shard_client/shard_queries.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <future>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>

#include "octomap_rt/box_query_t.hpp"
#include "protocol/limits.h"
#include "shard_client/shard_ask.h"
#include "shard_client/shard_rays.h"

namespace ort::client {
namespace {

using detail::ask_each;
using detail::every_shard;

using Occ = octomap_rt::occupancy_reply_t;

template <class Reply>
void merged_header(Reply& out, const std::vector<std::optional<Reply>>& got) {
  out.status = Occ::REPLY_BAD_REQUEST;
  out.error = "no shard answered";
  for (const auto& r : got)
    if (r) {
      out.status = Occ::REPLY_OK, out.error.clear();
      out.utime = std::max(out.utime, r->utime);
      out.snapshot_id = std::max(out.snapshot_id, r->snapshot_id);
      out.map_utime = std::max(out.map_utime, r->map_utime);
    }
}

}  // namespace

WaitFor ShardWait::on_shard(uint32_t i) const {
  WaitFor w;
  w.robot_id = robot_id, w.seq = seq, w.timeout_ms = timeout_ms;
  if (i < min_snapshot_ids.size() && min_snapshot_ids[i] > 0) w.min_snapshot_id = min_snapshot_ids[i];
  return w;
}

std::string ShardAnswer::shortfall() const {
  std::string out;
  for (size_t k = 0; k < missing.size(); ++k)
    out += (out.empty() ? "" : "; ") + std::string("shard ") + std::to_string(missing[k]) + " did not answer (" +
           errors[k] + "): its part is unknown";
  return out;
}

ShardQueries::ShardQueries(const std::string& url, const std::string& client_id, std::chrono::milliseconds timeout,
                           const std::string& ns, const protocol::ShardSet& set, double resolution)
    : set_(set), resolution_(resolution) {
  if (!(resolution > 0)) throw std::invalid_argument("a shard set's resolution must be > 0");
  for (uint32_t i = 0; i < set.count; ++i)
    clients_.push_back(
        std::make_unique<QueryClient>(url, client_id, timeout, set.sharded() ? protocol::shard_namespace(ns, i) : ns));
}

uint32_t ShardQueries::shard_of_point(double x, double y, double z) const {
  uint16_t key[3];
  const double p[3] = {x, y, z};
  for (int k = 0; k < 3; ++k) {  // OctoMap's coordToKeyChecked
    const double scaled = std::floor((1.0 / resolution_) * p[k]);
    if (!(scaled >= -32768.0 && scaled < 32768.0)) return set_.count;
    key[k] = static_cast<uint16_t>(static_cast<int>(scaled) + 32768);
  }
  return protocol::shard_of(set_, protocol::region_coords(set_.region_depth, key[0], key[1], key[2]));
}

Routed<Occ> ShardQueries::points(const std::vector<float>& xyz, int depth, const ShardWait& w) {
  const size_t n = xyz.size() / 3;
  Routed<Occ> out;
  out.reply.num_results = static_cast<int32_t>(n);
  out.reply.occupancy.assign(n, Occ::OCC_UNKNOWN);
  out.reply.probability.assign(n, -1.0f);
  const bool coarse = depth > 0 && depth < static_cast<int>(set_.region_depth);
  std::vector<std::vector<size_t>> mine(set_.count);  // point indices each shard is asked
  for (size_t j = 0; j < n; ++j) {
    if (coarse) {
      for (auto& m : mine) m.push_back(j);
      continue;
    }
    const uint32_t s = shard_of_point(xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]);
    if (s < set_.count) mine[s].push_back(j);  // outside the key range: unknown, as a server says
  }
  std::vector<uint32_t> asked;
  for (uint32_t i = 0; i < set_.count; ++i)
    if (!mine[i].empty()) asked.push_back(i);
  const auto got = ask_each<Occ>(asked, set_.count, out.shards, [&](uint32_t i) {
    std::vector<float> sub;
    for (size_t j : mine[i]) sub.insert(sub.end(), {xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]});
    return clients_[i]->points(sub, depth, w.on_shard(i));
  });
  merged_header(out.reply, got);
  if (asked.empty()) out.reply.status = Occ::REPLY_OK, out.reply.error.clear();
  for (uint32_t i = 0; i < set_.count; ++i) {
    if (!got[i] || got[i]->num_results != static_cast<int32_t>(mine[i].size())) continue;
    for (size_t k = 0; k < mine[i].size(); ++k) {
      const size_t j = mine[i][k];
      // A coarse node's value is the largest of its children's (OctoMap's inner nodes).
      if (got[i]->probability[k] > out.reply.probability[j]) {
        out.reply.probability[j] = got[i]->probability[k];
        out.reply.occupancy[j] = got[i]->occupancy[k];
      }
    }
  }
  return out;
}

Routed<octomap_rt::box_reply_t> ShardQueries::boxes(const std::vector<Box>& boxes, int8_t mode, const ShardWait& w) {
  Routed<octomap_rt::box_reply_t> out;
  const auto got = ask_each<octomap_rt::box_reply_t>(every_shard(set_.count), set_.count, out.shards, [&](uint32_t i) {
    return clients_[i]->boxes(boxes, mode, w.on_shard(i));
  });
  auto& r = out.reply;
  merged_header(r, got);
  const size_t n = boxes.size();
  r.num_boxes = static_cast<int32_t>(n);
  r.occupied.assign(n, 0), r.free.assign(n, 0), r.unknown.assign(n, 0), r.any_occupied.assign(n, 0);
  r.cut = Occ::CUT_NONE, r.cut_at = -1;
  std::vector<int64_t> voxels(n, -1);
  for (const auto& g : got) {
    if (!g || g->num_boxes != static_cast<int32_t>(n)) continue;
    if (g->cut != Occ::CUT_NONE && (r.cut_at < 0 || g->cut_at < r.cut_at)) r.cut = g->cut, r.cut_at = g->cut_at;
    for (size_t b = 0; b < n; ++b) {
      r.occupied[b] += g->occupied[b], r.free[b] += g->free[b];
      r.any_occupied[b] = static_cast<int8_t>(r.any_occupied[b] || g->any_occupied[b]);
      voxels[b] = g->occupied[b] + g->free[b] + g->unknown[b];  // the box's voxels, the same on every shard
    }
  }
  for (size_t b = 0; b < n; ++b) r.unknown[b] = voxels[b] < 0 ? 0 : voxels[b] - r.occupied[b] - r.free[b];
  return out;
}

Routed<octomap_rt::ray_reply_t> ShardQueries::rays(const std::vector<float>& origins,
                                                   const std::vector<float>& directions, float max_range,
                                                   bool ignore_unknown, const ShardWait& w) {
  Routed<octomap_rt::ray_reply_t> out;
  const auto got = ask_each<octomap_rt::ray_reply_t>(
      shards_for_rays(set_, origins, directions, max_range, resolution_), set_.count, out.shards,
      [&](uint32_t i) { return clients_[i]->rays(origins, directions, max_range, ignore_unknown, w.on_shard(i)); });
  merged_header(out.reply, got);
  merge_shard_rays(out.reply, got, origins, set_, resolution_);
  return out;
}

namespace {

// The shards with a region within `pad` voxels of the points xyz (3 floats each); every shard
// when a point is outside the key range (each then refuses it alike).
std::vector<uint32_t> within_reach(const protocol::ShardSet& set, std::span<const float> xyz, double res, int64_t pad) {
  std::array<int64_t, 3> lo{}, hi{};
  for (size_t p = 0; p + 2 < xyz.size(); p += 3)
    for (int a = 0; a < 3; ++a) {
      int64_t k = 0;
      if (!voxel_key(xyz[p + a], res, k)) return every_shard(set.count);
      lo[a] = p ? std::min(lo[a], k - pad) : k - pad, hi[a] = p ? std::max(hi[a], k + pad) : k + pad;
    }
  const std::vector<uint32_t> out = shards_meeting(set, lo, hi);
  return out.empty() ? std::vector<uint32_t>{0} : out;
}

template <class R>
std::vector<const R*> views_of(const std::vector<std::optional<R>>& got) {
  std::vector<const R*> v;
  for (const auto& g : got) v.push_back(g ? &*g : nullptr);
  return v;
}

// Adds one batch's shard answer to the whole query's.
void add_batch(ShardAnswer& all, const ShardAnswer& batch, bool first) {
  if (first) {
    all = batch;
    return;
  }
  for (size_t k = 0; k < batch.missing.size(); ++k)
    if (std::find(all.missing.begin(), all.missing.end(), batch.missing[k]) == all.missing.end())
      all.missing.push_back(batch.missing[k]), all.errors.push_back(batch.errors[k]);
  for (size_t i = 0; i < batch.snapshot_ids.size() && i < all.snapshot_ids.size(); ++i)
    all.snapshot_ids[i] = std::max(all.snapshot_ids[i], batch.snapshot_ids[i]);
}

}  // namespace

Routed<octomap_rt::distance_points_reply_t> ShardQueries::distance_points(const std::vector<float>& xyz,
                                                                          const DistanceRequest& d,
                                                                          const ShardWait& w) {
  using R = octomap_rt::distance_points_reply_t;
  const size_t n = xyz.size() / 3, per = d.gradient ? 7 : 1;
  const size_t batch = std::max<size_t>(1, size_t(protocol::kMaxQueryPoints) / per);
  DistanceRequest plain = d;
  plain.gradient = false, plain.cell_voxels = 1;
  const int64_t pad = distance_padding_cells(d.max_distance, resolution_, 1) + 1;
  Routed<R> out;
  out.reply.max_distance = d.max_distance;
  for (size_t first = 0; first < n; first += batch) {
    const size_t count = std::min(batch, n - first);
    const std::span<const float> part(xyz.data() + 3 * first, 3 * count);
    const std::vector<float> asked =
        d.gradient ? with_neighbours(part, resolution_) : std::vector<float>(part.begin(), part.end());
    ShardAnswer answer;
    const auto got = ask_each<R>(within_reach(set_, part, resolution_, pad), set_.count, answer,
                                 [&](uint32_t i) { return clients_[i]->distance_points(asked, plain, w.on_shard(i)); });
    const R merged = merge_distance_points(views_of(got), count, d.gradient);
    add_batch(out.shards, answer, first == 0);
    std::vector<float> distance = std::move(out.reply.distance), gradient = std::move(out.reply.gradient);
    if (first == 0 || merged.snapshot_id > out.reply.snapshot_id || merged.status != Occ::REPLY_OK) {
      const int8_t status = first == 0 ? merged.status : std::max(out.reply.status, merged.status);
      const std::string error = merged.status != Occ::REPLY_OK ? merged.error : out.reply.error;
      out.reply = merged;
      out.reply.status = status, out.reply.error = error;
    }
    distance.insert(distance.end(), merged.distance.begin(), merged.distance.end());
    gradient.insert(gradient.end(), merged.gradient.begin(), merged.gradient.end());
    out.reply.distance = std::move(distance), out.reply.gradient = std::move(gradient);
  }
  out.reply.num_points = int32_t(out.reply.distance.size());
  out.reply.num_gradient = int32_t(out.reply.gradient.size());
  return out;
}

Routed<DistanceBox> ShardQueries::distance_box(const Box& box, const DistanceRequest& d, const ShardWait& w) {
  const Box asked = d.gradient ? grown_distance_box(box, resolution_, d.cell_voxels) : box;
  DistanceRequest plain = d;
  plain.gradient = false;
  const int64_t pad = int64_t(distance_padding_cells(d.max_distance, resolution_, d.cell_voxels) + 1) * d.cell_voxels;
  const std::vector<float> corners = {float(asked.min[0]), float(asked.min[1]), float(asked.min[2]),
                                      float(asked.max[0]), float(asked.max[1]), float(asked.max[2])};
  Routed<DistanceBox> out;
  const auto got =
      ask_each<DistanceBox>(within_reach(set_, corners, resolution_, pad), set_.count, out.shards,
                            [&](uint32_t i) { return clients_[i]->distance_box(asked, plain, w.on_shard(i)); });
  const auto views = views_of(got);
  if (std::none_of(views.begin(), views.end(), [](const DistanceBox* b) { return b != nullptr; })) {
    out.reply.header.status = Occ::REPLY_BAD_REQUEST;
    out.reply.header.error = "no shard answered";
    return out;
  }
  out.reply = merge_distance_boxes(views, d.gradient, resolution_);
  return out;
}

Routed<octomap_rt::distance_path_reply_t> ShardQueries::distance_path(const std::vector<float>& vertices,
                                                                      const DistanceRequest& d, const ShardWait& w) {
  using R = octomap_rt::distance_path_reply_t;
  DistanceRequest plain = d;
  plain.gradient = false, plain.cell_voxels = 1;
  const int64_t pad = distance_padding_cells(d.max_distance, resolution_, 1) + 1;
  Routed<R> out;
  const auto got = ask_each<R>(within_reach(set_, vertices, resolution_, pad), set_.count, out.shards,
                               [&](uint32_t i) { return clients_[i]->distance_path(vertices, plain, w.on_shard(i)); });
  out.reply = merge_distance_paths(views_of(got));
  return out;
}

}  // namespace ort::client
