// Distance queries across shards (issues 26 and 27): on the real 3DTK scans, 3 hashed shards
// with small regions (3.2 m: many borders within the 2 m clamp) and 2 box shards answer points
// (with the gradient), dense boxes (at the resolution and at 2 voxels a cell, with the
// gradient) and a path, each shard through the daemon's own distance answers on its own map;
// merged as the shard client merges them (client/shard_client/shard_distance.h), every answer
// equals the one daemon's on the whole map, bit for bit, with unknown space free and occupied.
// Without the shards' ownership of their unknown space the merge would differ (checked, so the
// comparison can fail).
#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "daemon/queries/distance_answers.h"
#include "distance/squared_edt.h"
#include "octomap_rt/distance_box_chunk_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "server/shard_maps.h"
#include "shard_client/shard_distance.h"

namespace ort::test {
namespace {

using DQ = octomap_rt::distance_query_t;
using protocol::ShardRule;
using protocol::ShardSet;
constexpr double kRes = 0.2, kMax = 2.0;

// One daemon's answer to `q` from `tree`, as the query service computes it (read, then finish).
std::vector<std::vector<uint8_t>> answer(const octomap::OcTree& tree, const DQ& q, const ShardSet& shard) {
  daemon::DistanceServiceConfig cfg;
  cfg.shard = shard;
  daemon::EncodedReplies r =
      daemon::read_distance(tree, q, daemon::MapStamp{1, 1, 1}, "test", cfg, distance::cpu_edt(2));
  if (r.finish) r.finish(r);
  return r.messages;
}

template <class M>
M decoded(const std::vector<uint8_t>& bytes) {
  M m;
  EXPECT_GE(m.decode(bytes.data(), 0, int(bytes.size())), 0);
  return m;
}

client::DistanceBox box_of(const std::vector<std::vector<uint8_t>>& messages) {
  std::vector<octomap_rt::distance_box_chunk_t> chunks;
  for (const auto& m : messages) chunks.push_back(decoded<octomap_rt::distance_box_chunk_t>(m));
  return client::assemble_distance_box(chunks);
}

DQ query(int8_t mode, bool unknown_occupied) {
  DQ q{};
  q.mode = mode, q.max_distance = kMax, q.cell_voxels = 1;
  q.unknown_as = unknown_occupied ? DQ::UNKNOWN_OCCUPIED : DQ::UNKNOWN_FREE;
  q.client_id = "planner", q.reply_channel = "R";
  return q;
}

class ShardDistance : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { map_ = sharded_3dtk(kRes); }
  static void TearDownTestSuite() { map_.reset(); }
  void SetUp() override {
    if (!map_) GTEST_SKIP() << "3dtk_3scans.graph not found";
  }

  // Points near the scans' surfaces (every 97th end point, shifted off them by up to a metre).
  static std::vector<float> points() {
    std::vector<float> xyz;
    size_t n = 0;
    for (const PosedScan& s : map_->scans->scans) {
      const octomap::Pointcloud w = world_points(s);
      for (size_t i = 0; i < w.size() && xyz.size() < 3 * 600; i += 97, ++n) {
        const float shift = 0.1f * float(n % 11) - 0.5f;
        xyz.insert(xyz.end(), {w[i].x() + shift, w[i].y() - 0.7f * shift, w[i].z() + 0.3f * shift});
      }
    }
    return xyz;
  }

  static inline std::unique_ptr<ShardedScans> map_;
};

TEST_F(ShardDistance, PointsWithTheGradientEqualTheOneDaemon) {
  const std::vector<float> xyz = points();
  for (const bool unknown_occupied : {false, true}) {
    DQ q = query(DQ::MODE_POINTS, unknown_occupied);
    q.with_gradient = 1, q.xyz = xyz, q.num_xyz = int32_t(xyz.size());
    const auto want = decoded<octomap_rt::distance_points_reply_t>(answer(*map_->whole, q, {}).at(0));
    ASSERT_EQ(want.status, 0) << want.error;
    DQ asked = q;  // what the shard client sends: the points and their neighbours, no gradient
    asked.with_gradient = 0, asked.xyz = client::with_neighbours(xyz, kRes), asked.num_xyz = int32_t(asked.xyz.size());
    for (const ShardMaps& m : map_->sharded) {
      std::vector<octomap_rt::distance_points_reply_t> got;
      for (size_t i = 0; i < m.sets.size(); ++i)
        got.push_back(decoded<octomap_rt::distance_points_reply_t>(answer(*m.trees[i], asked, m.sets[i]).at(0)));
      std::vector<const octomap_rt::distance_points_reply_t*> views;
      for (const auto& g : got) views.push_back(&g);
      const auto merged = client::merge_distance_points(views, xyz.size() / 3, true);
      const std::string what = m.what + (unknown_occupied ? ", unknown occupied" : ", unknown free");
      ASSERT_EQ(merged.num_points, want.num_points) << what;
      ASSERT_EQ(merged.gradient.size(), want.gradient.size()) << what;
      int differing = 0, below_clamp = 0;
      for (int p = 0; p < want.num_points; ++p) {
        differing += merged.distance[p] != want.distance[p];
        for (int a = 0; a < 3; ++a) differing += merged.gradient[3 * p + a] != want.gradient[3 * p + a];
        below_clamp += want.distance[p] < kMax;
      }
      EXPECT_EQ(differing, 0) << what << ": of " << want.num_points << " points";
      EXPECT_GT(below_clamp, want.num_points / 2) << what;  // the points are near obstacles
    }
  }
}

TEST_F(ShardDistance, BoxesAndPathsEqualTheOneDaemon) {
  const client::Box box{{-4.0, -6.0, -1.0}, {6.0, 5.0, 1.5}};  // across both box shards and many regions
  for (const bool unknown_occupied : {false, true})
    for (const int m : {1, 2}) {
      DQ q = query(DQ::MODE_BOX, unknown_occupied);
      q.cell_voxels = m, q.with_gradient = 1;
      std::copy(box.min, box.min + 3, q.box_min), std::copy(box.max, box.max + 3, q.box_max);
      const client::DistanceBox want = box_of(answer(*map_->whole, q, {}));
      ASSERT_EQ(want.header.status, 0) << want.header.error;
      DQ asked = q;
      asked.with_gradient = 0;
      const client::Box grown = client::grown_distance_box(box, kRes, m);
      std::copy(grown.min, grown.min + 3, asked.box_min), std::copy(grown.max, grown.max + 3, asked.box_max);
      for (const ShardMaps& sm : map_->sharded) {
        std::vector<client::DistanceBox> got;
        for (size_t i = 0; i < sm.sets.size(); ++i) got.push_back(box_of(answer(*sm.trees[i], asked, sm.sets[i])));
        std::vector<const client::DistanceBox*> views;
        for (const auto& g : got) views.push_back(&g);
        const client::DistanceBox merged = client::merge_distance_boxes(views, true, kRes);
        const std::string what = sm.what + ", " + std::to_string(m) + " voxels a cell" +
                                 (unknown_occupied ? ", unknown occupied" : ", unknown free");
        for (int a = 0; a < 3; ++a) {
          ASSERT_EQ(merged.header.size[a], want.header.size[a]) << what;
          EXPECT_EQ(merged.header.origin[a], want.header.origin[a]) << what;
        }
        EXPECT_EQ(merged.squared, want.squared) << what;
        EXPECT_EQ(merged.gradient, want.gradient) << what;
        const auto near = std::count_if(want.squared.begin(), want.squared.end(),
                                        [](uint32_t s) { return s != distance::kNoObstacle && s > 0; });
        EXPECT_GT(near, int64_t(want.squared.size() / 10)) << what;
      }
    }
  // A path through the map, both unknown rules.
  const std::vector<float> v = {-5.f, -5.f, 0.3f, 0.f, 0.f, 0.5f, 4.f, 6.f, 0.2f, 8.f, -3.f, 1.f};
  for (const bool unknown_occupied : {false, true}) {
    DQ q = query(DQ::MODE_PATH, unknown_occupied);
    q.xyz = v, q.num_xyz = int32_t(v.size());
    const auto want = decoded<octomap_rt::distance_path_reply_t>(answer(*map_->whole, q, {}).at(0));
    ASSERT_EQ(want.status, 0) << want.error;
    for (const ShardMaps& sm : map_->sharded) {
      std::vector<octomap_rt::distance_path_reply_t> got;
      for (size_t i = 0; i < sm.sets.size(); ++i)
        got.push_back(decoded<octomap_rt::distance_path_reply_t>(answer(*sm.trees[i], q, sm.sets[i]).at(0)));
      std::vector<const octomap_rt::distance_path_reply_t*> views;
      for (const auto& g : got) views.push_back(&g);
      const auto merged = client::merge_distance_paths(views);
      EXPECT_EQ(merged.min_distance, want.min_distance) << sm.what;
      EXPECT_EQ(merged.min_sample, want.min_sample) << sm.what;
      EXPECT_EQ(merged.min_arc_length, want.min_arc_length) << sm.what;
      EXPECT_EQ(merged.num_samples, want.num_samples) << sm.what;
      for (int a = 0; a < 3; ++a) EXPECT_EQ(merged.min_xyz[a], want.min_xyz[a]) << sm.what;
      EXPECT_LT(want.min_distance, kMax);
    }
  }
}

// Each shard counts only its own unknown space: without that, the shards' answers merge to
// a field with too many obstacles (every other shard's region would be one).
TEST_F(ShardDistance, UnknownSpaceCountsOnlyWhereTheShardOwnsIt) {
  DQ q = query(DQ::MODE_BOX, true);
  const double lo[3] = {-4.0, -6.0, -1.0}, hi[3] = {6.0, 5.0, 1.5};
  std::copy(lo, lo + 3, q.box_min), std::copy(hi, hi + 3, q.box_max);
  const client::DistanceBox want = box_of(answer(*map_->whole, q, {}));
  const ShardMaps& sm = map_->sharded[0];
  std::vector<client::DistanceBox> owned, unowned;
  for (size_t i = 0; i < sm.sets.size(); ++i) {
    owned.push_back(box_of(answer(*sm.trees[i], q, sm.sets[i])));
    unowned.push_back(box_of(answer(*sm.trees[i], q, {})));  // as if it were the whole map
  }
  const auto merge = [](const std::vector<client::DistanceBox>& boxes) {
    std::vector<const client::DistanceBox*> views;
    for (const auto& b : boxes) views.push_back(&b);
    return client::merge_distance_boxes(views, false, kRes);
  };
  EXPECT_EQ(merge(owned).squared, want.squared);
  const auto wrong = merge(unowned).squared;
  size_t differ = 0;
  for (size_t c = 0; c < wrong.size(); ++c) differ += wrong[c] != want.squared[c];
  EXPECT_GT(differ, want.squared.size() / 10);
}

// A box shard farther than the padding from the other shard's box is asked alone.
TEST(ShardDistanceRouting, OnlyShardsWithinReachAreAsked) {
  const double inf = std::numeric_limits<double>::infinity();
  const double lo[3] = {-inf, -inf, -inf}, hi[3] = {inf, inf, inf}, cut_max[3] = {inf, 0.0, inf},
               cut_min[3] = {-inf, 0.0, -inf};
  ShardSet s;
  s.count = 2, s.rule = ShardRule::kBoxes, s.region_depth = 11;
  s.boxes = {protocol::region_box_of(lo, cut_max, kRes, 11), protocol::region_box_of(cut_min, hi, kRes, 11)};
  int64_t k0 = 0, k1 = 0, kx = 0;
  ASSERT_TRUE(client::voxel_key(-9.0, kRes, k0) && client::voxel_key(-3.0, kRes, k1) &&
              client::voxel_key(0.0, kRes, kx));
  EXPECT_EQ(client::shards_meeting(s, {kx, k0, kx}, {kx, k1, kx}), std::vector<uint32_t>{0});
  ASSERT_TRUE(client::voxel_key(-1.0, kRes, k0) && client::voxel_key(1.0, kRes, k1));
  EXPECT_EQ(client::shards_meeting(s, {kx, k0, kx}, {kx, k1, kx}), (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(client::distance_padding_cells(2.0, 0.2, 1), 11);
  EXPECT_EQ(client::distance_padding_cells(2.0, 0.2, 2), 6);
}

}  // namespace
}  // namespace ort::test
