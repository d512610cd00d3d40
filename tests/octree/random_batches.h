// Random scan-like batches that hit every special case of OcTree::updateNode (keys created,
// leaves and pruned nodes at the clamping bound, pruned nodes expanded, pruning, the edges of
// the key range): random_batches_test counts the cases, leaf_changes_test reuses them.
#pragma once

#include <algorithm>
#include <map>
#include <random>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/batched/morton_order.h"

namespace ort::test {

using octomap::OcTreeKey;

// A cube of keys that batches draw from: small, so that voxels are hit again and again.
struct Cluster {
  int x, y, z;  // lowest corner
  int side;
};
// At the map origin (crossing the depth-1 split), at both ends of the key range, and a
// corner mixing both ends.
inline constexpr Cluster kClusters[] = {{32768 - 8, 32768 - 8, 32768 - 8, 16},
                                        {0, 0, 0, 16},
                                        {65536 - 16, 65536 - 16, 65536 - 16, 16},
                                        {0, 65536 - 16, 0, 16}};

class BatchGenerator {
 public:
  explicit BatchGenerator(unsigned seed) : rng_(seed) {}

  // One scan's list: unique keys, in random order. Mostly whole aligned blocks in one state
  // (they saturate and become prunable), plus scattered voxels of either state (they expand
  // pruned blocks and break them up again).
  VoxelList next() {
    std::map<uint64_t, VoxelUpdate> states;  // by Morton code: unique keys, first state kept
    auto add = [&](const OcTreeKey& k, bool occupied) {
      states.emplace(morton_code(k[0], k[1], k[2]), make_update(k, occupied));
    };
    const int blocks = pick(1, 6);
    for (int b = 0; b < blocks; ++b) {
      const int cluster = pick(0, 3);
      const Cluster& c = kClusters[cluster];
      const int side = 1 << pick(1, 4);
      const int bx = c.x + side * pick(0, c.side / side - 1), by = c.y + side * pick(0, c.side / side - 1),
                bz = c.z + side * pick(0, c.side / side - 1);
      // A cluster's blocks keep to one state for a while, so that they reach the clamping
      // bound and get pruned there; then the state flips and they come back down.
      const bool occupied = ((cluster + batch_ / 15) % 2) == 0;
      for (int x = bx; x < bx + side; ++x)
        for (int y = by; y < by + side; ++y)
          for (int z = bz; z < bz + side; ++z) add(OcTreeKey(x, y, z), occupied);
    }
    const int singles = pick(0, 200);
    for (int i = 0; i < singles; ++i) {
      const Cluster& c = kClusters[pick(0, 3)];
      add(OcTreeKey(c.x + pick(0, c.side - 1), c.y + pick(0, c.side - 1), c.z + pick(0, c.side - 1)), pick(0, 2) == 0);
    }
    // The very corners of the key range, often.
    if (pick(0, 2) == 0) add(OcTreeKey(0, 0, 0), pick(0, 1) == 0);
    if (pick(0, 2) == 0) add(OcTreeKey(65535, 65535, 65535), pick(0, 1) == 0);
    if (pick(0, 2) == 0) add(OcTreeKey(0, 65535, 0), pick(0, 1) == 0);
    VoxelList list;
    for (const auto& [code, update] : states) list.push_back(update);
    std::shuffle(list.begin(), list.end(), rng_);
    ++batch_;
    return list;
  }

 private:
  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  std::mt19937 rng_;
  int batch_ = 0;
};

}  // namespace ort::test
