// The read replica's rebuild after it fell behind (daemon/map/map_replica.h, "Falling behind";
// octree/versions/region_sync.h): changes handed over while a reader holds the replica never
// wait; the replica rebuilds from the map of record in slices while scans and a step go on
// changing it, and once caught up its tree is the map of record's, byte for byte (.ot).
#include <future>
#include <random>
#include <set>
#include <shared_mutex>
#include <thread>
#include <tuple>

#include <gtest/gtest.h>

#include "daemon/map/map_replica.h"
#include "daemon/persistence/map_store.h"
#include "octree/octree_update.h"
#include "octree/versions/region_sync.h"

namespace ort::test {
namespace {

// A scan of 2000 voxels around the map's centre, spread over many regions of kRebuildRegionDepth,
// some in blocks of one state (so that the octree prunes them to coarser leaves).
VoxelList random_scan(std::mt19937& rng) {
  std::uniform_int_distribution<int> off(-300, 300), state(0, 3);
  VoxelList v;
  std::set<std::tuple<int, int, int>> seen;  // each key at most once in a list
  while (v.size() < 2000) {
    const int x = 32768 + off(rng), y = 32768 + off(rng), z = 32768 + off(rng) / 10;
    const bool block = state(rng) == 0;
    const bool occupied = state(rng) == 0;
    for (int i = 0; i < (block ? 8 : 1); ++i) {
      const int bx = (x & ~1) + (i & 1), by = (y & ~1) + ((i >> 1) & 1), bz = (z & ~1) + ((i >> 2) & 1);
      if (!block && i == 0 && seen.count({x, y, z})) break;
      const auto key = block ? std::tuple{bx, by, bz} : std::tuple{x, y, z};
      if (!seen.insert(key).second) continue;
      v.push_back(VoxelUpdate{uint16_t(std::get<0>(key)), uint16_t(std::get<1>(key)), uint16_t(std::get<2>(key)),
                              uint16_t(occupied ? kStateOccupied : kStateFree)});
    }
  }
  return v;
}

// Plays stage 2: the change applied to the map of record and handed to the replica, both under
// the map's exclusive lock.
struct Record {
  daemon::MapState map;
  OctreeStage stage{OctreeUpdateOptions{}};
  Record() { map.tree = std::make_unique<octomap::OcTree>(0.1); }
  void scan(VoxelList voxels) {
    std::lock_guard lock(map.mutex);
    stage.apply(*map.tree, voxels);
    map.version++;
    map.scans++;
    map.newest_scan["rover"] = daemon::MapState::NewestScan{"rover", int64_t(map.scans), map.scans};
    map.replica->scan_applied(voxels, map, "rover");
  }
  void step(const daemon::MapStep& s) {
    std::lock_guard lock(map.mutex);
    s(*map.tree);
    map.version++;
    map.replica->step_applied(s, map);
  }
  std::string bytes() {
    std::shared_lock lock(map.mutex);
    return daemon::serialize_map(*map.tree);
  }
};

TEST(MapReplicaRebuild, HeldPastItsRoomItRebuildsInSlicesWhileTheMapGoesOnAndThenEqualsIt) {
  Record rec;
  daemon::MapReplica replica(rec.map, OctreeUpdateOptions{}, /*max_pending_bytes=*/1,
                             daemon::MapReplica::kDefaultBatchVoxels, 0, region_grid(11), true, 0,
                             /*rebuild_slice_nodes=*/500);
  rec.map.replica = &replica;
  std::mt19937 rng(23);
  {
    std::shared_lock reader(replica.state().mutex);  // a reader holds it
    // Nothing handed over waits for it (a wait would never end while the reader holds).
    auto pushed = std::async(std::launch::async, [&] {
      for (int k = 0; k < 30; ++k) rec.scan(random_scan(rng));
    });
    ASSERT_EQ(pushed.wait_for(std::chrono::seconds(60)), std::future_status::ready) << "stage 2 waited";
    pushed.get();
    const auto st = replica.stats();
    EXPECT_GE(st.fell_behind, 1u);
    EXPECT_TRUE(st.behind);
    EXPECT_LT(replica.state().version, rec.map.version);
    EXPECT_TRUE(replica.reads_record());
    EXPECT_EQ(&daemon::readable_map(rec.map), &rec.map) << "whole-map readers read the replica while it is behind";
    EXPECT_EQ(replica.read_version(rec.map.version), nullptr);
  }
  // Released: it rebuilds while the map goes on (scans, and a step that changes it all over).
  for (int k = 0; k < 20; ++k) {
    rec.scan(random_scan(rng));
    if (k == 10)
      rec.step([](octomap::OcTree& t) {
        for (int i = 0; i < 200; ++i) t.updateNode(octomap::OcTreeKey(32768 + i, 32768, 32768), false);
      });
  }
  const auto caught_up = [&] {
    const auto st = replica.stats();
    return !st.behind && st.version == rec.map.version;
  };
  for (int i = 0; i < 4000 && !caught_up(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(caught_up()) << "the replica never caught up";
  const auto st = replica.stats();
  EXPECT_GE(st.rebuilds_done, 1u);
  EXPECT_GT(st.rebuild_slices, 1u);
  EXPECT_TRUE(replica.caught_up());
  EXPECT_FALSE(replica.reads_record());
  std::string replica_bytes;
  {
    std::shared_lock lock(replica.state().mutex);
    replica_bytes = daemon::serialize_map(*replica.state().tree);
    EXPECT_EQ(replica.state().tree->size(), rec.map.tree->size());
  }
  EXPECT_TRUE(replica_bytes == rec.bytes()) << "the rebuilt replica differs from the map of record";
  EXPECT_EQ(replica.read_version(rec.map.version)->map->ot_bytes(), rec.bytes());
  replica.stop();
  rec.map.replica = nullptr;
}

// The slices themselves: a copy synced a slice at a time while the source changes between
// slices (each change's regions named dirty) ends equal to it, node for node.
TEST(MapReplicaRebuild, RegionSlicesMakeACopyEqualToAChangingSource) {
  std::mt19937 rng(7);
  octomap::OcTree src(0.1);
  OctreeStage stage{OctreeUpdateOptions{}};
  const RegionGrid grid = region_grid(daemon::MapReplica::kRebuildRegionDepth);
  for (int k = 0; k < 5; ++k) stage.apply(src, random_scan(rng));
  auto dst = empty_tree_like(src);
  std::unordered_set<RegionId> dirty;
  for (RegionId id : list_regions(src, grid)) dirty.insert(id);
  int slices = 0;
  for (int k = 0; k < 10; ++k) {  // a change between two slices
    sync_slice(src, *dst, grid, dirty, 300);
    slices++;
    const VoxelList scan = random_scan(rng);
    stage.apply(src, scan);
    for (const VoxelUpdate& v : scan) dirty.insert(region_of(grid, v.key()));
  }
  while (!sync_slice(src, *dst, grid, dirty, 300).done) slices++;
  EXPECT_GT(slices, 10);
  EXPECT_EQ(dst->size(), src.size());
  EXPECT_TRUE(daemon::serialize_map(*dst) == daemon::serialize_map(src)) << "the copy differs";
  // Emptied source: the copy empties too.
  src.clear();
  EXPECT_TRUE(sync_slice(src, *dst, grid, dirty, 300).done);
  EXPECT_EQ(dst->size(), 0u);
}

}  // namespace
}  // namespace ort::test
