#include "shard_client/shard_distance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "octomap_rt/occupancy_reply_t.hpp"

namespace ort::client {
namespace {

constexpr int64_t kKeyOrigin = 32768;  // OctoMap's key of coordinate 0
constexpr int64_t kKeyTop = 65535;

// The centre of voxel `key` on one axis [m].
float voxel_center(int64_t key, double resolution) { return float((double(key - kKeyOrigin) + 0.5) * resolution); }

// The map state, stamp and request fields of a merged reply: the newest shard's.
template <class R>
void merge_stamp(R& out, const R& r, bool first) {
  if (first) {
    out = r;
    return;
  }
  out.utime = std::max(out.utime, r.utime);
  out.snapshot_id = std::max(out.snapshot_id, r.snapshot_id);
  out.map_utime = std::max(out.map_utime, r.map_utime);
}

// The gradient of a clamped field as distance_field.h computes it: central differences of
// float distances over two cells.
float central_difference(float plus, float minus, double cell_size) {
  return static_cast<float>((plus - minus) / (2 * cell_size));
}

}  // namespace

int distance_padding_cells(double max_distance, double resolution, int cell_voxels) {
  return static_cast<int>(std::ceil(max_distance / (resolution * cell_voxels) - 1e-9)) + 1;
}

bool voxel_key(double coordinate, double resolution, int64_t& key) {
  if (!(std::abs(coordinate) < resolution * double(kKeyOrigin))) return false;
  const double scaled = std::floor((1.0 / resolution) * coordinate);
  if (!(scaled >= -double(kKeyOrigin) && scaled < double(kKeyOrigin))) return false;
  key = int64_t(scaled) + kKeyOrigin;
  return true;
}

std::vector<uint32_t> shards_meeting(const protocol::ShardSet& set, std::array<int64_t, 3> lo,
                                     std::array<int64_t, 3> hi) {
  if (!set.sharded()) return {0};
  const uint32_t shift = 16 - set.region_depth;
  uint32_t r0[3], r1[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp<int64_t>(lo[a], 0, kKeyTop), hi[a] = std::clamp<int64_t>(hi[a], 0, kKeyTop);
    if (hi[a] < lo[a]) return {};
    r0[a] = uint32_t(lo[a]) >> shift, r1[a] = uint32_t(hi[a]) >> shift;
  }
  if (set.rule == protocol::ShardRule::kBoxes) {  // the boxes met, without a walk over the regions
    std::vector<uint32_t> out;
    for (uint32_t i = 0; i < set.count && i < set.boxes.size(); ++i) {
      const protocol::RegionBox& b = set.boxes[i];
      bool meet = true;
      for (int a = 0; a < 3; ++a) meet = meet && r0[a] < b.max[a] && r1[a] >= b.min[a];
      if (meet) out.push_back(i);
    }
    return out;
  }
  std::vector<bool> meets(set.count, false);
  uint32_t found = 0;
  for (uint32_t z = r0[2]; z <= r1[2] && found < set.count; ++z)
    for (uint32_t y = r0[1]; y <= r1[1] && found < set.count; ++y)
      for (uint32_t x = r0[0]; x <= r1[0] && found < set.count; ++x) {
        const uint32_t s = protocol::shard_of(set, protocol::RegionCoords{x, y, z});
        if (s < set.count && !meets[s]) meets[s] = true, ++found;
      }
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < set.count; ++i)
    if (meets[i]) out.push_back(i);
  return out;
}

std::vector<float> with_neighbours(std::span<const float> xyz, double resolution) {
  std::vector<float> out;
  out.reserve(xyz.size() * 7);
  for (size_t p = 0; p + 2 < xyz.size(); p += 3) {
    int64_t key[3];
    for (int a = 0; a < 3; ++a)
      if (!voxel_key(xyz[p + a], resolution, key[a]))
        throw std::invalid_argument("point " + std::to_string(p / 3) + " is outside the map's key range");
    out.insert(out.end(), {xyz[p], xyz[p + 1], xyz[p + 2]});
    for (int a = 0; a < 3; ++a)
      for (int step : {-1, 1}) {
        float c[3] = {voxel_center(key[0], resolution), voxel_center(key[1], resolution),
                      voxel_center(key[2], resolution)};
        c[a] = voxel_center(key[a] + step, resolution);
        out.insert(out.end(), {c[0], c[1], c[2]});
      }
  }
  return out;
}

octomap_rt::distance_points_reply_t merge_distance_points(
    const std::vector<const octomap_rt::distance_points_reply_t*>& got, size_t points, bool gradient) {
  octomap_rt::distance_points_reply_t out{};
  const size_t asked = gradient ? 7 * points : points;
  std::vector<float> field;  // per asked point, the smallest distance
  bool first = true;
  for (const auto* r : got) {
    if (!r || r->num_points != int32_t(asked) || r->distance.size() != asked) continue;
    merge_stamp(out, *r, first);
    if (first) field = r->distance;
    for (size_t j = 0; j < asked && !first; ++j) field[j] = std::min(field[j], r->distance[j]);
    first = false;
  }
  out.num_points = int32_t(points);
  out.gradient.clear(), out.num_gradient = 0;
  if (first) {  // nobody answered
    out.status = octomap_rt::occupancy_reply_t::REPLY_BAD_REQUEST;
    out.error = "no shard answered";
    out.distance.assign(points, float(out.max_distance));
    return out;
  }
  out.status = octomap_rt::occupancy_reply_t::REPLY_OK, out.error.clear();
  if (!gradient) {
    out.distance = field;
    return out;
  }
  out.distance.resize(points);
  out.gradient.resize(3 * points);
  for (size_t p = 0; p < points; ++p) {
    const float* f = &field[7 * p];
    out.distance[p] = f[0];
    for (int a = 0; a < 3; ++a) out.gradient[3 * p + a] = central_difference(f[2 + 2 * a], f[1 + 2 * a], out.cell_size);
  }
  out.num_gradient = int32_t(out.gradient.size());
  return out;
}

Box grown_distance_box(const Box& b, double resolution, int cell_voxels) {
  Box g{};
  const int64_t m = cell_voxels;
  for (int a = 0; a < 3; ++a) {
    int64_t lo = 0, hi = 0;
    if (!voxel_key(b.min[a], resolution, lo) || !voxel_key(b.max[a], resolution, hi))
      throw std::invalid_argument("a box corner is outside the map's key range");
    // The first voxel of the cell before the first and after the last (cells aligned to m).
    const int64_t c0 = lo / m - 1, c1 = hi / m + 1;
    g.min[a] = voxel_center(c0 * m, resolution), g.max[a] = voxel_center(c1 * m, resolution);
  }
  return g;
}

DistanceBox merge_distance_boxes(const std::vector<const DistanceBox*>& got, bool gradient, double resolution) {
  const DistanceBox* base = nullptr;
  DistanceBox merged;
  int64_t bytes = 0, chunks = 0;
  for (const DistanceBox* b : got) {
    if (!b || b->header.status != 0) continue;
    if (!base) {
      base = b, merged = *b;
    } else {
      for (int a = 0; a < 3; ++a)
        if (b->header.size[a] != base->header.size[a] || b->header.origin[a] != base->header.origin[a])
          throw DistanceBoxError("the shards' boxes differ (size or origin)");
      merge_stamp(merged.header, b->header, false);
      for (size_t c = 0; c < merged.squared.size(); ++c) merged.squared[c] = std::min(merged.squared[c], b->squared[c]);
    }
    bytes += b->header.total_size, chunks += b->header.num_chunks;
  }
  if (!base) throw DistanceBoxError("no shard answered");
  merged.header.total_size = bytes, merged.header.num_chunks = chunks;
  merged.header.chunk_index = 0, merged.header.blob_hash = 0;
  merged.header.compression = merged.header.COMPRESSION_NONE;
  merged.gradient.clear();
  merged.header.with_gradient = 0;
  if (!gradient) {
    merged.header.uncompressed_size = int64_t(merged.squared.size()) * 4;
    return merged;
  }
  // The box asked for is the grown one less its outer layer.
  DistanceBox inner;
  inner.header = merged.header;
  int n[3];
  for (int a = 0; a < 3; ++a) {
    n[a] = merged.header.size[a] - 2;
    if (n[a] < 1) throw DistanceBoxError("a grown box has fewer than 3 cells on an axis");
    inner.header.size[a] = n[a];
    const int64_t key_lo = std::llround(merged.header.origin[a] / resolution);  // key - kKeyOrigin
    const int64_t m = std::llround(merged.header.cell_size / resolution);
    inner.header.origin[a] = double(key_lo + m) * resolution;
  }
  inner.header.with_gradient = 1;
  const size_t cells = size_t(n[0]) * n[1] * n[2];
  inner.header.uncompressed_size = int64_t(cells) * 16;
  inner.squared.resize(cells);
  inner.gradient.resize(3 * cells);
  const double cs = merged.header.cell_size;
  size_t c = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i, ++c) {
        inner.squared[c] = merged.squared[merged.index(i + 1, j + 1, k + 1)];
        inner.gradient[3 * c] =
            central_difference(merged.distance(i + 2, j + 1, k + 1), merged.distance(i, j + 1, k + 1), cs);
        inner.gradient[3 * c + 1] =
            central_difference(merged.distance(i + 1, j + 2, k + 1), merged.distance(i + 1, j, k + 1), cs);
        inner.gradient[3 * c + 2] =
            central_difference(merged.distance(i + 1, j + 1, k + 2), merged.distance(i + 1, j + 1, k), cs);
      }
  return inner;
}

octomap_rt::distance_path_reply_t merge_distance_paths(
    const std::vector<const octomap_rt::distance_path_reply_t*>& got) {
  octomap_rt::distance_path_reply_t out{};
  bool first = true;
  for (const auto* r : got) {
    if (!r || r->status != 0) continue;
    const bool lower = first || r->min_distance < out.min_distance ||
                       (r->min_distance == out.min_distance && r->min_sample < out.min_sample);
    const auto stamp = out;
    if (lower) {
      out = *r;
      if (!first) merge_stamp(out, stamp, false);
    } else {
      merge_stamp(out, *r, false);
    }
    first = false;
  }
  if (first) out.status = octomap_rt::occupancy_reply_t::REPLY_BAD_REQUEST, out.error = "no shard answered";
  return out;
}

}  // namespace ort::client
