// Every .bt octomap-rt writes is what OcTree::writeBinary writes (max likelihood, pruned),
// byte for byte, and passes OctoMap's own round trip (its test_io: readBinary, writeBinary,
// readBinary, and the trees are ==), without pruning or changing the map it was made from:
// core/file_checks/octree_binary.h (snapshots, the OCTOMAP message, `octomap-rt build -o FILE.bt`).
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "core/file_checks/octree_binary.h"
#include "daemon/persistence/map_store.h"
#include "daemon/serving/octomap_raw_map.h"
#include "daemon/serving/snapshot_blob.h"
#include "octomap_rt/map_chunk_t.hpp"
#include "protocol/zstd_codec.h"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

std::string octomap_write_binary(const octomap::OcTree& tree) {
  octomap::OcTree copy(tree);
  std::ostringstream out;
  copy.writeBinary(out);
  return out.str();
}

// OctoMap 1.9.7's src/testing/test_io.cpp on a .bt file's bytes: read it, copy it, write
// the copy with writeBinary, read that back: the tree read first must equal the tree read back.
::testing::AssertionResult passes_test_io(const std::string& bt) {
  octomap::OcTree tree(0.1);
  std::istringstream in(bt);
  if (!tree.readBinary(in)) return ::testing::AssertionFailure() << "readBinary refused it";
  octomap::OcTree copy(tree);
  if (!(tree == copy)) return ::testing::AssertionFailure() << "copy differs";
  std::stringstream round;
  if (!copy.writeBinary(round)) return ::testing::AssertionFailure() << "writeBinary failed";
  octomap::OcTree back(0.1);
  if (!back.readBinary(round)) return ::testing::AssertionFailure() << "readBinary refused the copy";
  if (!(tree == back))
    return ::testing::AssertionFailure() << "tree read (" << tree.size() << " nodes) != tree written and read back ("
                                         << back.size() << " nodes): not a pruned max-likelihood tree";
  return ::testing::AssertionSuccess();
}

// Maps with log-odds as mapping makes them: OctoMap's insertPointCloud of real scans
// (the 3DTK scans; fr079's corridor scan), and random rays.
std::vector<std::pair<std::string, octomap::OcTree>> maps() {
  std::vector<std::pair<std::string, octomap::OcTree>> out;
  const ScanSet real = load_scan_graph(data_file("3dtk_dat/3dtk_3scans.graph"));
  out.emplace_back("3dtk 0.2 m", *octomap_reference(real, 0.2, 12));
  octomap::OcTree random(0.1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5.f, 5.f);
  octomap::Pointcloud cloud;
  for (int i = 0; i < 3000; ++i) cloud.push_back(u(rng), u(rng), u(rng) / 3);
  random.insertPointCloud(cloud, octomap::point3d(0, 0, 0));
  out.emplace_back("random rays", std::move(random));
  out.emplace_back("empty", octomap::OcTree(0.1));
  return out;
}

TEST(BtConformance, OurBtIsWriteBinarysBytesAndTheMapIsUntouched) {
  for (const auto& [name, map] : maps()) {
    const std::string before = daemon::serialize_map(map);
    const std::string ours = octomap_binary_bytes(map);
    EXPECT_EQ(ours, octomap_write_binary(map)) << name;
    EXPECT_TRUE(passes_test_io(ours)) << name;
    EXPECT_EQ(daemon::serialize_map(map), before) << name << ": the map changed";
    if (name.rfind("3dtk", 0) == 0) {  // the real scans' map has leaves max likelihood prunes
      std::ostringstream unpruned;
      map.writeBinaryConst(unpruned);
      EXPECT_LT(ours.size(), unpruned.str().size()) << name << ": the case does not test pruning";
      EXPECT_FALSE(passes_test_io(unpruned.str())) << name << ": test_io accepts an unpruned .bt";
    }
  }
}

TEST(BtConformance, SnapshotsAndTheViewerMessageCarryConformingBt) {
  for (const auto& [name, map] : maps()) {
    if (name == "empty") continue;
    daemon::SnapshotContents contents;
    const daemon::SnapshotBlob blob =
        daemon::make_snapshot_blob(map, contents, octomap_rt::map_chunk_t::FORMAT_OCTOMAP_BINARY, 3);
    const std::string bt = protocol::zstd_decompress(blob.bytes, static_cast<size_t>(blob.raw_size));
    EXPECT_TRUE(passes_test_io(bt)) << name << " snapshot";
    const daemon::RawMap full = daemon::make_raw_map(map, 1, daemon::RawMapOptions{64u << 20, 10});
    ASSERT_TRUE(full.message) << name;
    EXPECT_EQ(full.depth, 16u);
    EXPECT_TRUE(passes_test_io(std::string(full.message->data.begin(), full.message->data.end())))
        << name << " OCTOMAP";
    // Depth-limited: a coarser tree, written the same way.
    const daemon::RawMap cut = daemon::make_raw_map(map, 1, daemon::RawMapOptions{full.full_bytes / 3, 6});
    ASSERT_TRUE(cut.message) << name << ": " << cut.note;
    EXPECT_LT(cut.depth, 16u);
    EXPECT_TRUE(passes_test_io(std::string(cut.message->data.begin(), cut.message->data.end())))
        << name << " OCTOMAP at depth " << cut.depth;
  }
}

}  // namespace
}  // namespace ort::test
