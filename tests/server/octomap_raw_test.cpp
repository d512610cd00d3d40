// octomap.raw_t for LCM's OctoMap viewers: at full depth its data is OctoMap's .bt of the map and
// decodes with a type generated separately from the viewers' field list; too large, it is
// depth-limited and still shows every occupied voxel; far too large, it is skipped with a note.
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "daemon/serving/octomap_raw_map.h"
#include "libbot_copy/raw_t.hpp"

namespace ort::daemon {
namespace {

// A map of random rays in a 12 m room (many occupied and free voxels, partly pruned).
octomap::OcTree random_map(int rays) {
  octomap::OcTree tree(0.1);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-6.f, 6.f);
  octomap::Pointcloud cloud;
  for (int i = 0; i < rays; ++i) cloud.push_back(u(rng), u(rng), u(rng) / 4);
  tree.insertPointCloud(cloud, octomap::point3d(0, 0, 0));
  return tree;
}

// OctoMap's own .bt of the map: OcTree::writeBinary, on a copy (it prunes the tree it is given).
std::string bt_bytes(const octomap::OcTree& tree) {
  octomap::OcTree copy(tree);
  std::ostringstream out;
  copy.writeBinary(out);
  return out.str();
}

libbot_copy::raw_t through_the_wire(const octomap::raw_t& sent) {
  std::vector<uint8_t> buf(static_cast<size_t>(sent.getEncodedSize()));
  EXPECT_EQ(sent.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  libbot_copy::raw_t got;
  EXPECT_EQ(got.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()))
      << "the viewers' type does not decode octomap.raw_t";
  EXPECT_EQ(raw_message_bytes(static_cast<size_t>(sent.length)), buf.size());
  return got;
}

std::unique_ptr<octomap::OcTree> read_bt(const std::vector<uint8_t>& data) {
  auto tree = std::make_unique<octomap::OcTree>(0.5);
  std::istringstream in(std::string(data.begin(), data.end()));
  EXPECT_TRUE(tree->readBinary(in));
  return tree;
}

TEST(OctomapRaw, FullDepthCarriesTheBtFileAndDecodesWithTheViewersType) {
  const octomap::OcTree map = random_map(2000);
  const RawMap r = make_raw_map(map, 1'700'000'000'123'456, RawMapOptions{16u << 20, 10});
  ASSERT_TRUE(r.message);
  EXPECT_EQ(r.depth, 16u);
  EXPECT_EQ(r.note, "");
  const libbot_copy::raw_t got = through_the_wire(*r.message);
  EXPECT_EQ(got.utime, 1'700'000'000'123'456);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_EQ(got.transform[i][j], i == j ? 1.0 : 0.0);
  const std::string bt = bt_bytes(map);
  ASSERT_EQ(got.length, static_cast<int32_t>(bt.size()));
  EXPECT_TRUE(std::vector<uint8_t>(bt.begin(), bt.end()) == got.data) << "data is not the map's .bt bytes";
  const auto back = read_bt(got.data);
  EXPECT_EQ(back->getResolution(), 0.1);
  size_t occupied = 0;
  for (auto it = map.begin_leafs(); it != map.end_leafs(); ++it) {
    const octomap::OcTreeNode* n = back->search(it.getKey());
    ASSERT_NE(n, nullptr);
    EXPECT_EQ(back->isNodeOccupied(n), map.isNodeOccupied(*it));
    occupied += map.isNodeOccupied(*it);
  }
  EXPECT_GT(occupied, 1000u);
}

TEST(OctomapRaw, TooLargeIsDepthLimitedAndStillShowsEveryOccupiedVoxel) {
  const octomap::OcTree map = random_map(20000);
  const size_t full = raw_message_bytes(bt_bytes(map).size());
  const RawMap r = make_raw_map(map, 1, RawMapOptions{full / 4, 8});
  ASSERT_TRUE(r.message) << r.note;
  EXPECT_EQ(r.full_bytes, full);
  EXPECT_LT(r.depth, 16u);
  EXPECT_LE(raw_message_bytes(static_cast<size_t>(r.message->length)), full / 4);
  EXPECT_NE(r.note.find("depth-limited to " + std::to_string(r.depth) + " of 16"), std::string::npos) << r.note;
  const auto back = read_bt(through_the_wire(*r.message).data);
  EXPECT_DOUBLE_EQ(back->getResolution(), 0.1 * double(1u << (16 - r.depth)));  // a cut tree: coarser voxels
  for (auto it = map.begin_leafs(); it != map.end_leafs(); ++it) {
    if (!map.isNodeOccupied(*it)) continue;
    const octomap::OcTreeNode* n = back->search(it.getCoordinate());
    ASSERT_NE(n, nullptr);
    ASSERT_TRUE(back->isNodeOccupied(n)) << "occupied voxel at " << it.getCoordinate() << " lost";
  }
}

TEST(OctomapRaw, FarTooLargeIsSkippedWithANote) {
  const RawMap r = make_raw_map(random_map(2000), 1, RawMapOptions{300, 10});
  EXPECT_FALSE(r.message);
  EXPECT_NE(r.note.find("not published"), std::string::npos) << r.note;
  EXPECT_NE(r.note.find("depth 10"), std::string::npos) << r.note;
}

// Issue 24: octomap_server's occupancy_min_z/max_z on the viewer's copy. Checked leaf by leaf
// against the tree it came from: occupied leaves stay exactly where their centre is strictly
// inside the band, every free leaf stays.
TEST(OctomapRaw, TheOccupancyBandLeavesOutOccupiedCellsOutsideItOnly) {
  octomap::OcTree tree(0.1);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  octomap::Pointcloud cloud;
  for (int i = 0; i < 3000; ++i) cloud.push_back(u(rng), u(rng), u(rng));
  tree.insertPointCloud(cloud, octomap::point3d(0, 0, 0));
  octomap::OcTree band(tree);
  const double lo = -0.5, hi = 1.2;
  const size_t dropped = drop_occupied_outside_band(band, lo, hi);
  size_t expect_dropped = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::OcTreeNode* kept = band.search(it.getKey(), it.getDepth());
    const bool occupied_outside = tree.isNodeOccupied(*it) && !(it.getZ() > lo && it.getZ() < hi);
    expect_dropped += occupied_outside;
    if (!occupied_outside) {
      ASSERT_NE(kept, nullptr);
      EXPECT_EQ(kept->getLogOdds(), it->getLogOdds());
    }
  }
  EXPECT_EQ(dropped, expect_dropped);
  EXPECT_GT(dropped, 100u);
  for (auto it = band.begin_leafs(), end = band.end_leafs(); it != end; ++it) {
    if (band.isNodeOccupied(*it)) {
      EXPECT_TRUE(it.getZ() > lo && it.getZ() < hi) << it.getZ();
    }
  }
}

}  // namespace
}  // namespace ort::daemon
