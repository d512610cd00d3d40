#include "brute_distance.h"

#include <algorithm>

namespace ort::test {

bool BruteObstacles::at(int64_t x, int64_t y, int64_t z) const {
  const int64_t i = x - lo[0], j = y - lo[1], k = z - lo[2];
  if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return false;
  return blocked[size_t((k * n[1] + j) * n[0] + i)] != 0;
}

BruteObstacles brute_obstacles(const octomap::OcTree& t, std::array<int64_t, 3> lo, std::array<int64_t, 3> n, int m,
                               distance::UnknownAs unknown) {
  BruteObstacles o{lo, n, std::vector<uint8_t>(size_t(n[0] * n[1] * n[2]), 0)};
  const bool unknown_blocks = unknown == distance::UnknownAs::kOccupied;
  for (int64_t k = 0; k < n[2]; ++k)
    for (int64_t j = 0; j < n[1]; ++j)
      for (int64_t i = 0; i < n[0]; ++i) {
        bool blocked = false;
        for (int dz = 0; dz < m && !blocked; ++dz)
          for (int dy = 0; dy < m && !blocked; ++dy)
            for (int dx = 0; dx < m && !blocked; ++dx) {
              const int64_t key[3] = {(lo[0] + i) * m + dx, (lo[1] + j) * m + dy, (lo[2] + k) * m + dz};
              bool in_range = true;
              for (int64_t v : key) in_range = in_range && v >= 0 && v < 65536;
              if (!in_range) {
                blocked = unknown_blocks;
                continue;
              }
              const octomap::OcTreeNode* node = t.search(
                  octomap::OcTreeKey(octomap::key_type(key[0]), octomap::key_type(key[1]), octomap::key_type(key[2])));
              blocked = node ? t.isNodeOccupied(node) : unknown_blocks;
            }
        o.blocked[size_t((k * n[1] + j) * n[0] + i)] = blocked;
      }
  return o;
}

uint32_t brute_squared(const BruteObstacles& o, const std::array<int64_t, 3>& c, int reach) {
  uint32_t best = distance::kNoObstacle;
  for (int dz = -reach; dz <= reach; ++dz)
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        if (o.at(c[0] + dx, c[1] + dy, c[2] + dz))
          best = std::min(best, static_cast<uint32_t>(dx * dx + dy * dy + dz * dz));
  return best;
}

}  // namespace ort::test
