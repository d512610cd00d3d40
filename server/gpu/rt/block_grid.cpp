#include "gpu/rt/block_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ort::rt {

BlockGrid choose_block_grid(int block, const int wanted[3], const BlockGridLimits& limits) {
  if (block < 2 || block > 8)
    throw std::invalid_argument("rt: BLAS block size k must be 2..8, got " + std::to_string(block));
  BlockGrid s;
  s.block = block;
  const int max_blocks = std::max(1, std::min(limits.max_side, 65536) / block);
  for (int i = 0; i < 3; ++i) s.blocks[i] = std::clamp((std::max(wanted[i], 1) + block - 1) / block, 1, max_blocks);
  auto fits = [&] { return s.voxel_count() <= limits.max_voxels && s.instance_count() <= limits.max_instances; };
  while (!fits()) {
    int axis = 0;
    for (int i = 1; i < 3; ++i)
      if (s.blocks[i] > s.blocks[axis]) axis = i;
    if (s.blocks[axis] == 1) {
      throw std::invalid_argument("rt: the block-grid limits cannot hold one block of " + std::to_string(block) +
                                  "^3 voxels");
    }
    s.blocks[axis] = (s.blocks[axis] + 1) / 2;
  }
  return s;
}

void wanted_from_range(double resolution, double max_range, int fallback, int wanted[3]) {
  int side = fallback;
  if (max_range > 0) {
    // Origin voxel + range in both directions + the one-voxel window margin on each side.
    const double r = std::ceil(max_range / resolution);
    side = int(std::min(65536.0, 2.0 * r + 4.0));
  }
  for (int i = 0; i < 3; ++i) wanted[i] = side;
}

std::vector<Aabb> block_aabbs(int block, float margin) {
  std::vector<Aabb> out;
  out.reserve(size_t(block) * block * block);
  for (int z = 0; z < block; ++z)
    for (int y = 0; y < block; ++y)
      for (int x = 0; x < block; ++x) {
        const int v[3] = {x, y, z};
        Aabb b;
        for (int i = 0; i < 3; ++i) {
          b.min[i] = float(v[i]) - margin;
          b.max[i] = float(v[i] + 1) + margin;
        }
        out.push_back(b);
      }
  return out;
}

void instance_block(const BlockGrid& s, uint64_t instance, int out[3]) {
  out[0] = int(instance % uint64_t(s.blocks[0]));
  out[1] = int((instance / uint64_t(s.blocks[0])) % uint64_t(s.blocks[1]));
  out[2] = int(instance / (uint64_t(s.blocks[0]) * uint64_t(s.blocks[1])));
}

void instance_translation(const BlockGrid& s, uint64_t instance, float out[3]) {
  int b[3];
  instance_block(s, instance, b);
  for (int i = 0; i < 3; ++i) out[i] = float(b[i] * s.block);  // exact: integers < 2^24
}

void voxel_key(const BlockGrid& s, const int lo[3], uint64_t instance, uint32_t primitive, int out[3]) {
  int b[3];
  instance_block(s, instance, b);
  const uint32_t k = uint32_t(s.block);
  const int p[3] = {int(primitive % k), int((primitive / k) % k), int(primitive / (k * k))};
  for (int i = 0; i < 3; ++i) out[i] = lo[i] + b[i] * s.block + p[i];
}

std::vector<KeyBox> tile_windows(const KeyBox& keys, const BlockGrid& s, int margin) {
  std::vector<KeyBox> out;
  if (keys.empty()) return out;
  KeyBox wide;
  int count[3];
  for (int i = 0; i < 3; ++i) {
    wide.lo[i] = std::max(0, keys.lo[i] - margin);
    wide.hi[i] = std::min(2 * kTreeMaxVal - 1, keys.hi[i] + margin);
    const int extent = wide.hi[i] - wide.lo[i] + 1;
    count[i] = (extent + s.voxels(i) - 1) / s.voxels(i);
  }
  for (int z = 0; z < count[2]; ++z)
    for (int y = 0; y < count[1]; ++y)
      for (int x = 0; x < count[0]; ++x) {
        const int j[3] = {x, y, z};
        KeyBox w;
        for (int i = 0; i < 3; ++i) {
          w.lo[i] = wide.lo[i] + j[i] * s.voxels(i);
          w.hi[i] = std::min(wide.hi[i], w.lo[i] + s.voxels(i) - 1);
        }
        out.push_back(w);
      }
  return out;
}

void to_window_frame(const double p[3], double resolution, const int lo[3], float out[3]) {
  const double factor = 1.0 / resolution;
  for (int i = 0; i < 3; ++i) out[i] = float(p[i] * factor - double(lo[i] - kTreeMaxVal));
}

void trace_direction(const float o[3], const float f[3], float out[3]) {
  for (int i = 0; i < 3; ++i) {
    const float d = f[i] - o[i];
    out[i] = std::fabs(d) >= kMinDirection ? d : (d < 0.0f ? -kMinDirection : kMinDirection);
  }
}

}  // namespace ort::rt
