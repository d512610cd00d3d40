// The batched stage on real scans: voxel lists shot by the cpu back end (OctoMap's own ray
// walk) at 0.1 m from ../shared/data, applied by OctoMap's updateNode loop and by the
// batched stage with 1, 2, 7 and 16 threads; the trees must be the same after every scan.
// The scans are then replayed, so that voxels saturate and free space gets pruned. Scans
// joined into one list (keys repeated across them) give the tree of the scans one by one.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "engine/map_engine.h"
#include "octree/batched/batched_update.h"
#include "real_scan_voxels.h"
#include "scene/scan_set.h"
#include "support/test_data.h"
#include "tree_checks.h"

namespace ort {
namespace {

std::string ot_bytes(const octomap::OcTree& t) {
  std::ostringstream os;
  t.write(os);
  return os.str();
}
std::string bt_bytes(const octomap::OcTree& t) {
  std::ostringstream os;
  t.writeBinaryConst(os);
  return os.str();
}

void check_data_set(const std::string& graph) {
  const bool quick = test::quick_mode();
  const std::vector<VoxelList> lists = test::shoot_real_scans(graph, quick ? 1 : 1000);
  ASSERT_FALSE(lists.empty()) << graph;
  const int passes = quick ? 2 : 3;  // the scans, then replayed: saturation and pruning

  octomap::OcTree reference(0.1);
  struct Batched {
    unsigned threads;
    octomap::OcTree tree{0.1};
    std::unique_ptr<BatchedOctreeUpdater> updater;
    int64_t leaves = 0;  // from each update's leaf count change (no walk)
  };
  std::vector<std::unique_ptr<Batched>> batched;
  for (unsigned threads : {1u, 2u, 7u, 16u}) {
    auto b = std::make_unique<Batched>();
    b->threads = threads;
    BatchedUpdateOptions opts;
    opts.threads = threads;
    b->updater = std::make_unique<BatchedOctreeUpdater>(opts);
    batched.push_back(std::move(b));
  }
  size_t voxels = 0;
  for (int pass = 0; pass < passes; ++pass) {
    for (size_t s = 0; s < lists.size(); ++s) {
      apply_updates_sequential(reference, lists[s]);
      voxels += lists[s].size();
      for (auto& b : batched) {
        BatchedUpdateStats stats;
        const std::optional<int64_t> leaf_change = b->updater->apply(b->tree, lists[s], &stats);
        if (b->threads > 1) {
          EXPECT_GT(stats.subtrees, b->threads) << "the scan was not split";
        }
        ASSERT_TRUE(test::same_tree(reference, b->tree))
            << graph << ", " << b->threads << " threads, pass " << pass << ", scan " << s;
        ASSERT_TRUE(leaf_change.has_value());
        b->leaves += *leaf_change;
        ASSERT_EQ(b->leaves, static_cast<int64_t>(reference.getNumLeafNodes()))
            << "leaf count, " << graph << ", " << b->threads << " threads, pass " << pass << ", scan " << s;
      }
    }
  }
  // Written maps are byte for byte OctoMap's.
  const std::string ot = ot_bytes(reference), bt = bt_bytes(reference);
  for (auto& b : batched) {
    EXPECT_EQ(ot_bytes(b->tree), ot) << b->threads << " threads";
    EXPECT_EQ(bt_bytes(b->tree), bt) << b->threads << " threads";
    EXPECT_EQ(b->tree.memoryUsage(), reference.memoryUsage());
  }
  std::printf("%s: %zu scans x %d passes, %zu voxel updates, %zu nodes\n", graph.c_str(), lists.size(), passes, voxels,
              reference.size());
}

// Several scans' lists joined into one, applied as one update (what the read replica does with
// the scans waiting for it, daemon/map/map_replica.h): keys repeat across the scans, and the
// tree must be the one OctoMap's loop makes of the scans one by one, at the end of each join.
void check_joined_scans(const std::string& graph, size_t join) {
  const bool quick = test::quick_mode();
  const std::vector<VoxelList> lists = test::shoot_real_scans(graph, quick ? 4 : 1000);
  ASSERT_FALSE(lists.empty()) << graph;
  // The scans twice over (voxels saturate, free space gets pruned), cut into groups of `join`.
  std::vector<const VoxelList*> sequence;
  for (int pass = 0; pass < 2; ++pass)
    for (const VoxelList& l : lists) sequence.push_back(&l);
  octomap::OcTree reference(0.1), joined_tree(0.1);
  BatchedUpdateOptions opts;
  opts.threads = 2;
  BatchedOctreeUpdater updater(opts);
  size_t repeated = 0;
  int64_t leaves = 0;
  for (size_t s = 0; s < sequence.size(); s += join) {
    VoxelList joined;
    for (size_t k = s; k < std::min(sequence.size(), s + join); ++k) {
      apply_updates_sequential(reference, *sequence[k]);
      joined.insert(joined.end(), sequence[k]->begin(), sequence[k]->end());
    }
    const std::optional<int64_t> leaf_change = updater.apply(joined_tree, joined);
    ASSERT_TRUE(test::same_tree(reference, joined_tree)) << graph << ", scans from " << s;
    ASSERT_TRUE(leaf_change.has_value());
    leaves += *leaf_change;
    ASSERT_EQ(leaves, static_cast<int64_t>(reference.getNumLeafNodes())) << "leaf count, scans from " << s;
    std::vector<uint64_t> codes;
    for (const VoxelUpdate& u : joined) codes.push_back(uint64_t{u.x} << 32 | uint64_t{u.y} << 16 | u.z);
    std::sort(codes.begin(), codes.end());
    repeated += codes.size() - static_cast<size_t>(std::unique(codes.begin(), codes.end()) - codes.begin());
  }
  EXPECT_GT(repeated, 0u) << "no key repeated across the joined scans: the test shows nothing";
  EXPECT_EQ(ot_bytes(joined_tree), ot_bytes(reference));
  std::printf("%s: %zu scans twice over, joined %zu at a time, %zu repeated keys\n", graph.c_str(), lists.size(), join,
              repeated);
}

TEST(BatchedUpdateRealData, ThreeDtkThreeScans) { check_data_set("3dtk_dat/3dtk_3scans.graph"); }

TEST(BatchedUpdateRealData, JoinedScansGiveOctomapsTreeOfTheScansOneByOne) {
  check_joined_scans("3dtk_dat/3dtk_3scans.graph", 4);
  check_joined_scans("octomap_share/scan_dat.graph", 2);
}

TEST(BatchedUpdateRealData, OctomapScanDat) { check_data_set("octomap_share/scan_dat.graph"); }

}  // namespace
}  // namespace ort
